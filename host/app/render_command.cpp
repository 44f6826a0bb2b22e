#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/interrupt.h"
#include "app/progress_bar.h"
#include "display/display_server.h"
#include "image/image.h"
#include "image/staged_files.h"
#include "render/pathtrace_renderer.h"
#include "render/realtime_renderer.h"
#include "render/render_common.h"
#include "render/render_exr.h"
#include "scene/input_error.h"
#include "shared/structs.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct RenderArgs {
  std::string scene, out, algorithm, resolution, device, statsJson, localSize = "8x8", samples;
  int spp = -1, bounces = -1, frames = 0, samplesPerPass = 0, majorantResolution = 0;
  bool resume = false, counters = false, quiet = false;
  std::optional<double> exposure;
  std::string tonemap;
  std::string majorant = "auto", storage, displayServer;
  double partialEverySeconds = 0;
  long long seed = -1;
  std::vector<std::string> sets;
};

// Command-line options become --set overrides, so the scene validator checks them all alike.
std::vector<std::string> overridesFrom(const RenderArgs& a) {
  std::vector<std::string> o = a.sets;
  if (a.spp >= 0) o.push_back("renderer.spp=" + std::to_string(a.spp));
  if (!a.samples.empty()) {  // --samples A:B renders B - A samples, from index A on
    const auto [begin, end] = parseSampleRange(a.samples, "--samples");
    o.push_back("renderer.spp=" + std::to_string(end - begin));
  }
  if (a.bounces >= 0) o.push_back("renderer.bounces=" + std::to_string(a.bounces));
  if (a.seed >= 0) o.push_back("renderer.seed=" + std::to_string(a.seed));
  if (!a.algorithm.empty()) o.push_back("renderer.algorithm=\"" + a.algorithm + "\"");
  if (!a.storage.empty()) o.push_back("renderer.storage=\"" + a.storage + "\"");
  if (!a.resolution.empty()) o.push_back(resolutionOverride(a.resolution));
  if (a.exposure) o.push_back("renderer.exposure=" + nlohmann::json(*a.exposure).dump());
  if (!a.tonemap.empty()) o.push_back("renderer.toneMapping=\"" + a.tonemap + "\"");
  return o;
}

nlohmann::json statsJson(const RenderStats& s, const Scene& scene) {
  return {{"algorithm", s.algorithm},
          {"device", s.device},
          {"storage", s.storage},
          {"grid_bytes", s.gridBytes},
          {"bricks", {{"total", s.bricks}, {"occupied", s.bricksOccupied}}},
          {"width", s.width},
          {"height", s.height},
          {"spp", s.spp},
          {"sample_begin", s.sampleBegin},
          {"spp_requested", s.sppRequested},
          {"resumed_from_spp", s.resumedFromSpp},
          {"interrupted", s.interrupted},
          {"bounces", s.bounces},
          {"seed", scene.renderer.seed},
          {"seconds", s.seconds},
          {"kernel_seconds", s.kernelSeconds},
          {"build_seconds", s.buildSeconds},
          {"samples_per_second", s.samplesPerSecond},
          {"passes", s.passes},
          {"nan_pixels", s.nanPixels},
          {"program_from_cache", s.programFromCache},
          {"majorant", s.majorant},
          {"majorant_cells", {s.majorantCells[0], s.majorantCells[1], s.majorantCells[2]}},
          {"light_cache_cells", {s.lightCacheCells[0], s.lightCacheCells[1], s.lightCacheCells[2]}},
          {"light_cache_bytes", s.lightCacheBytes},
          {"light_cache_builds", s.lightCacheBuilds},
          {"light_cache_ms", s.lightCacheMs},
          {"ms_cache_cells", {s.msCacheCells[0], s.msCacheCells[1], s.msCacheCells[2]}},
          {"ms_cache_layout", s.msCacheView ? "view" : "grid"},
          {"ms_cache_paths", s.msCachePaths},
          {"ms_cache_builds", s.msCacheBuilds},
          {"ms_cache_ms", s.msCacheMs},
          {"ms_cache_filter", s.msCacheFilter},
          {"ms_cache_filter_tolerance", s.msCacheFilterTolerance},
          {"ms_cache_filter_twicing", s.msCacheFilterTwicing},
          {"ms_cache_guide", s.msCacheGuide},
          {"ms_cache_budget", {s.msCacheBudgetMin, s.msCacheBudgetMax}},
          {"status",
           {{"nan", (s.status & STATUS_NAN) != 0},
            {"negative_pdf", (s.status & STATUS_NEGATIVE_PDF) != 0},
            {"iteration_cap", (s.status & STATUS_ITERATION_CAP) != 0},
            {"unknown_kind", (s.status & STATUS_UNKNOWN_KIND) != 0}}},
          {"scene", scene.sourcePath}};
}

