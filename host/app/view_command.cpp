// narval view: the interactive viewer (viewer/viewer_session.h, viewer/viewer_window.h).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "app/commands.h"
#include "core/input_error.h"
#include "image/image.h"
#include "viewer/viewer_input.h"
#include "render/ms_cache_file.h"
#include "viewer/viewer_session.h"
#include "viewer/viewer_window.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct ViewArgs {
  std::string scene, algorithm, device, reference, resolution, script, screenshot, outputDir = "out", statsJson;
  std::string localSize = "8x8", msCacheIn;
  std::vector<std::string> sets;
  double targetMs = 50;
  int frames = 0;
};

// The session's --stats-json: frames and their median times per resolution, the largest after the
// first (which builds the programs), and the live error.
nlohmann::json viewStatsJson(const ViewerSession& session, const ViewerWindow& window, const ClRuntime& rt) {
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  nlohmann::json perResolution = nlohmann::json::object();
  for (const auto& [size, times] : session.frameTimes())
    perResolution[size] = {{"frames", times.kernelMs.size()},
                           {"kernel_ms_median", median(times.kernelMs)},
                           {"frame_ms_median", median(times.frameMs)},
                           {"frame_ms_max_after_first", times.frameMs.size() < 2 ? 0.0
                                                        : *std::max_element(times.frameMs.begin() + 1, times.frameMs.end())}};
  nlohmann::json j = {{"frames", session.frames()},
                      {"frames_per_resolution", session.framesPerResolution()},
                      {"per_resolution", perResolution},
                      {"present_ms_median", median(window.presentMs())},
                      {"algorithm", algorithmName(session.algorithm())},
                      {"last_frame_ms", session.lastFrameMs()},
                      {"device", rt.selected.info.name},
                      // Frames go through the host; whether the device could share them with OpenGL:
                      {"gl_sharing_extension",
                       rt.selected.device.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_gl_sharing") !=
                           std::string::npos}};
  if (session.liveError().valid)
    j["reference"] = {{"mean_delta_e76", session.liveError().meanDeltaE76},
                      {"jnd_percent", session.liveError().jndPercent}};
  return j;
}

int runView(const ViewArgs& a) {
  std::vector<std::string> overrides = a.sets;
  if (!a.algorithm.empty()) overrides.push_back("renderer.algorithm=\"" + a.algorithm + "\"");
  if (!a.resolution.empty()) overrides.push_back(resolutionOverride(a.resolution));
  Scene scene = loadScene(a.scene, overrides);
  for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
  const auto [lx, ly] = parseSize(a.localSize, "--local-size");

  // Everything the user gave is read and checked before the window opens and the grid loads.
  ViewerWindow::Run run;
  if (!a.script.empty()) {
    run.script = readViewerScript(a.script);
    run.scripted = true;
  }
  int scriptFrames = 0;
  for (const ViewerInput& in : run.script)
    if (in.kind == ViewerInput::Kind::Frames) scriptFrames += in.frames;
  run.frames = a.frames > 0 ? a.frames : run.scripted ? std::max(1, scriptFrames) : 0;
  if (!a.screenshot.empty()) {
    if (fs::path(a.screenshot).extension() != ".png")
      throw inputError("--screenshot", "", "the screenshot must be a .png file, got '" + a.screenshot + "'");
    if (run.frames == 0)
      throw inputError("--screenshot", "", "needs --script or --frames (the screenshot is of the last frame)");
    run.screenshot = a.screenshot;
  }
  checkOutputWritable(a.screenshot, "--screenshot");
  checkOutputWritable(a.statsJson, "--stats-json");
  checkOutputWritable((fs::path(a.outputDir) / "view.exr").string(), "--output-dir");  // where P writes
  ImageRGB reference;
  ViewerOptions options;
  if (!a.reference.empty()) {
    reference = readExr(a.reference);
    if (reference.width != scene.renderer.width || reference.height != scene.renderer.height)
      throw inputError("--reference", "", a.reference + " is " + std::to_string(reference.width) + "x" +
                                              std::to_string(reference.height) + "; the scene renders " +
                                              std::to_string(scene.renderer.width) + "x" +
                                              std::to_string(scene.renderer.height));
    options.reference = &reference;
    options.referenceName = a.reference;
  }
  MsCacheSnapshot cacheIn;
  if (!a.msCacheIn.empty()) {
    if (scene.renderer.raymarch.multipleScattering != MultipleScattering::Cache)
      throw msCacheFlagWithoutCache("--ms-cache-in");
    cacheIn = readMsCacheFile(a.msCacheIn, "--ms-cache-in", scene).snapshot;
    options.msCacheIn = &cacheIn;
  }
  options.targetMs = a.targetMs;
  options.outputDir = a.outputDir;
  options.render.localSizeX = lx;
  options.render.localSizeY = ly;

  ViewerWindow window(scene.renderer.width, scene.renderer.height, "narval view: " + a.scene, run.frames > 0);
  SceneGridStorage gridStorage;
  const SceneGrids grid = loadSceneGrids(scene, gridStorage);
  ClRuntime rt(a.device);
  checkLocalSize(lx, ly, rt.selected.device, rt.selected.info.name);
  ViewerSession session(rt, scene, grid, options);
  window.run(session, run);

  std::string perResolution;
  for (const auto& [size, count] : session.framesPerResolution())
    perResolution += (perResolution.empty() ? "" : ", ") + size + ": " + std::to_string(count);
  std::cout << "narval view: " << session.frames() << " frames (" << perResolution << ") on "
            << rt.selected.info.name << "\n";
  if (!a.statsJson.empty()) writeTextAtomic(a.statsJson, viewStatsJson(session, window, rt).dump(2) + "\n");
  return 0;
}

}  // namespace

