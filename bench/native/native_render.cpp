// narval-native: the native baseline (issue 6, item 4). Loads a scene with the CLI's own host code
// (loadScene with the same --set overrides, loadSceneGrids, buildDeviceScene), renders it with the
// shared kernel headers compiled as C++ on N host threads (native_render.h), writes a 32-bit float
// EXR and prints the timing as one JSON object; bench/native_baseline.py runs it beside PoCL.
// --frames K: per-frame ms like narval render's (the first apart; "seconds" is the others' median).
// --compare REF.exr: how many pixels equal REF's bit for bit, and the largest differences.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "core/input_error.h"
#include "image/image.h"
#include "native/native_render.h"
#include "render/lobe_directions.h"
#include "render/realtime_renderer.h"

#ifndef NARVAL_NATIVE_FLAGS
#define NARVAL_NATIVE_FLAGS "unknown"
#endif

namespace fs = std::filesystem;
using namespace narval;

namespace {

struct Args {
  std::string scene, out, algorithm, resolution, statsJson, compare, majorant = "grid";
  int spp = -1, bounces = -1, threads = 0, frames = 1, majorantResolution = 0;
  long long seed = -1;
  std::vector<std::string> sets;
};

std::vector<std::string> overridesFrom(const Args& a) {  // as narval render does (render_command.cpp)
  std::vector<std::string> o = a.sets;
  if (a.spp >= 0) o.push_back("renderer.spp=" + std::to_string(a.spp));
  if (a.bounces >= 0) o.push_back("renderer.bounces=" + std::to_string(a.bounces));
  if (a.seed >= 0) o.push_back("renderer.seed=" + std::to_string(a.seed));
  if (!a.algorithm.empty()) o.push_back("renderer.algorithm=\"" + a.algorithm + "\"");
  if (!a.resolution.empty()) {
    const auto [w, h] = parseSize(a.resolution, "--resolution");
    o.push_back("renderer.resolution=[" + std::to_string(w) + "," + std::to_string(h) + "]");
  }
  return o;
}

uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

nlohmann::ordered_json compareWith(const std::string& refPath, const ImageRGB& img) {
  const ImageRGB ref = readExr(refPath);
  if (ref.width != img.width || ref.height != img.height)
    throw inputError(refPath, "", "size " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                                      " differs from the native render's");
  const size_t pixels = size_t(img.width) * size_t(img.height);
  size_t identical = 0, valuesEqual = 0;
  double maxAbs = 0, maxRel = 0, sumRel = 0;
  for (size_t i = 0; i < pixels; ++i) {
    bool same = true;
    for (int c = 0; c < 3; ++c) {
      const float a = ref.rgb[i * 3 + size_t(c)], b = img.rgb[i * 3 + size_t(c)];
      if (bitsOf(a) == bitsOf(b)) {
        ++valuesEqual;
        continue;
      }
      same = false;
      const double d = std::fabs(double(a) - double(b));
      const double rel = d / std::max(1e-12, std::max(std::fabs(double(a)), std::fabs(double(b))));
      maxAbs = std::max(maxAbs, d);
      maxRel = std::max(maxRel, rel);
      sumRel += rel;
    }
    identical += same ? 1 : 0;
  }
  return {{"reference", refPath},
          {"pixels_bitwise_identical_pct", 100.0 * double(identical) / double(pixels)},
          {"values_bitwise_identical_pct", 100.0 * double(valuesEqual) / double(3 * pixels)},
          {"max_abs_diff", maxAbs},
          {"max_rel_diff", maxRel},
          {"mean_rel_diff_of_differing", (3 * pixels - valuesEqual) ? sumRel / double(3 * pixels - valuesEqual) : 0.0}};
}

int run(const Args& a) {
  Scene scene = loadScene(a.scene, overridesFrom(a));
  for (const std::string& w : scene.warnings) std::cerr << "narval-native: warning: " << w << "\n";
  const std::string alg = algorithmName(scene.renderer.algorithm);
  SceneGridStorage gridStorage;
  const SceneGrids grid = loadSceneGrids(scene, gridStorage);
  DeviceScene ds = buildDeviceScene(scene, grid);
  for (const std::string& w : ds.warnings) std::cerr << "narval-native: warning: " << w << "\n";
  // The baseline compiles the shared headers without -DEMISSION: an emitting medium would render dark.
  if (ds.params.medium.emission.kind != EMISSION_NONE)
    throw InputError(a.scene + ": the native baseline renders no emission (the medium emits)");
  if (a.majorantResolution > 0) setMajorantResolution(ds, a.majorantResolution);

  native::NativeOptions o;
  o.algorithm = scene.renderer.algorithm;
  o.threads = a.threads;
  o.majorant = a.majorant == "auto" ? "grid" : a.majorant;
  o.spp = scene.renderer.spp;
  native::prepareRealtimeInputs(scene, ds, o);

  std::vector<double> frameSeconds;
  native::NativeResult r;
  for (int f = 0; f < std::max(1, a.frames); ++f) {
    r = native::renderNative(ds, o);
    frameSeconds.push_back(r.seconds);
  }
  // Per-frame statistics as narval render --frames reports them: the first frame apart (cold
  // caches and page faults here; program build and first launch there), the others' median.
  std::vector<double> sorted(frameSeconds.size() > 1 ? frameSeconds.begin() + 1 : frameSeconds.begin(),
                             frameSeconds.end());
  std::sort(sorted.begin(), sorted.end());
  const size_t n = sorted.size();
  const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  const double seconds = a.frames > 1 ? median : frameSeconds.front();

  const fs::path out = a.out.empty() ? fs::path(fs::path(a.scene).stem().string() + "_native.exr") : fs::path(a.out);
  if (out.has_parent_path()) fs::create_directories(out.parent_path());
  const int W = r.image.width, H = r.image.height;
  const int spp = alg == "pathtrace" ? std::max(1, scene.renderer.spp) : 1;
  const std::string device = "native C++ (" + std::to_string(r.threads) + " threads, " NARVAL_NATIVE_FLAGS ")";
  writeExr(out.string(), r.image,
           {{"narval:algorithm", alg},
            {"narval:spp", spp},
            {"narval:seed", double(scene.renderer.seed)},
            {"narval:device", device}});

  const majorant_grid_params& mg = ds.params.medium.majorant_grid;
  const std::vector<int> cells = ds.grid ? std::vector<int>{mg.cells_x, mg.cells_y, mg.cells_z} : std::vector<int>{0, 0, 0};
  nlohmann::ordered_json j = {{"algorithm", alg},
                              {"device", device},
                              {"threads", r.threads},
                              {"compile_flags", NARVAL_NATIVE_FLAGS},
                              {"width", W},
                              {"height", H},
                              {"spp", spp},
                              {"bounces", ds.params.max_bounces},
                              {"seed", scene.renderer.seed},
                              {"majorant", alg == "pathtrace" ? o.majorant : std::string("grid")},
                              {"majorant_cells", cells},  // as narval render reports them: 0 0 0 without a grid
                              {"seconds", seconds},
                              {"samples_per_second", double(W) * H * spp / seconds},
                              {"nan_pixels", r.nanPixels},
                              {"status",
                               {{"nan", (r.status & STATUS_NAN) != 0},
                                {"negative_pdf", (r.status & STATUS_NEGATIVE_PDF) != 0},
                                {"iteration_cap", (r.status & STATUS_ITERATION_CAP) != 0}}},
                              {"output", out.string()},
                              {"scene", scene.sourcePath}};
  if (a.frames > 1)
    j["ms_per_frame"] = {{"frames", a.frames},
                         {"first_frame_ms", frameSeconds.front() * 1e3},
                         {"median", median * 1e3},
                         {"min", sorted.front() * 1e3},
                         {"max", sorted.back() * 1e3}};
  if (!a.compare.empty()) j["compare"] = compareWith(a.compare, r.image);
  const std::string text = j.dump(2) + "\n";
  std::cout << text;
  if (!a.statsJson.empty()) writeTextAtomic(a.statsJson, text);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("narval-native: the shared kernel headers compiled as C++ on host threads (native baseline)");
  Args a;
  app.add_option("SCENE.json", a.scene, "Scene file")->required();
  app.add_option("-o,--output", a.out, "Output .exr (default: <scene name>_native.exr)");
  app.add_option("--algorithm", a.algorithm, "pathtrace | raymarch | lobe");
  app.add_option("--spp", a.spp, "Samples per pixel")->check(CLI::PositiveNumber);
  app.add_option("--bounces", a.bounces, "Real scattering events per path")->check(CLI::NonNegativeNumber);
  app.add_option("--resolution", a.resolution, "WIDTHxHEIGHT");
  app.add_option("--seed", a.seed, "Random seed")->check(CLI::Range(0LL, 4294967295LL));
  app.add_option("--set", a.sets, "Override a scene value: dotted.path=value (repeatable)");
  app.add_option("--threads", a.threads, "Host threads (default: hardware concurrency)")->check(CLI::NonNegativeNumber);
  app.add_option("--frames", a.frames, "Render K times; report ms per frame (median, min, max)")
      ->check(CLI::PositiveNumber);
  app.add_option("--majorant", a.majorant, "pathtrace: grid (default) | global | auto (grid: what narval picks for CPUs)")
      ->check(CLI::IsMember({"grid", "global", "auto"}));
  app.add_option("--majorant-resolution", a.majorantResolution,
                 "Majorant cells along the longest axis (0: buildDeviceScene's automatic choice; narval render "
                 "may choose otherwise per device: give what its --stats-json majorant_cells says, as "
                 "bench/native_baseline.py does)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--stats-json", a.statsJson, "Also write the JSON to FILE");
  app.add_option("--compare", a.compare, "Compare bit for bit with REF.exr (e.g. the PoCL render)");
  CLI11_PARSE(app, argc, argv);
  try {
    return run(a);
  } catch (const InputError& e) {
    std::cerr << "narval-native: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "narval-native: " << e.what() << "\n";
    return 1;
  }
}
