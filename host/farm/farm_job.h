// farm_job.h: one path-traced render split into K sample ranges, as a job for a scheduler: each task
// renders `narval render SCENE --samples A:B` into JOB/parts/part_I.exr, and one last task merges
// them (`narval merge`, render/render_merge.h) into the output, bit for bit the single render.
// The job folder holds what the scheduler runs (farm_files.h) and its logs.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace narval {

enum class Scheduler { Slurm, OpenJd, Local };
const char* schedulerName(Scheduler s);  // "slurm", "openjd", "local"

struct FarmJob {
  std::string narval;                   // the binary every task runs (absolute)
  std::string scene;                    // the scene file (absolute)
  std::vector<std::string> renderArgs;  // options every task's render takes (--set, --seed, ...)
  int spp = 0, tasks = 0;
  std::string jobDir, output;           // absolute
  std::string renderKey;                // the scene's with these options (render_exr.h)
  std::string name;                     // the job's name: "narval-" + the scene's stem

  // Samples [i·N/K, (i+1)·N/K) of task i: contiguous, uneven by at most one sample.
  std::pair<int, int> range(int task) const;
  std::string partPath(int task) const;  // JOB/parts/part_I.exr
  std::string logPath(int task) const;   // JOB/logs/task_I.log
  std::string timePath(int task) const;  // JOB/logs/task_I.time: start and end, seconds since the epoch
  std::string mergeLogPath() const;      // JOB/logs/merge.log
  std::string mergeTimePath() const;     // JOB/logs/merge.time
  // The render and merge command lines a task runs (argv).
  std::vector<std::string> renderCommand(int task) const;
  std::vector<std::string> mergeCommand() const;
};

// Tasks whose part is not there yet as a finished render of this job's range and render key (so a
// failed or killed task, or a part of another render, is rendered again); ascending.
std::vector<int> missingTasks(const FarmJob& job);

// Writes the job's files for `scheduler` into job.jobDir (made if missing) and returns their paths:
// - every scheduler: task.sh (one task by index) and merge.sh, which record their times;
// - slurm: render.sbatch (a job array over the tasks), merge.sbatch and submit.sh, which submits
//   the array and the merge with --dependency=afterok:ARRAY;
// - openjd: template.json (jobtemplate-2023-09: a Render step over (Part, Samples), a Merge step
//   depending on it) and parameter_values.json: the folder is a Deadline Cloud job bundle;
// - local: run.sh, which runs the tasks one after another and then the merge.
std::vector<std::string> writeFarmFiles(const FarmJob& job, Scheduler scheduler);

// The OpenJD template's PATH parameters and their values for this job (Scene, PartsDir, Output).
std::vector<std::pair<std::string, std::string>> openJdParameters(const FarmJob& job);
// `openjd run JOB/template.json -p NAME=VALUE...`: the whole job on this machine.
std::vector<std::string> openJdRunCommand(const FarmJob& job);

}  // namespace narval
