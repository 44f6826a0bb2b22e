#include "render/realtime_renderer.h"

#include <algorithm>
#include <chrono>

#include "cl/device_allocation.h"
#include "core/input_error.h"
#include "render/device_light_cache.h"
#include "render/device_ms_cache.h"
#include "render/device_scene.h"
#include "render/lobe_directions.h"
#include "render/majorant_options.h"
#include "render/node_grid_layout.h"
#include "render/render_common.h"
#include "volume/majorant_grid.h"

namespace narval {

RealtimeRenderer::RealtimeRenderer(ClRuntime& rt, const Scene& scene, SceneGrids grid,
                                   const RenderOptions& options)
    : rt_(rt),
      view_(scene),
      options_(options),
      dev_(rt, checkedScene(scene, options), grid),
      cachePixels_(double(scene.renderer.width) * double(scene.renderer.height)) {
  const std::string algorithm = algorithmName(scene.renderer.algorithm);
  warnings_ = dev_.scene.warnings;
  stats_ = initialStats(algorithm, rt, scene);
  recordGridStorage(stats_, dev_);
  stats_.majorant = "grid";  // the marches always skip empty cells (march.h); options.majorant is the path tracer's
  // The marches place their samples over the occupied cells of the majorant grid (march.h), so its
  // resolution is part of their quadrature: they keep buildDeviceScene's, whatever the path
  // tracer's --majorant-resolution says, and that flag changes no real-time pixel.
  applyMajorantResolution(rt, dev_, 0, stats_);
  if (options.majorantResolution > 0)
    warnings_.push_back("--majorant-resolution applies to the path tracer; " + algorithm +
                        " samples over the occupied cells of the default " +
                        std::to_string(kDefaultMajorantResolution) + "-cell grid");
  stats_.spp = stats_.sppRequested = 1;
  program_ = buildProgram(rt, algorithm + ".cl", dev_.buildOptions(), nullptr, &stats_.programFromCache);
  kernel_ = NamedKernel(program_, algorithm);
  statusBuf_ = cl::Buffer(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
  rt.queue.enqueueFillBuffer(statusBuf_, cl_uint(0), 0, sizeof(cl_uint));
  noCache_ = cl::Buffer(rt.context, CL_MEM_READ_ONLY, sizeof(float));  // for a cache that is off: never read
  dev_.bind(kernel_);
  kernel_.set("status_word", statusBuf_);
  view_.renderer.width = view_.renderer.height = 0;  // setView uploads everything the first time
  setView(scene);
}

const Scene& RealtimeRenderer::checkedScene(const Scene& scene, const RenderOptions& options) {
  if (!isRealtime(scene.renderer.algorithm))
    throw std::invalid_argument(std::string("RealtimeRenderer: not a real-time algorithm: ") +
                                algorithmName(scene.renderer.algorithm));
  checkMajorantOptions(options);
  return scene;
}

void RealtimeRenderer::setView(const Scene& view) {
  if (view.renderer.algorithm != view_.renderer.algorithm)
    throw std::invalid_argument(std::string("RealtimeRenderer::setView: another algorithm (") +
                                algorithmName(view.renderer.algorithm) + ")");
  const int W = view.renderer.width, H = view.renderer.height;
  const bool resized = W != view_.renderer.width || H != view_.renderer.height;
  const camera_params camera = buildCamera(view);
  if (rawBytes(camera) != rawBytes(dev_.scene.params.camera) || resized) {
    dev_.scene.params.camera = camera;
    rt_.queue.enqueueWriteBuffer(dev_.sceneBuf, CL_TRUE, 0, sizeof(scene_params), &dev_.scene.params);
  }
  // Each kernel takes the blocks of its features (realtime_params.h); a cache that is off reads a
  // placeholder, never touched.
  const RealtimeParams params = realtimeParams(view, dev_.scene, rt_.selected.info.maxAllocBytes, cachePixels_,
                                                rt_.selected.info.type == "GPU");
  kernel_.set("march", params.march);
  kernel_.set("light_cache", params.lightCache);
  if (params.lightCache.nx == 0) kernel_.set("light_cache_nodes", noCache_);
  switch (view.renderer.algorithm) {
    case Algorithm::Raymarch:
      kernel_.set("ms_cache", params.msCache);
      if (params.msCache.grid.nx == 0) kernel_.set("ms_cache_nodes", noCache_);
      break;
    case Algorithm::Lobe:
      kernel_.set("lobe", params.lobe);
      // The lobe's directions depend on its point count (and g, seed: the scene's).
      if (params.lobe.points != params_.lobe.points || !dirBuf_()) {
        std::vector<nv_float4> dirs = lobeDirections(params.lobe.points, dev_.scene.params, view.renderer.seed);
        dirCount_ = dirs.size();
        dirBuf_ = cl::Buffer(rt_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, dirs.size() * sizeof(nv_float4),
                             dirs.data());
        kernel_.set("lobe_directions", dirBuf_);
      }
      break;
    case Algorithm::Pathtrace: break;  // refused by checkedScene
  }
  params_ = params;
  if (resized) {
    const AllocationSite site{view.sourcePath, "renderer.resolution",
                              "an image of " + std::to_string(W) + "x" + std::to_string(H) + " RGBA floats"};
    outBuf_ = allocateBuffer(rt_, CL_MEM_WRITE_ONLY, size_t(W) * size_t(H) * 4 * sizeof(float), site);
    kernel_.set("out", outBuf_);
  }
  view_ = view;
  stats_.width = W;
  stats_.height = H;
}

double RealtimeRenderer::renderFrame(double cacheBudgetMs, double* wallMs) {
  if (params_.lightCache.nx > 0) {  // a no-op unless the medium or a light changed
    lightCache_.update(rt_, dev_, params_.march, params_.lightCache, view_.sourcePath);
    kernel_.set("light_cache_nodes", lightCache_.buffer());
  }
  if (params_.msCache.grid.nx > 0) {  // built to its paths (within a budget: over frames), then kept
    const MsCacheSettings& mc = view_.renderer.raymarch.msCache;
    msCache_.refine(rt_, dev_, params_.msCache, mc.paths, kMsCachePathsPerLaunch, view_.sourcePath, cacheBudgetMs);
    kernel_.set("ms_cache_nodes", msCache_.buffer());
  }
  const int W = view_.renderer.width, H = view_.renderer.height;
  const size_t deviceBytes = deviceSceneBytes(dev_.scene) + size_t(W) * size_t(H) * 4 * sizeof(float) +
                             sizeof(params_) + dirCount_ * sizeof(nv_float4) + lightCache_.bytes() + msCache_.bytes();
  const auto t0 = std::chrono::steady_clock::now();
  const cl::Event ev = launchAndWait(rt_, kernel_.get(), paddedGlobalRange(W, H, options_), localRange(options_),
                                     algorithmName(view_.renderer.algorithm), deviceBytes);
  if (wallMs) *wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++stats_.passes;
  return eventSeconds(ev) * 1e3;
}

RenderResult RealtimeRenderer::result() {
  RenderResult result;
  result.warnings = warnings_;
  result.stats = stats_;
  RenderStats& st = result.stats;
  const int W = view_.renderer.width, H = view_.renderer.height;
  std::vector<float> rgba(size_t(W) * size_t(H) * 4);
  rt_.queue.enqueueReadBuffer(outBuf_, CL_TRUE, 0, rgba.size() * sizeof(float), rgba.data());
  rt_.queue.enqueueReadBuffer(statusBuf_, CL_TRUE, 0, sizeof(cl_uint), &st.status);
  st.status |= lightCache_.status() | msCache_.status();
  st.lightCache.ms = lightCache_.buildMs();
  st.lightCache.builds = lightCache_.slabsBuilt();
  st.lightCache.bytes = lightCache_.bytes();
  nodeGridCells(params_.lightCache, st.lightCache.cells);
  MsCacheStats& ms = st.msCache;
  const ms_cache_params& mc = params_.msCache;
  ms.ms = msCache_.buildMs();
  ms.paths = msCache_.paths();
  ms.progress = mc.grid.nx > 0 ? std::min(1.0, msCache_.pathsDone() / std::max(1, view_.renderer.raymarch.msCache.paths)) : 0;
  ms.builds = msCache_.rebuilds();
  ms.view = mc.layout == MS_CACHE_LAYOUT_VIEW;
  if (ms.view) {  // its nodes are not cell corners: columns, rows, slices
    ms.cells[0] = mc.grid.nx;
    ms.cells[1] = mc.grid.ny;
    ms.cells[2] = mc.grid.nz;
    ms.filter = mc.filter;
    ms.filterTwicing = mc.filter_twicing != 0;
  } else {
    nodeGridCells(mc.grid, ms.cells);
  }
  result.image = imageFromRgba(rgba, W, H, 1.0f, &st.nanPixels);
  return result;
}

RenderResult renderRealtime(ClRuntime& rt, const Scene& scene, SceneGrids grid, int frames,
                            const RenderOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  RealtimeRenderer renderer(rt, scene, grid, options);
  if (options.msCacheIn) renderer.restoreMsCache(*options.msCacheIn);
  rt.queue.finish();
  const double buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // One launch per frame, each timed by its profiling event and by the wall clock around it.
  const int requested = std::max(1, frames);
  std::vector<double> kernelMs, wallMs;
  const double budget = options.frameBudgetMs;
  for (int f = 0; f < requested && !cancelled(options); ++f) {
    double wall = 0;
    const auto frameStart = std::chrono::steady_clock::now();
    kernelMs.push_back(renderer.renderFrame(cacheBudgetMs(budget, kernelMs.empty() ? 0 : kernelMs.back()), &wall));
    if (budget > 0) wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frameStart).count();
    wallMs.push_back(wall);
    if (options.progress) options.progress(f + 1, requested);
  }
  if (kernelMs.empty()) {
    RenderResult result;
    result.warnings = renderer.warnings();
    result.stats = renderer.stats();
    result.stats.buildSeconds = buildSeconds;
    result.stats.interrupted = true;
    result.stats.spp = 0;
    return result;
  }
  RenderResult result = renderer.result();
  result.mediumMask = renderer.mediumMask();
  if (options.msCacheOut) *options.msCacheOut = renderer.msCacheSnapshot();
  RenderStats& st = result.stats;
  st.buildSeconds = buildSeconds;
  st.interrupted = int(kernelMs.size()) < requested;
  st.frames = frameTimings(kernelMs, wallMs);
  for (double ms : kernelMs) st.kernelSeconds += ms * 1e-3;
  for (double ms : wallMs) st.seconds += ms * 1e-3;
  const size_t pixels = size_t(scene.renderer.width) * size_t(scene.renderer.height);
  st.samplesPerSecond = st.seconds > 0 ? double(pixels) * st.passes / st.seconds : 0.0;
  return result;
}

}  // namespace narval
