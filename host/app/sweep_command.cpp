// narval sweep: speed against perceptual error over spp or bounces (dissertation ch. 5). Renders
// the scene at each value, largest first (the reference, unless --reference FILE.exr), and writes
// into DIR one EXR per value, sweep.csv, sweep.json and the figure strip sweep.png.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <filesystem>
#include <iostream>
#include <regex>

#include <nlohmann/json.hpp>

#include "analysis/image_compare.h"
#include "analysis/sweep.h"
#include "app/cli_common.h"
#include "app/commands.h"
#include "app/farm_cli.h"
#include "app/progress_bar.h"
#include "core/input_error.h"
#include "farm/farm_job.h"
#include "image/image.h"
#include "render/pathtrace_renderer.h"
#include "render/render_common.h"
#include "render/render_exr.h"
#include "shared/structs.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct SweepArgs {
  std::string scene, out, spp, bounces, reference, device, resolution, algorithm;
  long long seed = -1;
  std::vector<std::string> sets;
  // As farm tasks (--scheduler): one render per value, then `sweep --collect` of them.
  std::string scheduler, jobDir, narval;
  bool submit = false, collect = false;
  int parallel = 1;
};

// The sweep's own arguments as its command line spells them (for the farm's --collect step).
std::vector<std::string> sweepArgv(const SweepArgs& a, const std::string& scene, const std::string& out) {
  std::vector<std::string> v = {"sweep", scene, "-o", out};
  if (!a.spp.empty()) v.insert(v.end(), {"--spp", a.spp});
  if (!a.bounces.empty()) v.insert(v.end(), {"--bounces", a.bounces});
  if (!a.reference.empty()) v.insert(v.end(), {"--reference", fs::absolute(a.reference).string()});
  if (!a.resolution.empty()) v.insert(v.end(), {"--resolution", a.resolution});
  if (a.seed >= 0) v.insert(v.end(), {"--seed", std::to_string(a.seed)});
  for (const std::string& set : a.sets) v.insert(v.end(), {"--set", set});
  return v;
}

// The render key of `base` rendered by `narval render SCENE --algorithm pathtrace --bounces B` with
// the sweep's overrides: what the farm task for that value writes (render_exr.h).
std::string taskRenderKey(const Scene& base, int bounces) {
  std::vector<std::string> overrides = base.overrides;
  overrides.push_back("renderer.algorithm=\"pathtrace\"");
  overrides.push_back("renderer.bounces=" + std::to_string(bounces));
  return renderKey(loadScene(base.sourcePath, overrides));
}

// The sweep as farm tasks: value V rendered by `narval render` into DIR/<sweepFileName>, the other
// parameter fixed as the scene has it; then `narval sweep ... --collect` in DIR. A task is done
// when its EXR is a path-traced render of the scene at V (its render key and spp).
FarmJob sweepFarmJob(const SweepArgs& a, const Scene& scene, SweepParameter parameter, const std::vector<int>& values,
                     const std::string& narval, const fs::path& dir, const fs::path& jobDir) {
  FarmJob job;
  const std::string sceneFile = fs::absolute(a.scene).lexically_normal().string();
  job.name = "narval-sweep-" + fs::path(a.scene).stem().string();
  job.jobDir = jobDir.string();
  job.narval = narval;
  job.stepNames = {"Render", "Collect"};
  std::vector<std::string> keys;
  std::vector<int> spps;
  std::vector<int> sorted = values;
  std::sort(sorted.rbegin(), sorted.rend());  // the order the sweep renders in: largest first
  for (int v : sorted) {
    const bool spp = parameter == SweepParameter::Spp;
    Scene at = scene;
    (spp ? at.renderer.spp : at.renderer.bounces) = v;
    FarmTask t;
    t.output = (dir / sweepFileName(parameter, v)).string();
    t.label = sweepLabel(parameter, v);
    t.argv = {narval, "render", sceneFile, "--algorithm", "pathtrace"};
    for (const std::string& set : a.sets) t.argv.insert(t.argv.end(), {"--set", set});
    if (!a.resolution.empty()) t.argv.insert(t.argv.end(), {"--resolution", a.resolution});
    if (a.seed >= 0) t.argv.insert(t.argv.end(), {"--seed", std::to_string(a.seed)});
    if (!a.device.empty()) t.argv.insert(t.argv.end(), {"--device", a.device});
    t.argv.insert(t.argv.end(), {"--spp", std::to_string(at.renderer.spp), "--bounces",
                                 std::to_string(at.renderer.bounces), "-o", t.output, "--quiet"});
    job.tasks.push_back(t);
    keys.push_back(taskRenderKey(scene, at.renderer.bounces));
    spps.push_back(at.renderer.spp);
  }
  job.finalArgv = sweepArgv(a, sceneFile, dir.string());
  job.finalArgv.insert(job.finalArgv.begin(), narval);
  job.finalArgv.push_back("--collect");
  job.finalOutput = (dir / "sweep.json").string();
  job.taskDone = [tasks = job.tasks, keys, spps](int i) {
    return renderCovers(tasks[size_t(i)].output, keys[size_t(i)], 0, spps[size_t(i)]);
  };
  job.finalDone = [out = job.finalOutput] { return fs::exists(out); };
  return job;
}

