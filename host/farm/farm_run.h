// farm_run.h: `--submit` of `narval farm` and `narval sweep --scheduler`: runs a written job
// (farm_job.h) through its scheduler and waits, then tells each task's and the final step's outcome
// from what they left in the job folder (FarmJob::taskDone and finalDone; the time files task.sh
// and final.sh write), not from the scheduler's exit codes, which do not say whether a cancelled
// final job ran.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "farm/farm_job.h"

namespace narval {

struct FarmTaskOutcome {
  int task = 0;
  bool ok = false;
  bool reused = false;          // its output was already there from an earlier run: not run again
  double wallSeconds = 0;       // the task's start to end (task.sh's clock); -1 when unknown
  double renderSeconds = 0;     // its output's narval:seconds (the render's sample loop)
};

struct FarmOutcome {
  std::vector<FarmTaskOutcome> tasks;
  bool finalDone = false;       // the final step ran in this run and left its output
  double finalSeconds = 0;
  double wallSeconds = 0;       // submission to the end of the final step, as narval waited
  std::string schedulerIds;     // e.g. "array 12, final job 13" (Slurm)
};

// Runs the tasks of `job` that `missingTasks` names (the others keep their outputs), then the final
// step once they all succeeded. Local: up to `parallel` tasks at a time as child processes. Slurm:
// sbatch of the array (those tasks only) and of the final job with --dependency=afterok on it, then
// waits for the final job with sbatch --wait. OpenJD: `openjd run` of the first step with those
// tasks, then of the final step. `say` receives one progress line at a time.
// std::runtime_error when the scheduler's command cannot be run or refuses the job.
FarmOutcome runFarm(const FarmJob& job, Scheduler scheduler, int parallel, const std::function<void(const std::string&)>& say);

}  // namespace narval
