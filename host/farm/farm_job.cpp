#include "farm/farm_job.h"

#include <filesystem>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/shell_quote.h"
#include "render/render_exr.h"

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

bool schedulerFromName(const std::string& name, Scheduler* out) {
  for (Scheduler s : {Scheduler::Slurm, Scheduler::OpenJd, Scheduler::Local})
    if (name == schedulerName(s)) {
      *out = s;
      return true;
    }
  return false;
}

std::string FarmJob::logPath(int task) const { return jobDir + "/logs/task_" + std::to_string(task) + ".log"; }
std::string FarmJob::timePath(int task) const { return jobDir + "/logs/task_" + std::to_string(task) + ".time"; }
std::string FarmJob::finalLogPath() const { return jobDir + "/logs/final.log"; }
std::string FarmJob::finalTimePath() const { return jobDir + "/logs/final.time"; }


FarmJob renderFarmJob(const std::string& narval, const std::string& scene, const std::vector<std::string>& renderArgs,
                      int spp, int tasks, const std::string& jobDir, const std::string& output,
                      const std::string& renderKey, const std::string& name) {
  FarmJob job;
  job.name = name;
  job.jobDir = jobDir;
  job.narval = narval;
  std::vector<std::pair<int, int>> ranges;
  for (int i = 0; i < tasks; ++i) {
    const int a = int((long long)i * spp / tasks), b = int((long long)(i + 1) * spp / tasks);
    ranges.push_back({a, b});
    FarmTask t;
    t.output = jobDir + "/parts/part_" + std::to_string(i) + ".exr";
    t.label = "samples [" + std::to_string(a) + ", " + std::to_string(b) + ")";
    t.argv = {narval, "render", scene};
    t.argv.insert(t.argv.end(), renderArgs.begin(), renderArgs.end());
    t.argv.insert(t.argv.end(),
                  {"--samples", std::to_string(a) + ":" + std::to_string(b), "-o", t.output, "--resume", "--quiet"});
    job.tasks.push_back(t);
  }
  job.finalOutput = output;
  job.finalArgv = {narval, "merge"};
  for (const FarmTask& t : job.tasks) job.finalArgv.push_back(t.output);
  job.finalArgv.insert(job.finalArgv.end(), {"-o", output, "--quiet"});
  job.taskDone = [tasks = job.tasks, ranges, renderKey](int i) {
    return renderCovers(tasks[size_t(i)].output, renderKey, ranges[size_t(i)].first, ranges[size_t(i)].second);
  };
  job.finalDone = [output, renderKey, spp] { return renderCovers(output, renderKey, 0, spp); };
  job.taskResumable = [tasks = job.tasks, ranges, renderKey](int i) {
    try {
      const RenderPart p = readRenderPartHeader(tasks[size_t(i)].output);
      return p.attribute("narval:render_key") == renderKey && p.accumulator.begin == ranges[size_t(i)].first &&
             p.accumulator.end() <= ranges[size_t(i)].second;
    } catch (const std::exception&) {
      return false;
    }
  };
  job.openJd = [=] {
    using nlohmann::json;
    OpenJdForm f;
    f.pathParameters = json::array(
        {{{"name", "Scene"}, {"type", "PATH"}, {"objectType", "FILE"}, {"dataFlow", "IN"}},
         {{"name", "PartsDir"}, {"type", "PATH"}, {"objectType", "DIRECTORY"}, {"dataFlow", "OUT"}},
         {{"name", "Output"}, {"type", "PATH"}, {"objectType", "FILE"}, {"dataFlow", "OUT"}}});
    f.pathValues = {{"Scene", scene}, {"PartsDir", jobDir + "/parts"}, {"Output", output}};
    json parts = json::array(), samples = json::array();
    for (int i = 0; i < tasks; ++i) {
      parts.push_back(i);
      samples.push_back(std::to_string(ranges[size_t(i)].first) + ":" + std::to_string(ranges[size_t(i)].second));
    }
    f.taskParameters = json::array({{{"name", "Part"}, {"type", "INT"}, {"range", parts}},
                                    {{"name", "Samples"}, {"type", "STRING"}, {"range", samples}}});
    f.combination = "(Part, Samples)";
    f.taskArgs = {"render", "{{Param.Scene}}"};
    for (const std::string& a : renderArgs) f.taskArgs.push_back(a);
    for (const char* a : {"--samples", "{{Task.Param.Samples}}", "-o", "{{Param.PartsDir}}/part_{{Task.Param.Part}}.exr",
                          "--resume", "--quiet"})
      f.taskArgs.push_back(a);
    f.finalArgs = {"merge"};
    for (int i = 0; i < tasks; ++i) f.finalArgs.push_back("{{Param.PartsDir}}/part_" + std::to_string(i) + ".exr");
    for (const char* a : {"-o", "{{Param.Output}}", "--quiet"}) f.finalArgs.push_back(a);
    f.taskValues = [samples](int i) { return json{{"Part", i}, {"Samples", samples[size_t(i)]}}; };
    return f;
  };
  return job;
}

