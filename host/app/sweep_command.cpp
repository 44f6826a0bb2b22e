// narval sweep: speed against perceptual error over spp or bounces (dissertation ch. 5). Renders
// the scene at each value, largest first (the reference, unless --reference FILE.exr), and writes
// into DIR one EXR per value, sweep.csv, sweep.json and the figure strip sweep.png.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>

#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "app/commands.h"
#include "render/render_exr.h"
#include "app/progress_bar.h"
#include "image/image.h"
#include "image/image_compare.h"
#include "render/pathtrace_renderer.h"
#include "render/render_common.h"
#include "render/sweep.h"
#include "scene/input_error.h"
#include "shared/structs.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct SweepArgs {
  std::string scene, out, spp, bounces, reference, device, resolution, algorithm;
  long long seed = -1;
  std::vector<std::string> sets;
};

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

int runSweepCommand(const SweepArgs& a) {
  // ---- everything is checked before DIR is created or anything rendered
  if (!a.algorithm.empty() && a.algorithm != "pathtrace")
    throw inputError("--algorithm", "", "sweep renders with pathtrace only for now, got '" + a.algorithm + "'");
  const bool hasSpp = !a.spp.empty(), hasBounces = !a.bounces.empty();
  if (!hasSpp && !hasBounces)
    throw inputError("--spp, --bounces", "", "give the values to sweep, e.g. --spp 10,100,1000 or --bounces 50,10,5");
  SweepParameter parameter;
  if (hasSpp && hasBounces) {
    if (isList(a.spp) == isList(a.bounces))
      throw inputError("--spp, --bounces", "",
                       "sweep exactly one: give one of them as a comma-separated list and the other as a single "
                       "value (got '" + a.spp + "' and '" + a.bounces + "')");
    parameter = isList(a.spp) ? SweepParameter::Spp : SweepParameter::Bounces;
  } else {
    parameter = hasSpp ? SweepParameter::Spp : SweepParameter::Bounces;
  }
  const bool sweepSpp = parameter == SweepParameter::Spp;
  const std::string listOption = sweepSpp ? "--spp" : "--bounces";
  const std::vector<int> values = parseSweepList(sweepSpp ? a.spp : a.bounces, listOption);
  if (values.size() < 2 && a.reference.empty())
    throw inputError(listOption, "", "a sweep needs at least two values (or --reference FILE.exr)");

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
  // Last of the checks (it makes the folder, so nothing else may refuse after it): the folder takes files.
  checkOutputWritable((dir / "sweep.json").string(), "-o");
  ClRuntime rt(a.device);

  // ---- render
  fs::create_directories(dir);
  const std::string sceneName = fs::path(a.scene).filename().string();
  bool warned = false;
  SweepRenderer render = [&](const Scene& s) {
    const int value = sweepSpp ? s.renderer.spp : s.renderer.bounces;
    ProgressBar bar("sweep " + sceneName + ": " + sweepLabel(parameter, value));
    RenderOptions options;
    options.progress = [&bar](int done, int total) { bar.update(done, total); };
    RenderResult r = renderPathtrace(rt, s, g, options);
    bar.finish();
    if (!warned)
      for (const std::string& w : r.warnings) std::cerr << "narval: warning: " << w << "\n";
    warned = true;
    return r;
  };
  auto onRow = [&](const SweepRow& row) {
    const RenderStats& st = row.stats;
    const fs::path exr = dir / sweepFileName(parameter, row.value);
    writeExr(exr.string(), row.image, renderAttributes(st, renderIdentity(scene)));  // the row's spp and bounces from its stats
    for (const std::string& w : statusWarnings(st.status))
      std::cerr << "narval: warning: " << exr.string() << ": " << w << "\n";
    std::printf("%-14s %10.3f s", sweepLabel(parameter, row.value).c_str(), row.seconds);
    if (row.isReference)
      std::printf("  reference\n");
    else
      std::printf("  speed-up %7.2f  mean dE76 %6.3f  JND %6.2f%%  mean dE2000 %6.3f  JND2000 %6.2f%%\n", row.speedup,
                  row.dE76.mean, row.dE76.jndPercent, row.dE2000.mean, row.dE2000.jndPercent);
    std::fflush(stdout);
  };
  SweepSpec spec;
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
  return {sub, [a]() { return runSweepCommand(*a); }};
}

}  // namespace narval
