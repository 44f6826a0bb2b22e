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
#include "core/input_error.h"
#include "core/staged_files.h"
#include "display/display_server.h"
#include "image/image.h"
#include "render/pathtrace_renderer.h"
#include "render/realtime_renderer.h"
#include "render/render_common.h"
#include "render/ms_cache_file.h"
#include "render/render_exr.h"
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
  std::string majorant = "auto", storage, displayServer, msCacheIn, msCacheOut;
  double partialEverySeconds = 0, targetMs = 0;
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

// Flags that cannot apply to the scene's algorithm: one line each, before anything is loaded.
// The real-time algorithms take one estimate per pixel per frame; only the ray marcher's
// multiple-scattering cache traces paths, and it takes the scene's bounces.
void refuseFlagsThatDoNotApply(const RenderArgs& a, const Scene& scene) {
  if (a.targetMs > 0 && !isRealtime(scene.renderer.algorithm))
    throw inputError("--target-ms", "", "only the real-time algorithms render frames in a budget; the algorithm is " +
                                            std::string(algorithmName(scene.renderer.algorithm)));
  const bool msCache = scene.renderer.drawsMsCache();
  for (const auto& [flag, value] : {std::pair{"--ms-cache-in", &a.msCacheIn}, {"--ms-cache-out", &a.msCacheOut}})
    if (!value->empty() && !msCache) throw msCacheFlagWithoutCache(flag);
  if (!isRealtime(scene.renderer.algorithm)) return;
  const std::string algorithm = algorithmName(scene.renderer.algorithm);
  const std::string frames = "does not apply to " + algorithm + ", which renders frames (use --frames)";
  if (a.spp >= 0) throw inputError("--spp", "", frames);
  if (!a.samples.empty()) throw inputError("--samples", "", frames);
  if (a.bounces >= 0 && !msCache)
    throw inputError("--bounces", "", "does not apply to " + algorithm +
                                          " (only the ray marcher's multiple-scattering cache traces bounces)");
  if (a.counters)
    throw inputError("--counters", "", "only the path tracer counts collisions; the algorithm is " + algorithm);
  if (a.resume) throw inputError("--resume", "", "only path-traced renders resume; the algorithm is " + algorithm);
  if (a.partialEverySeconds > 0)
    throw inputError("--write-partial-images", "", "only path-traced renders write partial images; the algorithm is " +
                                                       algorithm);
}

// Where the render goes: OUT.exr, the PNG beside it, the statistics; each proven writable before
// any work (folders made as the writers would make them).
struct OutputPaths {
  fs::path exr, png;
  std::string statsJson, msCache;
};

OutputPaths outputPaths(const RenderArgs& a) {
  OutputPaths o;
  o.exr = a.out.empty() ? fs::path(fs::path(a.scene).stem().string() + ".exr") : fs::path(a.out);
  if (o.exr.extension() != ".exr") throw inputError("-o", "", "the output must be an .exr file, got '" + a.out + "'");
  o.png = fs::path(o.exr).replace_extension(".png");
  o.statsJson = a.statsJson;
  checkOutputWritable(o.exr.string(), "-o");
  checkOutputWritable(o.png.string(), "-o");
  checkOutputWritable(o.statsJson, "--stats-json");
  o.msCache = a.msCacheOut;
  checkOutputWritable(o.msCache, "--ms-cache-out");
  return o;
}

// --resume: the accumulator of an earlier render of the same settings at the output path, and the
// majorant it was rendered with.
struct ResumePoint {
  bool resuming = false;
  AccumulatorState state;
  std::string majorant;
  int majorantResolution = 0;
};

ResumePoint resumePoint(const RenderArgs& a, const Scene& scene, const fs::path& out, int sampleBegin) {
  ResumePoint r;
  r.majorant = a.majorant;
  r.majorantResolution = a.majorantResolution;
  if (!a.resume) return r;
  if (!fs::exists(out)) {
    std::cerr << "narval: --resume: " << out.string() << " does not exist yet; rendering from the first sample\n";
    return r;
  }
  r.state = readAccumulator(out.string(), scene, sampleBegin);
  r.resuming = true;
  resumeMajorant(out.string(), a, &r.majorant, &r.majorantResolution);
  return r;
}