// --collect: a render the farm's task left in DIR, as runSweep takes it: the image and the stats
// its header records (render_exr.h). InputError when it is missing or not this sweep's.
RenderResult collectedRender(const Scene& s, const fs::path& exr) {
  if (!renderCovers(exr.string(), taskRenderKey(s, s.renderer.bounces), 0, s.renderer.spp))
    throw inputError(exr.string(), "narval:render_key",
                     "not a path-traced render of " + s.sourcePath + " at " + std::to_string(s.renderer.spp) + " spp and " +
                         std::to_string(s.renderer.bounces) + " bounces; run the sweep's farm task for it again");
  const RenderPart part = readRenderPartHeader(exr.string());
  RenderResult r;
  r.image = readExr(exr.string());
  RenderStats& st = r.stats;
  st.algorithm = "pathtrace";
  st.device = part.attribute("narval:device");
  st.width = part.width;
  st.height = part.height;
  st.spp = st.sppRequested = part.accumulator.samples;
  st.bounces = std::atoi(part.attribute("narval:bounces").c_str());
  st.seconds = std::strtod(part.attribute("narval:seconds").c_str(), nullptr);
  st.status = part.accumulator.status;
  st.majorant = part.attribute("narval:majorant");
  st.majorantResolution = std::atoi(part.attribute("narval:majorant_resolution").c_str());
  for (float v : r.image.rgb) st.nanPixels += std::isfinite(v) ? 0 : 1;
  return r;
}

