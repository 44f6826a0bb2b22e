// farm_job.h: independent tasks plus one final step, written as a job for a scheduler: a path-traced render split
// into sample ranges (renderFarmJob: tasks `narval render --samples A:B` into JOB/parts, then `narval merge`, bit
// for bit the single render; render/render_merge.h), or a sweep's renders (sweep_command.cpp: one per value, then
// `narval sweep --collect`). JOB holds the scripts (writeFarmFiles), the logs and, for renders, the parts.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace narval {

enum class Scheduler { Slurm, OpenJd, Local };
const char* schedulerName(Scheduler s);  // "slurm", "openjd", "local"
bool schedulerFromName(const std::string& name, Scheduler* out);  // false for another name

struct FarmTask {
  std::vector<std::string> argv;  // the command it runs (the narval binary first)
  std::string output;             // the file it writes
  std::string label;              // its name in reports: "samples [0, 3)", "spp 100"
};

// An Open Job Description form for a job whose tasks differ only in task parameters, files as PATH job
// parameters (Deadline Cloud maps them to its workers' storage); without one, the template embeds task.sh.
struct OpenJdForm {
  nlohmann::json pathParameters;   // PATH parameter definitions (no defaults: OpenJD allows none absolute)
  std::vector<std::pair<std::string, std::string>> pathValues;  // their values for this job
  nlohmann::json taskParameters;   // the first step's taskParameterDefinitions
  std::string combination;         // e.g. "(Part, Samples)"; "" for one parameter
  nlohmann::json taskArgs, finalArgs;  // the two steps' narval arguments, with {{...}} references
  std::function<nlohmann::json(int task)> taskValues;  // task i's parameter values (openjd --tasks)
};

struct FarmJob {
  std::string name;        // the job's name, e.g. "narval-cloud"
  std::string jobDir;      // absolute
  std::string narval;      // the binary the tasks run (absolute)
  std::vector<std::string> stepNames = {"Render", "Merge"};  // the tasks' step and the final one
  std::vector<FarmTask> tasks;
  std::vector<std::string> finalArgv;
  std::string finalOutput;
  // Whether task i's output is there and is what it must be (so a failed, killed or foreign
  // output makes it run again); whether the final output is this job's.
  std::function<bool(int task)> taskDone;
  std::function<bool()> finalDone;
  // Whether task i's output, not done, may stay for the task to resume (a render part with the task's
  // key and first sample, fewer samples); null: never. runFarm removes any other output before the rerun.
  std::function<bool(int task)> taskResumable;
  std::function<OpenJdForm()> openJd;  // null: the generic template

  std::string logPath(int task) const;   // JOB/logs/task_I.log
  std::string timePath(int task) const;  // JOB/logs/task_I.time: start and end, seconds since the epoch
  std::string finalLogPath() const;      // JOB/logs/final.log
  std::string finalTimePath() const;     // JOB/logs/final.time
};

// A path-traced render of `scene` (absolute) with `renderArgs` (--set, --seed, ...): `spp` samples in `tasks`
// ranges [iN/K, (i+1)N/K) (contiguous, uneven by at most one), parts JOB/parts/part_I.exr merged into
// `output`; finished parts carry `renderKey` (render_exr.h: the scene's with those flags). Tasks use
// --resume, continuing a part an interrupted task left (Ctrl-C, or a kill with --write-partial-images).
FarmJob renderFarmJob(const std::string& narval, const std::string& scene, const std::vector<std::string>& renderArgs,
                      int spp, int tasks, const std::string& jobDir, const std::string& output,
                      const std::string& renderKey, const std::string& name);

// Tasks whose output is not (yet) what it must be; ascending.
std::vector<int> missingTasks(const FarmJob& job);

// Writes the job's files for `scheduler` into job.jobDir (made if missing); returns their paths. slurm and
// local: task.sh (one task by index: a case table of the commands) and final.sh, recording their times;
// slurm adds tasks.sbatch (a job array), final.sbatch and submit.sh (the array, then the final job with
// --dependency=afterok:ARRAY); local adds run.sh (every task, then the final step). openjd: template.json
// (jobtemplate-2023-09: a step over the tasks, the final step after it) and, with an OpenJdForm,
// Deadline's parameter_values.json: the folder is a Deadline Cloud job bundle.
std::vector<std::string> writeFarmFiles(const FarmJob& job, Scheduler scheduler);

// `openjd run JOB/template.json [-p NAME=VALUE...]`: the whole job on this machine.
std::vector<std::string> openJdRunCommand(const FarmJob& job);
// openjd run's --tasks value for these tasks of the first step.
nlohmann::json openJdTaskList(const FarmJob& job, const std::vector<int>& tasks);

}  // namespace narval