// Snapshots between passes: the display server's (its thread sends what changed, ~4 a second) and
// --write-partial-images' (the EXR so far, resumable, atomically over the output), each due once
// its interval has passed since it last took one.
class Snapshots {
 public:
  // Checks --display-server's address; nothing connects yet.
  Snapshots(const RenderArgs& a, const Scene& scene, const fs::path& out)
      : scene_(scene), out_(out), partialEverySeconds_(a.partialEverySeconds) {
    if (!a.displayServer.empty()) displayAt_ = parseHostPort(a.displayServer, "--display-server");
  }
  // Connects to the display server and starts the timers: just before the render.
  void install(RenderOptions& options) {
    if (displayAt_)
      display_ = std::make_unique<DisplayServer>(*displayAt_, out_.filename().string(), scene_.renderer.width,
                                                 scene_.renderer.height);
    show_ = {display_ && display_->receiving(), DisplayServer::kUpdateInterval};
    save_ = {partialEverySeconds_ > 0, std::chrono::duration<double>(partialEverySeconds_)};
    options.snapshotDue = [this]() { return show_.due() || save_.due(); };
    options.snapshot = [this](const RenderResult& partial) {
      if (show_.due()) {
        display_->post(partial.image);
        show_.last = std::chrono::steady_clock::now();
      }
      if (save_.due()) {
        writeRenderExr(out_.string(), partial, renderIdentity(scene_));
        save_.last = std::chrono::steady_clock::now();
      }
    };
  }
  // The final image to the display, and what it has to say.
  void finish(const RenderResult& r) {
    if (!display_) return;
    if (r.image.width > 0) display_->finish(r.image);
    for (const std::string& w : display_->warnings()) std::cerr << "narval: warning: " << w << "\n";
  }

 private:
  struct Periodic {
    bool on = false;
    std::chrono::duration<double> every{};
    std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
    bool due() const { return on && std::chrono::steady_clock::now() - last >= every; }
  };
  const Scene& scene_;
  fs::path out_;
  double partialEverySeconds_;
  std::optional<HostPort> displayAt_;
  std::unique_ptr<DisplayServer> display_;
  Periodic show_, save_;
};

// The EXR, the PNG and the stats land together or not at all (staged_files.h).
void writeOutputs(const OutputPaths& o, const RenderResult& r, const Scene& scene, int frames,
                  const MsCacheSnapshot& msCache) {
  StagedFiles staged;
  if (!o.msCache.empty()) writeMsCacheFile(staged.stage(o.msCache), {msCacheSettings(scene), msCache});
  writeRenderExr(staged.stage(o.exr.string()), r, renderIdentity(scene));
  writePng(staged.stage(o.png.string()), r.image, scene.renderer.exposure, scene.renderer.toneMapping);
  if (!o.statsJson.empty()) {
    nlohmann::json j = statsJson(r.stats, scene.renderer.seed, scene.sourcePath);
    if (frames > 0) j["ms_per_frame"] = framesJson(r.stats.frames);
    writeTextAtomic(staged.stage(o.statsJson), j.dump(2) + "\n");
  }
  staged.commit();
}

