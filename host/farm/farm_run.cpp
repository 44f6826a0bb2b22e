#include "farm/farm_run.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "farm/process.h"
#include "image/image.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

// The "start end" seconds a time file holds, as end - start; -1 when absent or unreadable.
double timeFileSeconds(const std::string& path) {
  std::ifstream in(path);
  double start = 0, end = 0;
  if (!(in >> start >> end)) return -1;
  return end - start;
}

std::string firstLine(const std::string& text) {
  const std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? text : line;
}

// Runs a scheduler command to its end; its stdout, or a runtime_error with its first error line.
std::string schedulerCommand(const std::vector<std::string>& argv) {
  std::string out, err;
  const ProcessEnd end = runCapturing(argv, &out, &err);
  if (!end.ok())
    throw std::runtime_error(argv[0] + " failed (" + end.describe() + "): " + firstLine(err.empty() ? out : err));
  return out;
}

void runLocalTasks(const FarmJob& job, const std::vector<int>& tasks, int parallel,
                   const std::function<void(const std::string&)>& say) {
  std::map<pid_t, int> running;
  size_t next = 0;
  while (next < tasks.size() || !running.empty()) {
    while (next < tasks.size() && int(running.size()) < std::max(1, parallel)) {
      const int t = tasks[next++];
      fs::remove(job.timePath(t));
      running[startProcess({"sh", job.jobDir + "/task.sh", std::to_string(t)}, job.logPath(t))] = t;
    }
    pid_t pid = -1;
    const ProcessEnd end = waitAnyProcess(&pid);
    const auto it = running.find(pid);
    if (it == running.end()) {
      if (pid < 0) break;  // no children left (should not happen while `running` is not empty)
      continue;
    }
    if (!end.ok()) say("task " + std::to_string(it->second) + ": " + end.describe());
    running.erase(it);
  }
}

void runLocalFinal(const FarmJob& job) {
  waitProcess(startProcess({"sh", job.jobDir + "/final.sh"}, job.finalLogPath()));
}

// The array over `tasks` (none: the final job alone), then the final job depending on it.
std::string submitSlurm(const FarmJob& job, const std::vector<int>& tasks) {
  std::string list, array;
  for (int t : tasks) list += (list.empty() ? "" : ",") + std::to_string(t);
  std::vector<std::string> final = {"sbatch", "--parsable", "--wait"};
  if (!tasks.empty()) {
    array = schedulerCommand({"sbatch", "--parsable", "--array=" + list, job.jobDir + "/tasks.sbatch"});
    array = array.substr(0, array.find_first_of(";\n"));
    final.insert(final.end(), {"--dependency=afterok:" + array, "--kill-on-invalid-dep=yes"});
  }
  final.push_back(job.jobDir + "/final.sbatch");
  // --wait returns when the final job ends, whether it ran or was cancelled (a failed task cancels
  // it); which one is read from the files afterwards.
  std::string out, err;
  const ProcessEnd end = runCapturing(final, &out, &err);
  const std::string id = out.substr(0, out.find_first_of(";\n"));
  if (id.empty()) throw std::runtime_error("sbatch of the final job failed (" + end.describe() + "): " + firstLine(err));
  return (array.empty() ? "" : "array " + array + ", ") + "final job " + id;
}

// OpenJD may run narval itself, not final.sh: the final step's time is measured here.
double runOpenJd(const FarmJob& job, const std::vector<int>& tasks) {
  // openjd prints everything on stdout; the logs keep it. A failed task ends the run (exit 1).
  std::vector<std::string> first = openJdRunCommand(job), last = first;
  first.insert(first.end(), {"--step", job.stepNames[0], "--tasks", openJdTaskList(job, tasks).dump()});
  last.insert(last.end(), {"--step", job.stepNames[1]});
  const bool ran = tasks.empty() || waitProcess(startProcess(first, job.jobDir + "/logs/openjd_tasks.log")).ok();
  if (!ran) return -1;
  const auto t0 = std::chrono::steady_clock::now();
  waitProcess(startProcess(last, job.finalLogPath()));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

FarmOutcome runFarm(const FarmJob& job, Scheduler scheduler, int parallel,
                    const std::function<void(const std::string&)>& say) {
  const auto t0 = std::chrono::steady_clock::now();
  fs::create_directories(job.jobDir + "/logs");
  const std::vector<int> toRun = missingTasks(job);
  std::vector<bool> reused(job.tasks.size(), true);
  for (int t : toRun) reused[size_t(t)] = false;
  FarmOutcome o;
  const int count = int(job.tasks.size());
  if (int(toRun.size()) < count)
    say(std::to_string(count - int(toRun.size())) + " of " + std::to_string(count) +
        " tasks already have their output; running the other " + std::to_string(toRun.size()));
  fs::remove(job.finalTimePath());
  for (int t : toRun) {
    fs::remove(job.timePath(t));
    // What a task left and cannot continue (another render's part, a broken file) goes first.
    const std::string& out = job.tasks[size_t(t)].output;
    if (fs::exists(out) && !(job.taskResumable && job.taskResumable(t))) fs::remove(out);
  }
  // The output counts as merged only when this run wrote it (an older one may be there).
  std::error_code ec;
  const auto outputTime = fs::last_write_time(job.finalOutput, ec);
  const bool outputExisted = !ec;
  double openJdFinalSeconds = -1;
  switch (scheduler) {
    case Scheduler::Local:
      if (!toRun.empty()) runLocalTasks(job, toRun, parallel, say);
      if (missingTasks(job).empty()) runLocalFinal(job);
      break;
    case Scheduler::Slurm:
      o.schedulerIds = submitSlurm(job, toRun);
      break;
    case Scheduler::OpenJd:
      openJdFinalSeconds = runOpenJd(job, toRun);
      break;
  }
  const std::vector<int> missing = missingTasks(job);
  for (int t = 0; t < count; ++t) {
    FarmTaskOutcome r;
    r.task = t;
    r.ok = std::find(missing.begin(), missing.end(), t) == missing.end();
    r.reused = reused[size_t(t)];
    r.wallSeconds = timeFileSeconds(job.timePath(t));
    if (r.ok) r.renderSeconds = std::atof(readExrAttributes(job.tasks[size_t(t)].output)["narval:seconds"].c_str());
    o.tasks.push_back(r);
  }
  o.finalSeconds = scheduler == Scheduler::OpenJd ? openJdFinalSeconds : timeFileSeconds(job.finalTimePath());
  const auto newTime = fs::last_write_time(job.finalOutput, ec);
  o.finalDone = missing.empty() && job.finalDone() && (!outputExisted || (!ec && newTime != outputTime));
  o.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

}  // namespace narval