Command addViewCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("view", "Look at a scene in a window, rendered by the same kernels as render");
  auto a = std::make_shared<ViewArgs>();
  sub->add_option("SCENE.json", a->scene, "Scene file")->required();
  sub->add_option("--algorithm", a->algorithm, "pathtrace | raymarch | lobe (keys 1 2 3 switch)");
  sub->add_option("--device", a->device, "Device index or name substring (narval devices)");
  sub->add_option("--reference", a->reference,
                  "A render of the scene's camera (.exr): the title shows the frame's mean dE76 and JND% "
                  "against it while the camera is there");
  sub->add_option("--set", a->sets, "Override a scene value: dotted.path=value (repeatable)");
  sub->add_option("--resolution", a->resolution, "WIDTHxHEIGHT of the full-size frames");
  sub->add_option("--target-ms", a->targetMs,
                  "A frame's budget: while the camera moves, render at 1/2, 1/4 or 1/8 resolution so that a frame "
                  "takes about this long, and build the multiple-scattering cache in the time a frame leaves "
                  "(default 50)")
      ->check(greaterThanZero());
  sub->add_option("--ms-cache-in", a->msCacheIn,
                  "Start the ray marcher's multiple-scattering cache from FILE (narval render --ms-cache-out of the "
                  "same scene and cache settings)");
  sub->add_option("--script", a->script,
                  "Replay the inputs in FILE instead of a user (key, drag, scroll, hold, frames; docs/viewer.md)");
  sub->add_option("--frames", a->frames, "Stop after N frames (default with --script: the script's frames)")
      ->check(atLeast(1));
  sub->add_option("--screenshot", a->screenshot, "Save the window's last frame as PNG");
  sub->add_option("--output-dir", a->outputDir, "Where P writes its EXR, PNG and scene JSON (default out/, as scripts/render.sh)");
  sub->add_option("--stats-json", a->statsJson, "Write frame counts per resolution and the last frame's time");
  sub->add_option("--local-size", a->localSize, "Work-group shape WxH (default 8x8); never changes the pixels");
  addThreadsOption(sub);
  return {sub, [a]() { return runView(*a); }};
}

}  // namespace narval
