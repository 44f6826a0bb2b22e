// realtime_renderer.h: drives the real-time kernels (kernels/raymarch.cl, kernels/lobe.cl): the
// scene's arguments, each feature's parameter block (realtime_params.h), the caches, RGBA out and
// the status word, bound by name. A frame is one launch that writes the whole image; `frames`
// launches are timed one by one. The light-transmittance cache (render/device_light_cache.h) is
// brought up to date before every frame, which rebuilds it only when what it was built from changed
// (counted in RenderStats).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "render/device_light_cache.h"
#include "render/device_ms_cache.h"
#include "render/device_scene.h"
#include "render/medium_mask.h"
#include "render/realtime_params.h"
#include "render/render_types.h"
#include "render/scene_upload.h"
#include "scene/scene.h"
#include "shared/structs.h"
#include "volume/dense_grid.h"

namespace narval {

// A real-time renderer held across frames: the program, the scene on the device and the caches are
// built once; the camera, the resolution and the quality settings may change between frames
// (setView) without rebuilding them. `narval render` runs one for its frames (renderRealtime), the
// viewer one per real-time algorithm, so both draw with the same code.
class RealtimeRenderer {
 public:
  // scene.renderer.algorithm must be "raymarch" or "lobe". Builds the program and uploads the scene;
  // the caches are built by the first frame.
  RealtimeRenderer(ClRuntime& rt, const Scene& scene, SceneGrids grid, const RenderOptions& options = {});
  // The next frames show `view`: the constructor's scene with another camera, renderer.resolution or
  // renderer.raymarch / renderer.lobe settings (its medium, lights and algorithm unchanged). The
  // automatic light cache is weighed against the constructor's resolution, so that frames drawn
  // smaller (a viewer in motion) keep it.
  void setView(const Scene& view);
  // One frame: brings the caches up to date (with cacheBudgetMs > 0, at most about that much build time
  // of the multiple-scattering cache, so a viewer refines it over frames and never waits for all of it:
  // DeviceMsCache::refine; otherwise all of it), then one launch of the kernel, waited for. Returns its
  // milliseconds by profiling event; wallMs, when not null, gets the wall clock around the launch.
  double renderFrame(double cacheBudgetMs = 0, double* wallMs = nullptr);
  // The last frame read back (image, status, caches' statistics); stats.frames stays empty.
  RenderResult result();
  const RenderStats& stats() const { return stats_; }
  // The multiple-scattering cache: started from a snapshot at the first frame (DeviceMsCache::
  // restoreAtStart), or read back as it is.
  void restoreMsCache(MsCacheSnapshot snapshot) { msCache_.restoreAtStart(std::move(snapshot)); }
  MsCacheSnapshot msCacheSnapshot() { return msCache_.snapshot(rt_); }
  const std::vector<std::string>& warnings() const { return warnings_; }
  const DeviceScene& deviceScene() const { return dev_.scene; }
  // The current camera's medium mask (render/medium_mask.h): what an EXR of the image holds beside
  // it. Asked for by whoever writes one, not per frame: a host ray per pixel.
  std::vector<uint32_t> mediumMask() { return mask_.pixels(dev_.scene); }

 private:
  // The scene, once its algorithm and the options are known to suit a real-time renderer.
  static const Scene& checkedScene(const Scene& scene, const RenderOptions& options);
  ClRuntime& rt_;
  Scene view_;
  RenderOptions options_;
  DeviceSceneBuffers dev_;
  MediumMask mask_;
  double cachePixels_;  // the constructor's image size (realtimeParams)
  RealtimeParams params_;
  DeviceLightCache lightCache_;
  DeviceMsCache msCache_;
  cl::Program program_;
  NamedKernel kernel_;
  cl::Buffer dirBuf_, outBuf_, statusBuf_, noCache_;
  size_t dirCount_ = 0;
  RenderStats stats_;
  std::vector<std::string> warnings_;
};

// What a frame with a budget of frameBudgetMs leaves the multiple-scattering cache after a frame that
// took lastFrameMs: the rest, a quarter of the budget at least (the viewer and renderRealtime).
inline double cacheBudgetMs(double frameBudgetMs, double lastFrameMs) {
  return frameBudgetMs > 0 ? std::max(frameBudgetMs / 4, frameBudgetMs - lastFrameMs) : 0;
}

// Renders scene.renderer.algorithm ("raymarch" or "lobe") `frames` times (>= 1); the image is the
// last frame (every frame is the same: the kernels are deterministic).
RenderResult renderRealtime(ClRuntime& rt, const Scene& scene, SceneGrids grid, int frames,
                            const RenderOptions& options = {});

}  // namespace narval
