#include "farm/farm_job.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "image/atomic_file.h"
#include "render/render_exr.h"
#include "util/shell_quote.h"

namespace fs = std::filesystem;

namespace narval {

const char* schedulerName(Scheduler s) {
  switch (s) {
    case Scheduler::Slurm: return "slurm";
    case Scheduler::OpenJd: return "openjd";
    case Scheduler::Local: return "local";
  }
  return "?";
}

std::pair<int, int> FarmJob::range(int task) const {
  return {int((long long)task * spp / tasks), int((long long)(task + 1) * spp / tasks)};
}
std::string FarmJob::partPath(int task) const { return jobDir + "/parts/part_" + std::to_string(task) + ".exr"; }
std::string FarmJob::logPath(int task) const { return jobDir + "/logs/task_" + std::to_string(task) + ".log"; }
std::string FarmJob::timePath(int task) const { return jobDir + "/logs/task_" + std::to_string(task) + ".time"; }
std::string FarmJob::mergeLogPath() const { return jobDir + "/logs/merge.log"; }
std::string FarmJob::mergeTimePath() const { return jobDir + "/logs/merge.time"; }

std::vector<std::string> FarmJob::renderCommand(int task) const {
  const auto [a, b] = range(task);
  std::vector<std::string> argv = {narval, "render", scene};
  argv.insert(argv.end(), renderArgs.begin(), renderArgs.end());
  argv.insert(argv.end(), {"--samples", std::to_string(a) + ":" + std::to_string(b), "-o", partPath(task), "--quiet"});
  return argv;
}

std::vector<std::string> FarmJob::mergeCommand() const {
  std::vector<std::string> argv = {narval, "merge"};
  for (int i = 0; i < tasks; ++i) argv.push_back(partPath(i));
  argv.insert(argv.end(), {"-o", output, "--quiet"});
  return argv;
}

std::vector<int> missingTasks(const FarmJob& job) {
  std::vector<int> missing;
  for (int i = 0; i < job.tasks; ++i) {
    bool done = false;
    if (fs::exists(job.partPath(i))) {
      try {
        const RenderPart p = readRenderPart(job.partPath(i));
        const auto [a, b] = job.range(i);
        done = p.attribute("narval:render_key") == job.renderKey && p.accumulator.begin == a &&
               p.accumulator.end() == b;
      } catch (const std::exception&) {
        done = false;  // unreadable or not a part: render it again
      }
    }
    if (!done) missing.push_back(i);
  }
  return missing;
}

namespace {

void writeScript(const std::string& path, const std::string& text) {
  writeTextAtomic(path, text);
  fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec, fs::perm_options::add);
}

// `command`, then its start and end times into `timeWord` (a shell word) once it has succeeded.
std::string timed(const std::string& command, const std::string& timeWord) {
  return "start=$(date +%s.%N)\n" + command + "\nprintf '%s %s\\n' \"$start\" \"$(date +%s.%N)\" > " + timeWord + "\n";
}

std::string taskScript(const FarmJob& job) {
  // The range is FarmJob::range's arithmetic, in the shell's (64-bit) integers.
  std::vector<std::string> render = {job.narval, "render", job.scene};
  render.insert(render.end(), job.renderArgs.begin(), job.renderArgs.end());
  const std::string n = std::to_string(job.spp), k = std::to_string(job.tasks);
  return "#!/bin/sh\n"
         "# Task I of the narval farm job " + job.name + ": samples [I*" + n + "/" + k + ", (I+1)*" + n + "/" + k +
         ") of every pixel\n# into parts/part_I.exr, then its start and end times into logs/task_I.time.\n"
         "# Usage: task.sh I (0 <= I < " + k + "). Written by narval farm.\n"
         "set -eu\n"
         "i=$1\n"
         "case $i in ''|*[!0-9]*) echo \"task.sh: not a task index: '$i'\" >&2; exit 2;; esac\n"
         "if [ \"$i\" -ge " + k + " ]; then echo \"task.sh: no task $i (0 to " + std::to_string(job.tasks - 1) +
         ")\" >&2; exit 2; fi\n"
         "job=" + shellQuoted(job.jobDir) + "\n"
         "mkdir -p \"$job/logs\"\n" +
         timed(shellJoined(render) + " \\\n  --samples \"$((i * " + n + " / " + k + ")):$(((i + 1) * " + n + " / " + k +
                   "))\" -o \"$job/parts/part_$i.exr\" --quiet",
               "\"$job/logs/task_$i.time\"");
}

std::string mergeScript(const FarmJob& job) {
  return "#!/bin/sh\n# Merges the parts of the narval farm job " + job.name +
         " into the output; its times into logs/merge.time.\nset -eu\nmkdir -p " + shellQuoted(job.jobDir + "/logs") +
         "\n" + timed(shellJoined(job.mergeCommand()), shellQuoted(job.mergeTimePath()));
}

std::string slurmRenderScript(const FarmJob& job) {
  return "#!/bin/sh\n"
         "#SBATCH --job-name=" + job.name + "-render\n"
         "#SBATCH --array=0-" + std::to_string(job.tasks - 1) + "\n"
         "#SBATCH --output=" + job.jobDir + "/logs/task_%a.log\n"
         "# One array task per sample range (task.sh). Add --cpus-per-task, --time or --partition here or\n"
         "# on the sbatch line as the cluster needs; the pixels never depend on them.\n"
         "exec " + shellQuoted(job.jobDir + "/task.sh") + " \"$SLURM_ARRAY_TASK_ID\"\n";
}

std::string slurmMergeScript(const FarmJob& job) {
  return "#!/bin/sh\n"
         "#SBATCH --job-name=" + job.name + "-merge\n"
         "#SBATCH --output=" + job.mergeLogPath() + "\n"
         "exec " + shellQuoted(job.jobDir + "/merge.sh") + "\n";
}

std::string slurmSubmitScript(const FarmJob& job) {
  return "#!/bin/sh\n"
         "# Submits the render array, then the merge once every task has succeeded (a failed task cancels\n"
         "# it). Extra arguments go to the array's sbatch, e.g. --array=3,5 to render only tasks 3 and 5.\n"
         "set -eu\n"
         "array=$(sbatch --parsable \"$@\" " + shellQuoted(job.jobDir + "/render.sbatch") + ")\n"
         "array=${array%%;*}\n"
         "merge=$(sbatch --parsable --dependency=afterok:$array --kill-on-invalid-dep=yes " +
         shellQuoted(job.jobDir + "/merge.sbatch") + ")\n"
         "echo \"render array $array, merge ${merge%%;*}\"\n";
}

std::string localScript(const FarmJob& job) {
  return "#!/bin/sh\n# The narval farm job " + job.name + " on this machine: every task in turn, then the merge.\nset -eu\n"
         "i=0\nwhile [ $i -lt " + std::to_string(job.tasks) + " ]; do\n  " + shellQuoted(job.jobDir + "/task.sh") +
         " $i\n  i=$((i + 1))\ndone\n" + shellQuoted(job.jobDir + "/merge.sh") + "\n";
}

// An Open Job Description template (jobtemplate-2023-09). The scene, the parts folder and the
// output are PATH job parameters, so a Deadline Cloud submission can map them to its workers'
// storage; OpenJD allows no absolute PATH default, nor one outside the template's folder, so their
// values come with the submission (openJdParameters; parameter_values.json for Deadline).
std::string openJdTemplate(const FarmJob& job) {
  using nlohmann::json;
  json parts = json::array(), samples = json::array();
  for (int i = 0; i < job.tasks; ++i) {
    const auto [a, b] = job.range(i);
    parts.push_back(i);
    samples.push_back(std::to_string(a) + ":" + std::to_string(b));
  }
  json render = {"render", "{{Param.Scene}}"};
  for (const std::string& a : job.renderArgs) render.push_back(a);
  for (const char* a : {"--samples", "{{Task.Param.Samples}}", "-o", "{{Param.PartsDir}}/part_{{Task.Param.Part}}.exr",
                        "--quiet"})
    render.push_back(a);
  json merge = {"merge"};
  for (int i = 0; i < job.tasks; ++i) merge.push_back("{{Param.PartsDir}}/part_" + std::to_string(i) + ".exr");
  for (const char* a : {"-o", "{{Param.Output}}", "--quiet"}) merge.push_back(a);
  const json t = {
      {"specificationVersion", "jobtemplate-2023-09"},
      {"name", job.name},
      {"description", "narval: " + std::to_string(job.spp) + " spp of " + fs::path(job.scene).filename().string() +
                          " in " + std::to_string(job.tasks) + " sample ranges, then merged bit for bit"},
      {"parameterDefinitions",
       json::array({{{"name", "Narval"}, {"type", "STRING"}, {"default", job.narval},
                     {"description", "The narval binary on the workers"}},
                    {{"name", "Scene"}, {"type", "PATH"}, {"objectType", "FILE"}, {"dataFlow", "IN"}},
                    {{"name", "PartsDir"}, {"type", "PATH"}, {"objectType", "DIRECTORY"}, {"dataFlow", "OUT"}},
                    {{"name", "Output"}, {"type", "PATH"}, {"objectType", "FILE"}, {"dataFlow", "OUT"}}})},
      {"steps",
       json::array(
           {{{"name", "Render"},
             {"parameterSpace",
              {{"taskParameterDefinitions",
                json::array({{{"name", "Part"}, {"type", "INT"}, {"range", parts}},
                             {{"name", "Samples"}, {"type", "STRING"}, {"range", samples}}})},
               {"combination", "(Part, Samples)"}}},
             {"script", {{"actions", {{"onRun", {{"command", "{{Param.Narval}}"}, {"args", render}}}}}}}},
            {{"name", "Merge"},
             {"dependencies", json::array({{{"dependsOn", "Render"}}})},
             {"script", {{"actions", {{"onRun", {{"command", "{{Param.Narval}}"}, {"args", merge}}}}}}}}})}};
  return t.dump(2) + "\n";
}

// Deadline Cloud's job bundle file of parameter values.
std::string deadlineParameterValues(const FarmJob& job) {
  nlohmann::json values = nlohmann::json::array();
  for (const auto& [name, value] : openJdParameters(job)) values.push_back({{"name", name}, {"value", value}});
  return nlohmann::json({{"parameterValues", values}}).dump(2) + "\n";
}

}  // namespace

