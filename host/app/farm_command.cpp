// farm_command.cpp: `narval farm SCENE.json --spp N --tasks K --scheduler slurm|openjd|local -o
// OUT.exr [--submit]` (farm/farm_job.h, farm/farm_run.h).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/farm_cli.h"
#include "core/input_error.h"
#include "farm/farm_job.h"
#include "farm/process.h"
#include "render/render_exr.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct FarmArgs {
  std::string scene, out, scheduler, jobDir, narval, resolution, device, majorant;
  int spp = -1, tasks = 0, parallel = 1, bounces = -1, majorantResolution = -1, threads = 0;
  long long seed = -1;
  double checkpointSeconds = 0;
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
  if (a.checkpointSeconds > 0) {
    std::ostringstream seconds;
    seconds << a.checkpointSeconds;
    v.insert(v.end(), {"--write-partial-images", seconds.str()});
  }
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
  schedulerFromName(a.scheduler, &scheduler);  // CLI11 checked the name
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
  sub->add_option("--checkpoint", a->checkpointSeconds,
                  "Every SECONDS, each task writes its part so far (render --write-partial-images): a task killed "
                  "or preempted then continues from there when the job runs again")
      ->check(greaterThanZero());
  return {sub, [a]() { return runFarmCommand(*a); }};
}

}  // namespace narval