// --frames: per-frame milliseconds, the first frame (build, warm-up) apart.
nlohmann::json framesJson(const FrameTimings& f) {
  return {{"frames", f.count},
          {"first_frame_ms", {{"kernel", f.firstKernelMs}, {"wall", f.firstWallMs}}},
          {"median", f.medianKernelMs},
          {"min", f.minKernelMs},
          {"max", f.maxKernelMs},
          {"wall", {{"median", f.medianWallMs}, {"min", f.minWallMs}, {"max", f.maxWallMs}}}};
}

// --resume continues with the majorant the file at `out` was rendered with (its samples depend on
// the majorant and, for the grid, on its cells): "auto" and resolution 0 take the file's; an explicit
// choice that differs is a usage error. Files without the attributes (older renders) are left alone.
void resumeMajorant(const std::string& out, const RenderArgs& a, std::string* majorant, int* resolution) {
  const auto attrs = readExrAttributes(out);
  const auto m = attrs.find("narval:majorant");
  if (m == attrs.end() || m->second.empty()) return;
  if (a.majorant != "auto" && a.majorant != m->second)
    throw inputError("--majorant", "", out + " was rendered with --majorant " + m->second +
                                           "; resume with it (or leave --majorant out)");
  *majorant = m->second;
  const auto r = attrs.find("narval:majorant_resolution");
  if (m->second != "grid" || r == attrs.end()) return;
  const int fileResolution = std::atoi(r->second.c_str());
  if (a.majorantResolution != 0 && a.majorantResolution != fileResolution)
    throw inputError("--majorant-resolution", "", out + " was rendered with --majorant-resolution " + r->second +
                                                      "; resume with it (or leave it out)");
  *resolution = fileResolution;
}