std::vector<std::pair<std::string, std::string>> openJdParameters(const FarmJob& job) {
  return {{"Scene", job.scene}, {"PartsDir", job.jobDir + "/parts"}, {"Output", job.output}};
}

std::vector<std::string> openJdRunCommand(const FarmJob& job) {
  std::vector<std::string> argv = {"openjd", "run", job.jobDir + "/template.json"};
  for (const auto& [name, value] : openJdParameters(job)) argv.insert(argv.end(), {"-p", name + "=" + value});
  return argv;
}

std::vector<std::string> writeFarmFiles(const FarmJob& job, Scheduler scheduler) {
  fs::create_directories(job.jobDir + "/logs");
  std::vector<std::pair<std::string, std::string>> files;
  switch (scheduler) {
    case Scheduler::Slurm:
      files = {{"task.sh", taskScript(job)},
               {"merge.sh", mergeScript(job)},
               {"render.sbatch", slurmRenderScript(job)},
               {"merge.sbatch", slurmMergeScript(job)},
               {"submit.sh", slurmSubmitScript(job)}};
      break;
    case Scheduler::OpenJd:
      files = {{"template.json", openJdTemplate(job)}, {"parameter_values.json", deadlineParameterValues(job)}};
      break;
    case Scheduler::Local:
      files = {{"task.sh", taskScript(job)}, {"merge.sh", mergeScript(job)}, {"run.sh", localScript(job)}};
      break;
  }
  std::vector<std::string> written;
  for (const auto& [name, text] : files) {
    const std::string path = job.jobDir + "/" + name;
    if (name.size() > 5 && name.substr(name.size() - 5) == ".json") writeTextAtomic(path, text);
    else writeScript(path, text);
    written.push_back(path);
  }
  return written;
}

}  // namespace narval
