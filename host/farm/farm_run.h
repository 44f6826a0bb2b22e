// farm_run.h: `narval farm --submit`: runs a written job (farm_job.h) through its scheduler and
// waits, then tells each task's and the merge's outcome from what they left in the job folder (a
// part with the task's range and the job's render key; the time files task.sh and merge.sh write),
// not from the scheduler's exit codes, which do not say whether a cancelled merge ran.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "farm/farm_job.h"

namespace narval {

struct FarmTaskOutcome {
  int task = 0;
  bool ok = false;
  bool reused = false;          // its part was already there from an earlier run: not run again
  double wallSeconds = 0;       // the task's start to end (task.sh's clock)
  double renderSeconds = 0;     // the part's narval:seconds (the sample loop)
};

struct FarmOutcome {
  std::vector<FarmTaskOutcome> tasks;
  bool merged = false;
  double mergeSeconds = 0;
  double wallSeconds = 0;       // submission to the end of the merge, as narval farm waited
  std::string schedulerIds;     // e.g. "array 12, merge 13" (Slurm)
};

// Runs the tasks of `job` that `missingTasks` names (the others keep their parts), then the merge
// once they all succeeded. Local: up to `parallel` tasks at a time as child processes. Slurm:
// sbatch of the array (those tasks only) and of the merge with --dependency=afterok on it, then
// waits for the merge job with sbatch --wait. OpenJD: `openjd run` of the Render step with those
// tasks, then of the Merge step. `say` receives one progress line at a time.
// std::runtime_error when the scheduler's command cannot be run or refuses the job.
FarmOutcome runFarm(const FarmJob& job, Scheduler scheduler, int parallel, const std::function<void(const std::string&)>& say);

}  // namespace narval
