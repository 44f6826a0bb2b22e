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
#include "render/render_exr.h"

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

void runLocalMerge(const FarmJob& job) {
  waitProcess(startProcess({"sh", job.jobDir + "/merge.sh"}, job.mergeLogPath()));
}

// The array over `tasks` (none: the merge alone), then the merge depending on it.
std::string submitSlurm(const FarmJob& job, const std::vector<int>& tasks) {
  std::string list, array;
  for (int t : tasks) list += (list.empty() ? "" : ",") + std::to_string(t);
  std::vector<std::string> merge = {"sbatch", "--parsable", "--wait"};
  if (!tasks.empty()) {
    array = schedulerCommand({"sbatch", "--parsable", "--array=" + list, job.jobDir + "/render.sbatch"});
    array = array.substr(0, array.find_first_of(";\n"));
    merge.insert(merge.end(), {"--dependency=afterok:" + array, "--kill-on-invalid-dep=yes"});
  }
  merge.push_back(job.jobDir + "/merge.sbatch");
  // --wait returns when the merge ends, whether it ran or was cancelled (a failed task cancels it);
  // which one is read from the files afterwards.
  std::string out, err;
  const ProcessEnd end = runCapturing(merge, &out, &err);
  const std::string id = out.substr(0, out.find_first_of(";\n"));
  if (id.empty()) throw std::runtime_error("sbatch of the merge failed (" + end.describe() + "): " + firstLine(err));
  return (array.empty() ? "" : "array " + array + ", ") + "merge " + id;
}

// Whether `job.output` is this job's merged render of [0, N).
bool mergedOutput(const FarmJob& job) {
  try {
    const RenderPart p = readRenderPart(job.output);
    return p.attribute("narval:render_key") == job.renderKey && p.accumulator.begin == 0 &&
           p.accumulator.end() == job.spp;
  } catch (const std::exception&) {
    return false;
  }
}

// OpenJD runs narval itself, not task.sh: the merge's time is its step's, as measured here.
double runOpenJd(const FarmJob& job, const std::vector<int>& tasks) {
  nlohmann::json list = nlohmann::json::array();
  for (int t : tasks) {
    const auto [a, b] = job.range(t);
    list.push_back({{"Part", t}, {"Samples", std::to_string(a) + ":" + std::to_string(b)}});
  }
  // openjd prints everything on stdout; the logs keep it. A failed task ends the run (exit 1).
  std::vector<std::string> render = openJdRunCommand(job), merge = render;
  render.insert(render.end(), {"--step", "Render", "--tasks", list.dump()});
  merge.insert(merge.end(), {"--step", "Merge"});
  const bool rendered = tasks.empty() || waitProcess(startProcess(render, job.jobDir + "/logs/openjd_render.log")).ok();
  if (!rendered) return -1;
  const auto t0 = std::chrono::steady_clock::now();
  waitProcess(startProcess(merge, job.mergeLogPath()));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

FarmOutcome runFarm(const FarmJob& job, Scheduler scheduler, int parallel,
                    const std::function<void(const std::string&)>& say) {
  const auto t0 = std::chrono::steady_clock::now();
  fs::create_directories(job.jobDir + "/logs");
  const std::vector<int> todo = missingTasks(job);
  std::vector<bool> reused(size_t(job.tasks), true);
  for (int t : todo) reused[size_t(t)] = false;
  FarmOutcome o;
  if (todo.size() < size_t(job.tasks))
    say(std::to_string(job.tasks - int(todo.size())) + " of " + std::to_string(job.tasks) +
        " tasks already have their part; running the other " + std::to_string(todo.size()));
  fs::remove(job.mergeTimePath());
  for (int t : todo) fs::remove(job.timePath(t));
  // The output counts as merged only when this run wrote it (an older one may be there).
  std::error_code ec;
  const auto outputTime = fs::last_write_time(job.output, ec);
  const bool outputExisted = !ec;
  double openJdMergeSeconds = -1;
  switch (scheduler) {
    case Scheduler::Local:
      if (!todo.empty()) runLocalTasks(job, todo, parallel, say);
      if (missingTasks(job).empty()) runLocalMerge(job);
      break;
    case Scheduler::Slurm:
      o.schedulerIds = submitSlurm(job, todo);
      break;
    case Scheduler::OpenJd:
      openJdMergeSeconds = runOpenJd(job, todo);
      break;
  }
  const std::vector<int> missing = missingTasks(job);
  for (int t = 0; t < job.tasks; ++t) {
    FarmTaskOutcome r;
    r.task = t;
    r.ok = std::find(missing.begin(), missing.end(), t) == missing.end();
    r.reused = reused[size_t(t)];
    r.wallSeconds = timeFileSeconds(job.timePath(t));
    if (r.ok) r.renderSeconds = std::atof(readRenderPart(job.partPath(t)).attribute("narval:seconds").c_str());
    o.tasks.push_back(r);
  }
  o.mergeSeconds = scheduler == Scheduler::OpenJd ? openJdMergeSeconds : timeFileSeconds(job.mergeTimePath());
  const auto newTime = fs::last_write_time(job.output, ec);
  o.merged = missing.empty() && mergedOutput(job) && (!outputExisted || (!ec && newTime != outputTime));
  o.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

}  // namespace narval