std::vector<int> missingTasks(const FarmJob& job) {
  std::vector<int> missing;
  for (int i = 0; i < int(job.tasks.size()); ++i)
    if (!job.taskDone(i)) missing.push_back(i);
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

std::string lastTask(const FarmJob& job) { return std::to_string(int(job.tasks.size()) - 1); }

std::string taskScript(const FarmJob& job) {
  std::string cases;
  for (size_t i = 0; i < job.tasks.size(); ++i)
    cases += "  " + std::to_string(i) + ")  # " + job.tasks[i].label + "\n    " + shellJoined(job.tasks[i].argv) + "\n    ;;\n";
  return "#!/bin/sh\n"
         "# One task of the narval farm job " + job.name + " by index (0 to " + lastTask(job) +
         "): its command below, then its\n# start and end times into logs/task_I.time. Usage: task.sh I. Written by narval.\n"
         "set -eu\n"
         "job=" + shellQuoted(job.jobDir) + "\n"
         "mkdir -p \"$job/logs\"\n" +
         timed("case $1 in\n" + cases + "  *)\n    echo \"task.sh: no task '$1' (0 to " + lastTask(job) +
                   ")\" >&2\n    exit 2\n    ;;\nesac",
               "\"$job/logs/task_$1.time\"");
}

std::string finalScript(const FarmJob& job) {
  return "#!/bin/sh\n# The last step of the narval farm job " + job.name + " (" + job.stepNames[1] +
         "), once every task has succeeded;\n# its times into logs/final.time.\nset -eu\nmkdir -p " +
         shellQuoted(job.jobDir + "/logs") + "\n" + timed(shellJoined(job.finalArgv), shellQuoted(job.finalTimePath()));
}

std::string slurmTaskScript(const FarmJob& job) {
  return "#!/bin/sh\n"
         "#SBATCH --job-name=" + job.name + "\n"
         "#SBATCH --array=0-" + lastTask(job) + "\n"
         "#SBATCH --output=" + job.jobDir + "/logs/task_%a.log\n"
         "# One array task per task.sh entry. Add --cpus-per-task, --time or --partition here or on the\n"
         "# sbatch line as the cluster needs; the pixels never depend on them.\n"
         "exec " + shellQuoted(job.jobDir + "/task.sh") + " \"$SLURM_ARRAY_TASK_ID\"\n";
}

std::string slurmFinalScript(const FarmJob& job) {
  return "#!/bin/sh\n"
         "#SBATCH --job-name=" + job.name + "-final\n"
         "#SBATCH --output=" + job.finalLogPath() + "\n"
         "exec " + shellQuoted(job.jobDir + "/final.sh") + "\n";
}

std::string slurmSubmitScript(const FarmJob& job) {
  return "#!/bin/sh\n"
         "# Submits the tasks as a job array, then the final step once every task has succeeded (a\n"
         "# failed task cancels it). Extra arguments go to the array's sbatch, e.g. --array=3,5 to run\n"
         "# only tasks 3 and 5.\n"
         "set -eu\n"
         "array=$(sbatch --parsable \"$@\" " + shellQuoted(job.jobDir + "/tasks.sbatch") + ")\n"
         "array=${array%%;*}\n"
         "final=$(sbatch --parsable --dependency=afterok:$array --kill-on-invalid-dep=yes " +
         shellQuoted(job.jobDir + "/final.sbatch") + ")\n"
         "echo \"task array $array, final job ${final%%;*}\"\n";
}

std::string localScript(const FarmJob& job) {
  return "#!/bin/sh\n# The narval farm job " + job.name + " on this machine: every task in turn, then the final step.\n"
         "set -eu\ni=0\nwhile [ $i -le " + lastTask(job) + " ]; do\n  " + shellQuoted(job.jobDir + "/task.sh") +
         " $i\n  i=$((i + 1))\ndone\n" + shellQuoted(job.jobDir + "/final.sh") + "\n";
}

// An Open Job Description template (jobtemplate-2023-09): the tasks' step, then the final step
// depending on it. With an OpenJdForm, narval runs directly with the files as PATH parameters; else
// each step runs task.sh's or final.sh's text as an embedded file.
std::string openJdTemplate(const FarmJob& job) {
  using nlohmann::json;
  json params = json::array({{{"name", "Narval"}, {"type", "STRING"}, {"default", job.narval},
                              {"description", "The narval binary on the workers"}}});
  json taskSpace, taskScriptJson, finalScriptJson;
  if (job.openJd) {
    const OpenJdForm f = job.openJd();
    for (const json& p : f.pathParameters) params.push_back(p);
    taskSpace = {{"taskParameterDefinitions", f.taskParameters}};
    if (!f.combination.empty()) taskSpace["combination"] = f.combination;
    taskScriptJson = {{"actions", {{"onRun", {{"command", "{{Param.Narval}}"}, {"args", f.taskArgs}}}}}};
    finalScriptJson = {{"actions", {{"onRun", {{"command", "{{Param.Narval}}"}, {"args", f.finalArgs}}}}}};
  } else {
    json indices = json::array();
    for (size_t i = 0; i < job.tasks.size(); ++i) indices.push_back(i);
    taskSpace = {{"taskParameterDefinitions", json::array({{{"name", "Task"}, {"type", "INT"}, {"range", indices}}})}};
    // OpenJD wants `args` absent rather than empty.
    auto embedded = [](const std::string& text, const std::vector<std::string>& args) {
      json run = {{"command", "{{Task.File.Run}}"}};
      if (!args.empty()) run["args"] = args;
      return json{{"embeddedFiles", json::array({{{"name", "Run"}, {"type", "TEXT"}, {"runnable", true}, {"data", text}}})},
                  {"actions", {{"onRun", run}}}};
    };
    taskScriptJson = embedded(taskScript(job), {"{{Task.Param.Task}}"});
    finalScriptJson = embedded(finalScript(job), {});
  }
  const json t = {
      {"specificationVersion", "jobtemplate-2023-09"},
      {"name", job.name},
      {"parameterDefinitions", params},
      {"steps", json::array({{{"name", job.stepNames[0]}, {"parameterSpace", taskSpace}, {"script", taskScriptJson}},
                             {{"name", job.stepNames[1]},
                              {"dependencies", json::array({{{"dependsOn", job.stepNames[0]}}})},
                              {"script", finalScriptJson}}})}};
  return t.dump(2) + "\n";
}

// Deadline Cloud's job bundle file of parameter values.
std::string deadlineParameterValues(const OpenJdForm& f) {
  nlohmann::json values = nlohmann::json::array();
  for (const auto& [name, value] : f.pathValues) values.push_back({{"name", name}, {"value", value}});
  return nlohmann::json({{"parameterValues", values}}).dump(2) + "\n";
}

}  // namespace

