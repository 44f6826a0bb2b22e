// viewer_session.h: what `narval view` does between its window and the renderers, without the
// window: the camera controls, the algorithm and its quality parameter, progressive accumulation,
// the reduced resolution while the camera moves, snapshots (P), the live comparison against a
// reference, and the frames counted per resolution. The GLFW window (viewer_window.h) and the
// scripted runs feed it the same ViewerInputs, so scripted tests exercise what a user drives.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "analysis/image_compare.h"
#include "cl/cl_runtime.h"
#include "image/image.h"
#include "render/pathtrace_renderer.h"
#include "render/realtime_renderer.h"
#include "scene/scene.h"
#include "viewer/orbit_camera.h"
#include "viewer/viewer_input.h"
#include "volume/dense_grid.h"

namespace narval {

struct ViewerOptions {
  // A frame's budget: while the camera moves, the resolution is divided by 2, 4 or 8 so that a frame is
  // predicted to take at most this many milliseconds (kernel time, from the frames so far); still frames
  // are full size. The multiple-scattering cache is built in what the last frame left of it.
  double targetMs = 50;
  std::string outputDir = ".";          // where P writes its EXR, PNG and scene JSON
  const ImageRGB* reference = nullptr;  // --reference: compared while the camera is at the scene's pose
  std::string referenceName;
  RenderOptions render;                 // work-group shape, majorant (as `narval render` takes them)
  const MsCacheSnapshot* msCacheIn = nullptr;  // --ms-cache-in: the ray marcher's cache starts from it
};

class ViewerSession {
 public:
  // `scene` is validated, its algorithm the first one shown; `grid` outlives the session.
  ViewerSession(ClRuntime& rt, const Scene& scene, SceneGrids grid, const ViewerOptions& options);
  ~ViewerSession();

  // Applies one input; camera moves and settings take effect at the next frame. Frames inputs are
  // the caller's (it renders them).
  void apply(const ViewerInput& input);
  // Whether a frame would change nothing: the path tracer has all its samples and nothing moved.
  // The real-time kernels redraw every frame.
  bool idle() const;
  // Renders the next frame and composes what the window shows (display()).
  void renderFrame();

  // The last frame as shown: full resolution (a reduced frame scaled up by pixel replication),
  // display-transformed as the PNG is, with the help overlay when it is on.
  const ImageRGB8& display() const { return display_; }
  // "narval view: SCENE | ALGORITHM | MS ms | WxH | SPP spp | DEVICE | ms cache P% | ΔE76 E, JND J%": the
  // ms cache part (the share of its paths built) with the ray marcher's multiple-scattering cache, the
  // error part with --reference at the scene's pose.
  std::string title() const;
  // Frames rendered per resolution ("320x240" → count), in this run.
  const std::map<std::string, int>& framesPerResolution() const { return framesPerResolution_; }
  // Per resolution, each frame's kernel milliseconds (profiling events) and the whole frame's (wall
  // clock: caches, launch, read-back, display transform, comparison), for the viewer's report.
  struct FrameTimes {
    std::vector<double> kernelMs, frameMs;
  };
  const std::map<std::string, FrameTimes>& frameTimes() const { return frameTimes_; }
  int frames() const { return frames_; }
  // Lines for the user (snapshots written, warnings), taken once.
  std::vector<std::string> takeMessages();
  Algorithm algorithm() const { return algorithm_; }
  double lastFrameMs() const { return lastMs_; }
  // Live comparison with --reference (valid() false when there is none or the camera is elsewhere).
  struct LiveError {
    bool valid = false;
    double meanDeltaE76 = 0, jndPercent = 0;
  };
  const LiveError& liveError() const { return liveError_; }

 private:
  // The scene the next full-size frame renders (camera, algorithm, quality, resolution).
  Scene currentScene() const;
  int chooseLevel() const;
  void writeSnapshot(const RenderResult& result, const Scene& view);
  void compose(const ImageRGB& image);
  RealtimeRenderer& realtime(const Scene& view);
  PathtraceRenderer& pathtrace(const Scene& view);

  ClRuntime& rt_;
  Scene scene_;  // as loaded; the current camera, algorithm and quality are kept apart
  SceneGrids grid_;
  ViewerOptions options_;
  OrbitCamera camera_;
  Algorithm algorithm_;
  int raymarchSteps_, lobePoints_, pathtraceSppPerFrame_ = 1;
  bool moved_ = true;       // the camera changed since the last frame
  bool restart_ = true;     // the path tracer starts over at the next frame
  bool snapshot_ = false;   // P pressed: the next frame is full size and written out
  bool help_ = false;
  std::unique_ptr<RealtimeRenderer> raymarch_, lobe_;
  std::unique_ptr<PathtraceRenderer> pathtrace_;
  std::string pathtraceViewKey_;  // the view the path tracer accumulates
  std::map<Algorithm, double> msPerPixel_;  // per algorithm: the last frame's kernel ms per pixel (and sample)
  ImageRGB8 display_;
  int frames_ = 0, lastWidth_ = 0, lastHeight_ = 0, spp_ = 0;
  double lastMs_ = 0;
  double cacheProgress_ = -1;  // the ray marcher's multiple-scattering cache: the share built (-1: none)
  std::map<std::string, int> framesPerResolution_;
  std::map<std::string, FrameTimes> frameTimes_;
  std::vector<std::string> messages_;
  LiveError liveError_;
  std::vector<float> comparedRgb_;  // the last frame compared with the reference, and its error
  LiveError comparedError_;
};

}  // namespace narval
