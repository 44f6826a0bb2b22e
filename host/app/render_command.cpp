#include <filesystem>
#include <cstdio>
#include <iostream>
#include <regex>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/progress_bar.h"
#include "image/atomic_file.h"
#include "image/image.h"
#include "render/pathtrace_renderer.h"
#include "scene/input_error.h"
#include "shared/structs.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct RenderArgs {
  std::string scene, out, algorithm, resolution, device, statsJson, localSize = "8x8";
  int spp = -1, bounces = -1;
  long long seed = -1;
  std::vector<std::string> sets;
};

// "WxH" -> {W, H}; `what` names the option in the error.
std::pair<int, int> parseSize(const std::string& text, const std::string& what) {
  std::smatch m;
  static const std::regex re(R"(^(\d{1,6})x(\d{1,6})$)");
  if (!std::regex_match(text, m, re) || std::stoi(m[1]) == 0 || std::stoi(m[2]) == 0)
    throw inputError(what, "", "expected WIDTHxHEIGHT with positive integers, got '" + text + "'");
  return {std::stoi(m[1]), std::stoi(m[2])};
}

// Command-line options become --set overrides, so the scene validator checks them all alike.
std::vector<std::string> overridesFrom(const RenderArgs& a) {
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

const Material* volumeMaterial(const Scene& scene) {
  for (const Primitive& p : scene.primitives)
    if (p.type == PrimitiveType::Volume) return &scene.materials.at(size_t(p.materialIndex));
  return nullptr;
}

void writeTextAtomic(const std::string& path, const std::string& text) {
  AtomicFile f(path);
  if (std::fwrite(text.data(), 1, text.size(), f.file()) != text.size()) f.fail("short write");
  f.commit();
}

nlohmann::json statsJson(const RenderStats& s, const Scene& scene) {
  return {{"algorithm", s.algorithm},
          {"device", s.device},
          {"width", s.width},
          {"height", s.height},
          {"spp", s.spp},
          {"bounces", s.bounces},
          {"seed", scene.renderer.seed},
          {"seconds", s.seconds},
          {"kernel_seconds", s.kernelSeconds},
          {"build_seconds", s.buildSeconds},
          {"samples_per_second", s.samplesPerSecond},
          {"passes", s.passes},
          {"nan_pixels", s.nanPixels},
          {"program_from_cache", s.programFromCache},
          {"status",
           {{"nan", (s.status & STATUS_NAN) != 0},
            {"negative_pdf", (s.status & STATUS_NEGATIVE_PDF) != 0},
            {"iteration_cap", (s.status & STATUS_ITERATION_CAP) != 0}}},
          {"scene", scene.sourcePath}};
}

int runRender(const RenderArgs& a) {
  const Scene scene = loadScene(a.scene, overridesFrom(a));
  for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
  if (scene.renderer.algorithm != "pathtrace")
    throw inputError(scene.sourcePath, "renderer.algorithm",
                     "'" + scene.renderer.algorithm + "' is not available yet (available: pathtrace)");
  const auto [lx, ly] = parseSize(a.localSize, "--local-size");

  fs::path out = a.out.empty() ? fs::path(fs::path(a.scene).stem().string() + ".exr") : fs::path(a.out);
  if (out.extension() != ".exr") throw inputError("-o", "", "the output must be an .exr file, got '" + a.out + "'");
  const fs::path png = fs::path(out).replace_extension(".png");
  if (out.has_parent_path()) fs::create_directories(out.parent_path());

  // Everything the render needs is loaded and checked before the first sample.
  DenseGrid grid;
  const Material* vm = volumeMaterial(scene);
  const bool hasGrid = vm && !vm->path.empty();
  if (hasGrid) grid = loadGrid(vm->path, vm->gridName);
  ClRuntime rt(a.device);

  ProgressBar bar("rendering " + fs::path(a.scene).filename().string());
  RenderOptions options;
  options.localSizeX = lx;
  options.localSizeY = ly;
  options.progress = [&bar](int done, int total) { bar.update(done, total); };
  const RenderResult r = renderPathtrace(rt, scene, hasGrid ? &grid : nullptr, options);
  bar.finish();
  for (const std::string& w : r.warnings) std::cerr << "narval: warning: " << w << "\n";

  const RenderStats& s = r.stats;
  writeExr(out.string(), r.image,
           {{"narval:algorithm", s.algorithm}, {"narval:spp", std::to_string(s.spp)},
            {"narval:bounces", std::to_string(s.bounces)}, {"narval:seed", std::to_string(scene.renderer.seed)},
            {"narval:scene", scene.sourcePath}, {"narval:device", s.device}});
  writePng(png.string(), r.image, scene.renderer.exposure, scene.renderer.toneMapping);
  if (!a.statsJson.empty()) writeTextAtomic(a.statsJson, statsJson(s, scene).dump(2) + "\n");

  if (s.status & STATUS_NAN) std::cerr << "narval: warning: the kernel produced non-finite samples (dropped)\n";
  if (s.status & STATUS_NEGATIVE_PDF) std::cerr << "narval: warning: the kernel met a non-positive pdf\n";
  if (s.status & STATUS_ITERATION_CAP) std::cerr << "narval: warning: a tracking loop hit its iteration cap\n";
  std::cout << "wrote " << out.string() << " and " << png.string() << " (" << s.width << "x" << s.height << ", "
            << s.spp << " spp, " << s.bounces << " bounces, " << s.seconds << " s, " << s.samplesPerSecond / 1e6
            << " Msamples/s on " << s.device << ")\n";
  return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("render", "Render a scene to OUT.exr (linear) and OUT.png (display)");
  auto a = std::make_shared<RenderArgs>();
  sub->add_option("SCENE.json", a->scene, "Scene file")->required();
  sub->add_option("-o,--output", a->out, "Output .exr (the .png goes beside it); default: <scene name>.exr");
  sub->add_option("--algorithm", a->algorithm, "pathtrace | raymarch | lobe");
  sub->add_option("--spp", a->spp, "Samples per pixel")->check(CLI::PositiveNumber);
  sub->add_option("--bounces", a->bounces, "Real scattering events per path")->check(CLI::NonNegativeNumber);
  sub->add_option("--resolution", a->resolution, "WIDTHxHEIGHT");
  sub->add_option("--device", a->device, "Device index or name substring (narval devices)");
  sub->add_option("--seed", a->seed, "Random seed")->check(CLI::Range(0LL, 4294967295LL));
  sub->add_option("--set", a->sets, "Override a scene value: dotted.path=value (repeatable)");
  sub->add_option("--stats-json", a->statsJson, "Write render statistics as JSON");
  sub->add_option("--local-size", a->localSize, "Work-group shape WxH (default 8x8); never changes the pixels");
  return {sub, [a]() { return runRender(*a); }};
}

}  // namespace narval