// What was written, on `report`; an interrupted render says so on stderr and exits 130.
int reportOutcome(const RenderArgs& a, const OutputPaths& o, const RenderStats& s, bool realtime,
                  std::ostream& report) {
  for (const std::string& w : statusWarnings(s.status)) std::cerr << "narval: warning: " << w << "\n";
  if (s.interrupted) {
    std::cerr << "narval: interrupted: wrote " << o.exr.string() << " and " << o.png.string() << " with "
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
  report << describe(s.lightCache) << describe(s.msCache);
  report << "wrote " << o.exr.string() << " and " << o.png.string() << " (" << s.width << "x" << s.height << ", "
         << s.algorithm << ", ";
  if (realtime)
    report << s.frames.count << " frame(s), " << s.frames.medianKernelMs << " ms per frame";
  else
    report << (a.samples.empty() ? std::to_string(s.spp) + " spp"
                                 : "samples [" + std::to_string(s.sampleBegin) + ", " +
                                       std::to_string(s.sampleBegin + s.spp) + ")")
           << ", " << s.bounces << " bounces, " << s.seconds << " s, " << s.samplesPerSecond / 1e6 << " Msamples/s";
  report << " on " << s.device << ")\n";
  return 0;
}

int runRender(const RenderArgs& a) {
  std::ostream silent(nullptr);  // --quiet: report lines go nowhere (a stream without a buffer drops them)
  std::ostream& report = a.quiet ? silent : std::cout;
  Scene scene = loadScene(a.scene, overridesFrom(a));
  for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
  const bool realtime = isRealtime(scene.renderer.algorithm);
  const auto [lx, ly] = parseSize(a.localSize, "--local-size");
  refuseFlagsThatDoNotApply(a, scene);
  if (a.targetMs > 0 && !scene.renderer.drawsMsCache())
    std::cerr << "narval: warning: --target-ms: only the ray marcher's multiple-scattering cache is built within a "
                 "frame budget; this scene's "
              << algorithmName(scene.renderer.algorithm) << " has none, so every frame is drawn whole\n";
  const int sampleBegin = a.samples.empty() ? 0 : parseSampleRange(a.samples, "--samples").first;
  const OutputPaths out = outputPaths(a);
  const ResumePoint resume = resumePoint(a, scene, out.exr, sampleBegin);
  if (resume.resuming && resume.state.samples == scene.renderer.spp) {
    report << out.exr.string() << " already has " << resume.state.samples << " spp; nothing to render\n";
    return 0;
  }
  Snapshots snapshots(a, scene, out.exr);
  MsCacheSnapshot cacheIn, cacheOut;  // read and checked before the grids load
  if (!a.msCacheIn.empty()) cacheIn = readMsCacheFile(a.msCacheIn, "--ms-cache-in", scene).snapshot;

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
  if (resume.resuming) options.resumeFrom = &resume.state;
  // --frames with the path tracer: K passes of one sample per pixel (a frame each), K spp in all.
  if (a.frames > 0 && !realtime) {
    scene.renderer.spp = a.frames;
    options.samplesPerPass = 1;
  }
  options.majorant = resume.majorant;
  options.majorantResolution = resume.majorantResolution;
  options.counters = a.counters;
  options.frameBudgetMs = a.targetMs;
  if (!a.msCacheIn.empty()) options.msCacheIn = &cacheIn;
  if (!a.msCacheOut.empty()) options.msCacheOut = &cacheOut;
  snapshots.install(options);
  const RenderResult r = realtime ? renderRealtime(rt, scene, g, std::max(1, a.frames), options)
                                  : renderPathtrace(rt, scene, g, options);
  bar.finish();
  snapshots.finish(r);
  for (const std::string& w : r.warnings) std::cerr << "narval: warning: " << w << "\n";
  if (r.image.width == 0) {
    std::cerr << "narval: interrupted before the first " << (realtime ? "frame" : "pass") << "; nothing written\n";
    return kExitInterrupted;
  }
  writeOutputs(out, r, scene, a.frames, cacheOut);
  return reportOutcome(a, out, r.stats, realtime, report);
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
  sub->add_option("--target-ms", a->targetMs,
                  "Real-time, with --frames: a frame's budget, as the viewer's; the multiple-scattering cache is "
                  "built over the frames in what each leaves of it (the image is the last frame's)")
      ->check(greaterThanZero());
  sub->add_option("--ms-cache-out", a->msCacheOut,
                  "raymarch: write the multiple-scattering cache as built to FILE, for --ms-cache-in");
  sub->add_option("--ms-cache-in", a->msCacheIn,
                  "raymarch: start the multiple-scattering cache from FILE (--ms-cache-out of the same scene and "
                  "cache settings; another camera pose where the cache does not depend on it)");
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
  sub->get_option("--target-ms")->needs(frames);
  sub->add_flag("--resume", a->resume,
                "pathtrace: continue the render already at the output path (interrupted, or with fewer spp) "
                "to the requested spp; the pixels equal those of one uninterrupted render")
      ->excludes(frames);
  return {sub, [a]() { return runRender(*a); }};
}

}  // namespace narval