// One integer option's value (the parameter that stays fixed).
int parseSingle(const std::string& text, const std::string& option, int minimum) {
  static const std::regex re(R"(^\s*(\d{1,10})\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, re) || std::stoll(m[1]) < minimum || std::stoll(m[1]) > 2147483647LL)
    throw inputError(option, "",
                     std::string("expected ") + (minimum > 0 ? "a positive" : "a non-negative") + " integer, got '" +
                         text + "'");
  return int(std::stoll(m[1]));
}

bool isList(const std::string& s) { return s.find(',') != std::string::npos; }

// Which of --spp and --bounces is swept: the one given as a list (or alone).
SweepParameter sweptParameter(const SweepArgs& a) {
  const bool hasSpp = !a.spp.empty(), hasBounces = !a.bounces.empty();
  if (!hasSpp && !hasBounces)
    throw inputError("--spp, --bounces", "", "give the values to sweep, e.g. --spp 10,100,1000 or --bounces 50,10,5");
  if (hasSpp && hasBounces) {
    if (isList(a.spp) == isList(a.bounces))
      throw inputError("--spp, --bounces", "",
                       "sweep exactly one: give one of them as a comma-separated list and the other as a single "
                       "value (got '" + a.spp + "' and '" + a.bounces + "')");
    return isList(a.spp) ? SweepParameter::Spp : SweepParameter::Bounces;
  }
  return hasSpp ? SweepParameter::Spp : SweepParameter::Bounces;
}

// The scene with the fixed parameter and the other flags as overrides, rendered by the path tracer.
Scene sweepScene(const SweepArgs& a, bool sweepSpp) {
  const bool hasSpp = !a.spp.empty(), hasBounces = !a.bounces.empty();
  std::vector<std::string> overrides = a.sets;
  if (sweepSpp && hasBounces) overrides.push_back("renderer.bounces=" + std::to_string(parseSingle(a.bounces, "--bounces", 0)));
  if (!sweepSpp && hasSpp) overrides.push_back("renderer.spp=" + std::to_string(parseSingle(a.spp, "--spp", 1)));
  if (a.seed >= 0) overrides.push_back("renderer.seed=" + std::to_string(a.seed));
  if (!a.resolution.empty()) overrides.push_back(resolutionOverride(a.resolution));
  Scene scene = loadScene(a.scene, overrides);
  for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
  if (scene.renderer.algorithm != Algorithm::Pathtrace && a.algorithm.empty())
    std::cerr << "narval: warning: " << a.scene << ": renderer.algorithm is \"" << algorithmName(scene.renderer.algorithm)
              << "\"; the sweep renders with pathtrace\n";
  scene.renderer.algorithm = Algorithm::Pathtrace;
  return scene;
}

// A finished row: its EXR (unless collected from a farm), its warnings and its line of the table.
void reportSweepRow(const SweepArgs& a, const Scene& scene, const fs::path& dir, SweepParameter parameter,
                    const SweepRow& row) {
  const RenderStats& st = row.stats;
  const fs::path exr = dir / sweepFileName(parameter, row.value);
  // The row's spp and bounces from its stats; collected renders are there already.
  if (!a.collect) writeExr(exr.string(), row.image, renderAttributes(st, renderIdentity(scene)));
  for (const std::string& w : statusWarnings(st.status))
    std::cerr << "narval: warning: " << exr.string() << ": " << w << "\n";
  std::printf("%-14s %10.3f s", sweepLabel(parameter, row.value).c_str(), row.seconds);
  if (row.isReference)
    std::printf("  reference\n");
  else
    std::printf("  speed-up %7.2f  mean dE76 %6.3f  JND %6.2f%%  mean dE2000 %6.3f  JND2000 %6.2f%%\n", row.speedup,
                row.dE76.mean, row.dE76.jndPercent, row.dE2000.mean, row.dE2000.jndPercent);
  std::fflush(stdout);
}

int runSweepCommand(const SweepArgs& a) {
  // ---- everything is checked before DIR is created or anything rendered
  if (!a.algorithm.empty() && a.algorithm != "pathtrace")
    throw inputError("--algorithm", "", "sweep renders with pathtrace only for now, got '" + a.algorithm + "'");
  const SweepParameter parameter = sweptParameter(a);
  const bool sweepSpp = parameter == SweepParameter::Spp;
  const std::string listOption = sweepSpp ? "--spp" : "--bounces";
  const std::vector<int> values = parseSweepList(sweepSpp ? a.spp : a.bounces, listOption);
  if (values.size() < 2 && a.reference.empty())
    throw inputError(listOption, "", "a sweep needs at least two values (or --reference FILE.exr)");

  Scene scene = sweepScene(a, sweepSpp);

  const fs::path dir(a.out);
  if (fs::exists(dir) && !fs::is_directory(dir))
    throw inputError("-o", "", "'" + a.out + "' exists and is not a folder");

  SceneGridStorage gridStorage;
  const SceneGrids g = loadSceneGrids(scene, gridStorage);
  ImageRGB reference;
  if (!a.reference.empty()) {
    reference = readExr(a.reference);
    checkSweepReference(scene, reference, a.reference);
  }
  if (!a.scheduler.empty() && a.collect)
    throw inputError("--collect", "", "collects what a farm rendered; it does not go with --scheduler");
  // Last of the checks (it makes the folder, so nothing else may refuse after it): the folder takes files.
  checkOutputWritable((dir / "sweep.json").string(), "-o");

  if (!a.scheduler.empty()) {  // the renders as farm tasks, then this sweep with --collect
    Scheduler scheduler = Scheduler::Local;
    schedulerFromName(a.scheduler, &scheduler);  // CLI11 checked the name
    const std::string narval = a.narval.empty() ? thisNarvalBinary() : fs::absolute(a.narval).string();
    const fs::path jobDir = fs::absolute(a.jobDir.empty() ? dir / "farm" : fs::path(a.jobDir)).lexically_normal();
    const FarmJob job = sweepFarmJob(a, scene, parameter, values, narval, fs::absolute(dir).lexically_normal(), jobDir);
    std::cout << "sweep: " << job.name << ", " << values.size() << " renders for " << schedulerName(scheduler) << ": ";
    return runOrWriteFarmJob(job, scheduler, a.submit, a.parallel, "sweep");
  }
  std::optional<ClRuntime> rt;
  if (!a.collect) rt.emplace(a.device);

  // ---- render
  fs::create_directories(dir);
  const std::string sceneName = fs::path(a.scene).filename().string();
  bool warned = false;
  SweepRenderer render = [&](const Scene& s) {
    const int value = sweepSpp ? s.renderer.spp : s.renderer.bounces;
    if (a.collect) return collectedRender(s, dir / sweepFileName(parameter, value));
    ProgressBar bar("sweep " + sceneName + ": " + sweepLabel(parameter, value));
    RenderOptions options;
    options.progress = [&bar](int done, int total) { bar.update(done, total); };
    RenderResult r = renderPathtrace(*rt, s, g, options);
    bar.finish();
    if (!warned)
      for (const std::string& w : r.warnings) std::cerr << "narval: warning: " << w << "\n";
    warned = true;
    return r;
  };
  auto onRow = [&](const SweepRow& row) { reportSweepRow(a, scene, dir, parameter, row); };
  SweepSpec spec;
  spec.warmUp = !a.collect;
  spec.parameter = parameter;
  spec.values = values;
  if (!a.reference.empty()) {
    spec.reference = &reference;
    spec.referenceName = a.reference;
  }
  const SweepResult result = runSweep(scene, spec, render, onRow);

  // ---- tables and figure
  writeTextAtomic((dir / "sweep.csv").string(), sweepCsv(result));
  writeTextAtomic((dir / "sweep.json").string(), sweepJson(result).dump(2) + "\n");
  writePng8((dir / "sweep.png").string(), sweepFigure(result));
  std::cout << "wrote " << result.rows.size() << " renders, sweep.csv, sweep.json and sweep.png to " << dir.string()
            << " (" << result.width << "x" << result.height << ", "
            << (sweepSpp ? sweepLabel(SweepParameter::Bounces, result.fixedValue)
                         : sweepLabel(SweepParameter::Spp, result.fixedValue))
            << ", on " << result.device << ")\n";
  return 0;
}

}  // namespace

