// farm_command.cpp: `narval farm SCENE.json --spp N --tasks K --scheduler slurm|openjd|local -o
// OUT.exr [--submit]` (farm/farm_job.h, farm/farm_run.h).
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/farm_cli.h"
#include "farm/farm_job.h"
#include "farm/farm_run.h"
#include "farm/process.h"
#include "render/render_exr.h"
#include "scene/input_error.h"
#include "util/shell_quote.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, s >= 100 ? "%.0f s" : "%.3g s", s);
  return buf;
}

}  // namespace

std::string thisNarvalBinary() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("narval") : self.string();
}

int runOrWriteFarmJob(const FarmJob& job, Scheduler scheduler, bool submit, int parallel, const std::string& who) {
  const std::vector<std::string> files = writeFarmFiles(job, scheduler);
  std::cout << "wrote";
  for (const std::string& f : files) std::cout << " " << fs::path(f).filename().string();
  std::cout << " in " << job.jobDir << "\n";
  if (!submit) {
    switch (scheduler) {
      case Scheduler::Slurm: std::cout << "submit with: sh " << shellQuoted(job.jobDir + "/submit.sh") << "\n"; break;
      case Scheduler::OpenJd:
        std::cout << "run with: " << shellJoined(openJdRunCommand(job))
                  << "\n(or submit the folder to Deadline Cloud: deadline bundle submit " << shellQuoted(job.jobDir) << ")\n";
        break;
      case Scheduler::Local: std::cout << "run with: sh " << shellQuoted(job.jobDir + "/run.sh") << "\n"; break;
    }
    return 0;
  }

  const FarmOutcome o = runFarm(job, scheduler, parallel, [&who](const std::string& line) {
    std::cout << who << ": " << line << "\n" << std::flush;
  });
  double taskSum = 0, longest = 0;
  int failed = 0;
  for (const FarmTaskOutcome& t : o.tasks) {
    const std::string what = "task " + std::to_string(t.task) + " " + job.tasks[size_t(t.task)].label;
    if (!t.ok) {
      ++failed;
      std::cerr << "narval: " << who << ": " << what << " failed: no output written; its log: " << job.logPath(t.task)
                << "\n";
      continue;
    }
    if (t.reused) {
      std::cout << what << ": output from an earlier run\n";
      continue;
    }
    // Wall time from task.sh's clock; OpenJD runs narval directly, so there only the render's.
    const double wall = t.wallSeconds >= 0 ? t.wallSeconds : t.renderSeconds;
    taskSum += wall;
    longest = std::max(longest, wall);
    if (t.wallSeconds >= 0)
      std::cout << what << ": " << seconds(t.wallSeconds) << " (rendering " << seconds(t.renderSeconds) << ")\n";
    else
      std::cout << what << ": rendering " << seconds(t.renderSeconds) << "\n";
  }
  const std::string step = job.stepNames[1];  // "Merge", "Collect"
  std::string lower = step;
  lower[0] = char(std::tolower(static_cast<unsigned char>(lower[0])));
  if (failed > 0) {
    std::cerr << "narval: " << who << ": " << failed << " of " << o.tasks.size() << " tasks failed; no " << lower
              << ", " << job.finalOutput << " not written. Run the same command again to run only the missing tasks.\n";
    return 1;
  }
  if (!o.finalDone) {
    std::cerr << "narval: " << who << ": the " << lower << " failed; its log: " << job.finalLogPath() << "\n";
    return 1;
  }
  std::cout << lower << ": " << seconds(o.finalSeconds) << "\n";
  std::cout << "wrote " << job.finalOutput << " (" << o.tasks.size() << " tasks"
            << (o.schedulerIds.empty() ? "" : "; slurm " + o.schedulerIds) << "): tasks " << seconds(taskSum)
            << " in all, longest " << seconds(longest) << ", " << seconds(o.wallSeconds) << " from submission to "
            << lower << "\n";
  return 0;
}