std::vector<std::string> openJdRunCommand(const FarmJob& job) {
  std::vector<std::string> argv = {"openjd", "run", job.jobDir + "/template.json"};
  if (job.openJd)
    for (const auto& [name, value] : job.openJd().pathValues) argv.insert(argv.end(), {"-p", name + "=" + value});
  return argv;
}

nlohmann::json openJdTaskList(const FarmJob& job, const std::vector<int>& tasks) {
  nlohmann::json list = nlohmann::json::array();
  const std::function<nlohmann::json(int)> values =
      job.openJd ? job.openJd().taskValues : [](int i) { return nlohmann::json{{"Task", i}}; };
  for (int t : tasks) list.push_back(values(t));
  return list;
}

std::vector<std::string> writeFarmFiles(const FarmJob& job, Scheduler scheduler) {
  fs::create_directories(job.jobDir + "/logs");
  std::vector<std::pair<std::string, std::string>> files;
  switch (scheduler) {
    case Scheduler::Slurm:
      files = {{"task.sh", taskScript(job)},
               {"final.sh", finalScript(job)},
               {"tasks.sbatch", slurmTaskScript(job)},
               {"final.sbatch", slurmFinalScript(job)},
               {"submit.sh", slurmSubmitScript(job)}};
      break;
    case Scheduler::OpenJd:
      files = {{"template.json", openJdTemplate(job)}};
      if (job.openJd) files.push_back({"parameter_values.json", deadlineParameterValues(job.openJd())});
      break;
    case Scheduler::Local:
      files = {{"task.sh", taskScript(job)}, {"final.sh", finalScript(job)}, {"run.sh", localScript(job)}};
      break;
  }
  std::vector<std::string> written;
  for (const auto& [name, text] : files) {
    const std::string path = job.jobDir + "/" + name;
    if (fs::path(name).extension() == ".json") writeTextAtomic(path, text);
    else writeScript(path, text);
    written.push_back(path);
  }
  return written;
}

}  // namespace narval