int runRender(const RenderArgs& a) {
  std::ostream silent(nullptr);  // --quiet: report lines go nowhere (a stream without a buffer drops them)
  std::ostream& report = a.quiet ? silent : std::cout;
  Scene scene = loadScene(a.scene, overridesFrom(a));
  for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
  const bool realtime = isRealtime(scene.renderer.algorithm);
  const std::string algorithm = algorithmName(scene.renderer.algorithm);
  const auto [lx, ly] = parseSize(a.localSize, "--local-size");
  // The real-time algorithms take one estimate per pixel per frame; only the ray marcher's
  // multiple-scattering cache traces paths, and it takes the scene's bounces.
  if (realtime && a.spp >= 0)
    throw inputError("--spp", "", "does not apply to " + algorithm + ", which renders frames (use --frames)");
  if (realtime && !a.samples.empty())
    throw inputError("--samples", "", "does not apply to " + algorithm + ", which renders frames (use --frames)");
  const int sampleBegin = a.samples.empty() ? 0 : parseSampleRange(a.samples, "--samples").first;
  const bool cachePaths = scene.renderer.algorithm == Algorithm::Raymarch &&
                          scene.renderer.raymarch.multipleScattering == MultipleScattering::Cache;
  if (realtime && a.bounces >= 0 && !cachePaths)
    throw inputError("--bounces", "", "does not apply to " + algorithm +
                                          " (only the ray marcher's multiple-scattering cache traces bounces)");
  if (a.counters && realtime)
    throw inputError("--counters", "", "only the path tracer counts collisions; the algorithm is " + algorithm);

  fs::path out = a.out.empty() ? fs::path(fs::path(a.scene).stem().string() + ".exr") : fs::path(a.out);
  if (out.extension() != ".exr") throw inputError("-o", "", "the output must be an .exr file, got '" + a.out + "'");
  const fs::path png = fs::path(out).replace_extension(".png");
  // Every output is proven writable before any work (folders made as the writers would make them).
  checkOutputWritable(out.string(), "-o");
  checkOutputWritable(png.string(), "-o");
  checkOutputWritable(a.statsJson, "--stats-json");

  // --resume: the accumulator of an earlier render of the same settings at the output path.
  std::string majorant = a.majorant;
  int majorantResolution = a.majorantResolution;
  AccumulatorState resumeState;
  bool resuming = false;
  if (a.resume) {
    if (realtime) throw inputError("--resume", "", "only path-traced renders resume; the algorithm is " + algorithm);
    if (fs::exists(out)) {
      resumeState = readAccumulator(out.string(), scene, sampleBegin);
      resuming = true;
      resumeMajorant(out.string(), a, &majorant, &majorantResolution);
      if (resumeState.samples == scene.renderer.spp) {
        report << out.string() << " already has " << resumeState.samples << " spp; nothing to render\n";
        return 0;
      }
    } else {
      std::cerr << "narval: --resume: " << out.string() << " does not exist yet; rendering from the first sample\n";
    }
  }

  std::optional<HostPort> displayAt;
  if (!a.displayServer.empty()) displayAt = parseHostPort(a.displayServer, "--display-server");
  if (a.partialEverySeconds > 0 && realtime)
    throw inputError("--write-partial-images", "", "only path-traced renders write partial images; the algorithm is " +
                                                       algorithm);

  // Everything the render needs is loaded and checked before the first sample.
  SceneGridStorage gridStorage;
  const SceneGrids g = loadSceneGrids(scene, gridStorage);
  const InterruptWatch interrupt;  // from here on, Ctrl-C stops after the pass in flight
  ClRuntime rt(a.device);
  checkLocalSize(lx, ly, rt.selected.device, rt.selected.info.name);

  ProgressBar bar((realtime ? "frames of " : "rendering ") + fs::path(a.scene).filename().string(), !a.quiet);
  RenderOptions options;
  options.localSizeX = lx;
  options.localSizeY = ly;
  options.samplesPerPass = a.samplesPerPass;
  options.sampleBegin = sampleBegin;
  options.progress = [&bar](int done, int total) { bar.update(done, total); };
  options.cancel = &interrupt.flag();
  if (resuming) options.resumeFrom = &resumeState;
  // --frames with the path tracer: K passes of one sample per pixel (a frame each), K spp in all.
  if (a.frames > 0 && !realtime) {
    scene.renderer.spp = a.frames;
    options.samplesPerPass = 1;
  }
  options.majorant = majorant;
  options.majorantResolution = majorantResolution;
  options.counters = a.counters;
  // Snapshots between passes: the display server's (its thread sends what changed, ~4 a second)
  // and --write-partial-images' (the EXR so far, resumable, atomically over the output).
  std::unique_ptr<DisplayServer> display;
  if (displayAt)
    display = std::make_unique<DisplayServer>(*displayAt, out.filename().string(), scene.renderer.width,
                                              scene.renderer.height);
  // One timer per consumer: due once `every` has passed since it last took a snapshot.
  struct Periodic {
    bool on;
    std::chrono::duration<double> every;
    std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
    bool due() const { return on && std::chrono::steady_clock::now() - last >= every; }
  };
  Periodic show{display && display->receiving(), DisplayServer::kUpdateInterval};
  Periodic save{a.partialEverySeconds > 0, std::chrono::duration<double>(a.partialEverySeconds)};
  options.snapshotDue = [&]() { return show.due() || save.due(); };
  options.snapshot = [&](const RenderResult& partial) {
    if (show.due()) {
      display->post(partial.image);
      show.last = std::chrono::steady_clock::now();
    }
    if (save.due()) {
      writeRenderExr(out.string(), partial, renderIdentity(scene));
      save.last = std::chrono::steady_clock::now();
    }
  };
  const RenderResult r = realtime ? renderRealtime(rt, scene, g, std::max(1, a.frames), options)
                                  : renderPathtrace(rt, scene, g, options);
  bar.finish();
  if (display) {
    if (r.image.width > 0) display->finish(r.image);
    for (const std::string& w : display->warnings()) std::cerr << "narval: warning: " << w << "\n";
  }
  for (const std::string& w : r.warnings) std::cerr << "narval: warning: " << w << "\n";
  const RenderStats& s = r.stats;
  if (r.image.width == 0) {
    std::cerr << "narval: interrupted before the first " << (realtime ? "frame" : "pass") << "; nothing written\n";
    return kExitInterrupted;
  }

  // The EXR, the PNG and the stats land together or not at all (staged_files.h).
  StagedFiles staged;
  writeRenderExr(staged.stage(out.string()), r, renderIdentity(scene));
  writePng(staged.stage(png.string()), r.image, scene.renderer.exposure, scene.renderer.toneMapping);
  if (!a.statsJson.empty()) {
    nlohmann::json j = statsJson(s, scene);
    if (a.frames > 0) j["ms_per_frame"] = framesJson(s.frames);
    if (s.counters) {
      j["collisions_tentative"] = s.collisionsTentative;
      j["collisions_real"] = s.collisionsReal;
      j["density_lookups"] = s.densityLookups;
    }
    writeTextAtomic(staged.stage(a.statsJson), j.dump(2) + "\n");
  }
  staged.commit();

  for (const std::string& w : statusWarnings(s.status)) std::cerr << "narval: warning: " << w << "\n";
  if (s.interrupted) {
    std::cerr << "narval: interrupted: wrote " << out.string() << " and " << png.string() << " with "
              << (realtime ? std::to_string(s.passes) + " of " + std::to_string(std::max(1, a.frames)) + " frames"
                           : std::to_string(s.spp) + " of " + std::to_string(s.sppRequested) +
                                 " spp; --resume continues it")
              << "\n";
    return kExitInterrupted;
  }
  if (a.frames > 0)
    report << s.algorithm << ": " << s.frames.count << " frames, first " << s.frames.firstKernelMs
              << " ms, then median " << s.frames.medianKernelMs << " ms (min " << s.frames.minKernelMs << ", max "
              << s.frames.maxKernelMs << ") per frame by profiling events, median " << s.frames.medianWallMs
              << " ms by wall clock\n";
  if (s.lightCacheBuilds > 0)
    report << "light cache: " << s.lightCacheCells[0] << "x" << s.lightCacheCells[1] << "x" << s.lightCacheCells[2]
              << " cells, " << s.lightCacheBuilds << (s.lightCacheBuilds == 1 ? " light" : " lights") << " built in "
              << s.lightCacheMs << " ms (not in the frame times)\n";
  if (s.msCacheBuilds > 0) {
    report << "multiple-scattering cache: " << s.msCacheCells[0] << "x" << s.msCacheCells[1] << "x"
           << s.msCacheCells[2] << (s.msCacheView ? " columns x rows x slices, " : " cells, ")
           << (s.msCacheBudgetMax > 0 ? "a mean of " : "") << s.msCachePaths
           << " paths per node";
    if (s.msCacheFilter > 0)
      report << ", filtered (sigma " << s.msCacheFilter << " columns, tolerance " << s.msCacheFilterTolerance
             << " standard errors" << (s.msCacheFilterTwicing ? ", twiced" : "") << ")";
    if (s.msCacheGuide > 0) report << ", guided towards the lights (share " << s.msCacheGuide << ")";
    if (s.msCacheBudgetMax > 0)
      report << ", allocated perceptually (" << s.msCacheBudgetMin << "-" << s.msCacheBudgetMax << " paths a column)";
    report << " in " << s.msCacheMs << " ms (not in the frame times)\n";
  }
  report << "wrote " << out.string() << " and " << png.string() << " (" << s.width << "x" << s.height << ", "
            << s.algorithm << ", ";
  if (realtime)
    report << s.frames.count << " frame(s), " << s.frames.medianKernelMs << " ms per frame";
  else
    report << (a.samples.empty() ? std::to_string(s.spp) + " spp"
                                 : "samples [" + std::to_string(s.sampleBegin) + ", " +
                                       std::to_string(s.sampleBegin + s.spp) + ")")
           << ", " << s.bounces << " bounces, " << s.seconds << " s, " << s.samplesPerSecond / 1e6
              << " Msamples/s";
  report << " on " << s.device << ")\n";
  return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("render", "Render a scene to OUT.exr (linear) and OUT.png (display)");
  auto a = std::make_shared<RenderArgs>();
  sub->add_option("SCENE.json", a->scene, "Scene file")->required();
  sub->add_option("-o,--output", a->out, "Output .exr (the .png goes beside it); default: <scene name>.exr");
  sub->add_option("--algorithm", a->algorithm, "pathtrace | raymarch | lobe");
  sub->add_option("--spp", a->spp, "pathtrace: samples per pixel")->check(atLeast(1));
  CLI::Option* spp = sub->get_option("--spp");
  sub->add_option("--samples", a->samples,
                  "pathtrace: render only the sample indices [A, B) of every pixel (A:B), a part for `narval "
                  "merge`; the EXR records the range")
      ->excludes(spp);
  sub->add_option("--bounces", a->bounces,
                  "pathtrace and the ray marcher's multiple-scattering cache: real scattering events per path")
      ->check(atLeast(0));
  sub->add_option("--resolution", a->resolution, "WIDTHxHEIGHT");
  sub->add_option("--device", a->device, "Device index or name substring (narval devices)");
  sub->add_option("--seed", a->seed, "Random seed")->check(between(0, 4294967295LL));
  sub->add_option("--set", a->sets, "Override a scene value: dotted.path=value (repeatable)");
  sub->add_option("--frames", a->frames,
                  "Render K frames and report ms per frame (pathtrace: K passes of 1 spp)")
      ->check(atLeast(1));
  sub->add_option("--stats-json", a->statsJson, "Write render statistics as JSON");
  sub->add_option("--storage", a->storage,
                  "Density grid on the device: image (3D image, hardware sampler), buffer (float buffer, the "
                  "shared trilinear filter), bricks (sparse 8^3 bricks: grids beyond one image or buffer) or auto "
                  "(buffer on CPUs, image on GPUs; bricks when those cannot hold the grid); renderer.storage")
      ->check(CLI::IsMember({"auto", "image", "buffer", "bricks"}));
  sub->add_option("--local-size", a->localSize, "Work-group shape WxH (default 8x8); never changes the pixels");
  sub->add_option("--samples-per-pass", a->samplesPerPass,
                  "pathtrace: samples per pixel per launch (default: about 2^20 paths per launch); never "
                  "changes the pixels")
      ->check(atLeast(1));
  sub->add_option("--majorant", a->majorant,
                  "pathtrace: majorant of delta and ratio tracking: grid (per cell of a coarse grid, walked by "
                  "DDA), global (one for the whole medium), or auto (default: grid on CPUs, global on GPUs)")
      ->check(CLI::IsMember({"auto", "grid", "global"}));
  sub->add_option("--majorant-resolution", a->majorantResolution,
                  "Majorant grid cells along the grid's longest axis (0: automatic)")
      ->check(atLeast(0));
  sub->add_flag("--counters", a->counters,
                "pathtrace: count tentative and real collisions and density lookups (a kernel built to count; "
                "--stats-json reports them)");
  sub->add_option("--display-server", a->displayServer,
                  "Stream the image being rendered to a running tev at HOST:PORT (tev listens on "
                  "localhost:14158): the tiles that changed, about 4 times a second");
  sub->add_option("--write-partial-images", a->partialEverySeconds,
                  "pathtrace: every SECONDS, write the EXR so far over the output (atomically; --resume "
                  "continues it)")
      ->check(greaterThanZero());
  sub->add_option("--exposure", a->exposure, "Exposure in stops of the PNG (overrides renderer.exposure)");
  sub->add_option("--tonemap", a->tonemap, "Tone mapping of the PNG: none | reinhard | aces (overrides renderer.toneMapping)")
      ->check(CLI::IsMember({"none", "reinhard", "aces"}));
  sub->add_flag("-q,--quiet", a->quiet, "Print only errors and warnings (no progress bar, no report lines)");
  addThreadsOption(sub);
  CLI::Option* frames = sub->get_option("--frames");
  sub->get_option("--samples")->excludes(frames);
  sub->add_flag("--resume", a->resume,
                "pathtrace: continue the render already at the output path (interrupted, or with fewer spp) "
                "to the requested spp; the pixels equal those of one uninterrupted render")
      ->excludes(frames);
  return {sub, [a]() { return runRender(*a); }};
}

}  // namespace narval