namespace {

struct FarmArgs {
  std::string scene, out, scheduler, jobDir, narval, resolution, device, majorant;
  int spp = -1, tasks = 0, parallel = 1, bounces = -1, majorantResolution = -1, threads = 0;
  long long seed = -1;
  bool submit = false;
  std::vector<std::string> sets;
};

// The options every task's render takes, as render's command line spells them.
std::vector<std::string> renderArgs(const FarmArgs& a) {
  std::vector<std::string> v;
  for (const std::string& s : a.sets) v.insert(v.end(), {"--set", s});
  if (!a.resolution.empty()) v.insert(v.end(), {"--resolution", a.resolution});
  if (a.seed >= 0) v.insert(v.end(), {"--seed", std::to_string(a.seed)});
  if (a.bounces >= 0) v.insert(v.end(), {"--bounces", std::to_string(a.bounces)});
  if (!a.device.empty()) v.insert(v.end(), {"--device", a.device});
  if (!a.majorant.empty()) v.insert(v.end(), {"--majorant", a.majorant});
  if (a.majorantResolution >= 0) v.insert(v.end(), {"--majorant-resolution", std::to_string(a.majorantResolution)});
  if (a.threads > 0) v.insert(v.end(), {"--threads", std::to_string(a.threads)});
  return v;
}

// The scene as its tasks will load it: the same overrides render derives from the same flags.
std::vector<std::string> sceneOverrides(const FarmArgs& a) {
  std::vector<std::string> o = a.sets;
  if (!a.resolution.empty()) o.push_back(resolutionOverride(a.resolution));
  if (a.seed >= 0) o.push_back("renderer.seed=" + std::to_string(a.seed));
  if (a.bounces >= 0) o.push_back("renderer.bounces=" + std::to_string(a.bounces));
  if (a.spp >= 0) o.push_back("renderer.spp=" + std::to_string(a.spp));
  return o;
}



int runFarmCommand(const FarmArgs& a) {
  Scheduler scheduler = Scheduler::Local;
  if (a.scheduler == "slurm") scheduler = Scheduler::Slurm;
  else if (a.scheduler == "openjd") scheduler = Scheduler::OpenJd;
  const Scene scene = loadScene(a.scene, sceneOverrides(a));
  for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
  if (scene.renderer.algorithm != Algorithm::Pathtrace)
    throw inputError("--scheduler", "", std::string("only path-traced renders split into sample ranges; the algorithm is ") +
                                            algorithmName(scene.renderer.algorithm));
  const int spp = scene.renderer.spp;
  if (a.tasks > spp)
    throw inputError("--tasks", "", std::to_string(a.tasks) + " tasks for " + std::to_string(spp) +
                                        " spp; a task renders at least one sample");
  SceneGridStorage gridStorage;
  loadSceneGrids(scene, gridStorage);  // a missing or broken grid is said now, not by every task

  const fs::path out = fs::absolute(a.out.empty() ? fs::path(fs::path(a.scene).stem().string() + ".exr") : fs::path(a.out));
  if (out.extension() != ".exr") throw inputError("-o", "", "the output must be an .exr file, got '" + a.out + "'");
  const fs::path jobDir =
      fs::absolute(a.jobDir.empty() ? fs::path(out).replace_extension(".farm") : fs::path(a.jobDir)).lexically_normal();
  checkOutputWritable(out.string(), "-o");
  checkOutputWritable((jobDir / "logs" / ".probe").string(), "--job-dir");
  if (a.submit) {
    const char* tool = scheduler == Scheduler::Slurm ? "sbatch" : scheduler == Scheduler::OpenJd ? "openjd" : nullptr;
    if (tool && !onPath(tool))
      throw inputError("--submit", "", std::string(tool) + " is not on PATH" +
                                           (scheduler == Scheduler::OpenJd ? " (pip install openjd-cli)" : "") +
                                           "; leave out --submit to write the job only");
  }

  const std::string narval = a.narval.empty() ? thisNarvalBinary() : fs::absolute(a.narval).string();
  const FarmJob job = renderFarmJob(narval, fs::absolute(a.scene).lexically_normal().string(), renderArgs(a), spp,
                                    a.tasks, jobDir.string(), out.lexically_normal().string(), renderKey(scene),
                                    "narval-" + fs::path(a.scene).stem().string());
  std::cout << "farm: " << job.name << ", " << spp << " spp in " << a.tasks << (a.tasks == 1 ? " task" : " tasks")
            << " for " << schedulerName(scheduler) << ": ";
  return runOrWriteFarmJob(job, scheduler, a.submit, a.parallel, "farm");
}

}  // namespace

Command addFarmCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "farm",
      "Split a path-traced render into sample ranges as a job for a scheduler (Slurm, Open Job Description, or "
      "this machine): one task per range, then `narval merge`; the result is bit for bit one render's");
  auto a = std::make_shared<FarmArgs>();
  sub->add_option("SCENE.json", a->scene, "Scene file")->required();
  sub->add_option("--spp", a->spp, "Samples per pixel of the whole render (default: the scene's)")->check(atLeast(1));
  sub->add_option("--tasks", a->tasks, "Number of tasks (sample ranges), at most spp")->required()->check(atLeast(1));
  sub->add_option("--scheduler", a->scheduler,
                  "slurm (a job array and a dependent merge job), openjd (an Open Job Description template: openjd "
                  "run, Deadline Cloud) or local (processes on this machine)")
      ->required()
      ->check(CLI::IsMember({"slurm", "openjd", "local"}));
  sub->add_option("-o,--output", a->out, "Output .exr of the merged render; default: <scene name>.exr");
  sub->add_option("--job-dir", a->jobDir, "Folder for the job's scripts, parts and logs; default: OUT with .farm");
  sub->add_flag("--submit", a->submit,
                "Run the job and wait: sbatch (slurm), openjd run (openjd) or child processes (local); tasks whose "
                "part is already there are not run again. Reports each task's time and the merge's");
  sub->add_option("--parallel", a->parallel, "local: tasks run at once (default 1)")->check(atLeast(1));
  sub->add_option("--narval", a->narval, "The narval binary the tasks run (default: this one)");
  sub->add_option("--set", a->sets, "Override a scene value for every task: dotted.path=value (repeatable)");
  sub->add_option("--resolution", a->resolution, "WIDTHxHEIGHT");
  sub->add_option("--seed", a->seed, "Random seed")->check(between(0, 4294967295LL));
  sub->add_option("--bounces", a->bounces, "Real scattering events per path")->check(atLeast(0));
  sub->add_option("--device", a->device, "Device index or name substring, on every task's machine");
  sub->add_option("--majorant", a->majorant, "grid | global | auto (see narval render --help)")
      ->check(CLI::IsMember({"auto", "grid", "global"}));
  sub->add_option("--majorant-resolution", a->majorantResolution, "Majorant grid cells (0: automatic)")
      ->check(atLeast(0));
  sub->add_option("--threads", a->threads, "PoCL worker threads of every task (CPU devices)")->check(atLeast(1));
  return {sub, [a]() { return runFarmCommand(*a); }};
}

}  // namespace narval