Command addSweepCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "sweep", "Render a scene over several spp or bounces values; time and compare each with the reference");
  auto a = std::make_shared<SweepArgs>();
  sub->add_option("SCENE.json", a->scene, "Scene file")->required();
  sub->add_option("-o,--output", a->out, "Output folder (created)")->required();
  sub->add_option("--spp", a->spp, "Samples per pixel: a comma-separated list to sweep, or one fixed value");
  sub->add_option("--bounces", a->bounces, "Bounces: a comma-separated list to sweep, or one fixed value");
  sub->add_option("--reference", a->reference,
                  "Compare with this EXR (the sweep's size) instead of rendering the largest value as reference");
  sub->add_option("--algorithm", a->algorithm, "pathtrace (the only one for now)");
  sub->add_option("--resolution", a->resolution, "WIDTHxHEIGHT");
  sub->add_option("--device", a->device, "Device index or name substring (narval devices)");
  sub->add_option("--seed", a->seed, "Random seed")->check(between(0, 4294967295LL));
  addThreadsOption(sub);
  sub->add_option("--set", a->sets, "Override a scene value: dotted.path=value (repeatable)");
  sub->add_option("--scheduler", a->scheduler,
                  "Render the values as farm tasks (narval farm's schedulers: slurm, openjd, local) into DIR, then "
                  "collect them with --collect; the job goes into DIR/farm (--job-dir)")
      ->check(CLI::IsMember({"slurm", "openjd", "local"}));
  sub->add_flag("--submit", a->submit, "With --scheduler: run the job and wait, as narval farm --submit");
  sub->add_option("--parallel", a->parallel, "With --scheduler local: tasks at once (default 1)")->check(atLeast(1));
  sub->add_option("--job-dir", a->jobDir, "With --scheduler: the job's folder (default DIR/farm)");
  sub->add_option("--narval", a->narval, "With --scheduler: the narval binary the tasks run (default: this one)");
  sub->add_flag("--collect", a->collect,
                "Compare and tabulate the renders already in DIR (what the farm's tasks wrote; their times are "
                "their EXRs' narval:seconds) instead of rendering");
  return {sub, [a]() { return runSweepCommand(*a); }};
}

}  // namespace narval
