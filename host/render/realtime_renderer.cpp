#include "render/realtime_renderer.h"

#include <algorithm>
#include <chrono>

#include "render/device_allocation.h"
#include "render/device_scene.h"
#include "render/light_cache.h"
#include "render/ms_cache.h"
#include "render/node_grid.h"
#include "render/lobe_directions.h"
#include "render/majorant_options.h"
#include "render/render_common.h"
#include "scene/input_error.h"
#include "volume/majorant_grid.h"

namespace narval {

realtime_params realtimeParams(const Scene& scene, const DeviceScene& ds, size_t maxAllocBytes) {
  const RendererSettings& r = scene.renderer;
  const bool lobe = r.algorithm == Algorithm::Lobe;
  realtime_params p{};
  p.steps = lobe ? r.lobe.firstHitSteps : r.raymarch.steps;
  p.shadow_steps = lobe ? r.lobe.shadowSteps : r.raymarch.shadowSteps;
  p.min_transmittance = lobe ? r.lobe.minTransmittance : r.raymarch.minTransmittance;
  p.octaves = r.raymarch.multipleScattering == MultipleScattering::Octaves ? r.raymarch.octaves : 1;
  p.octave_a = r.raymarch.octaveScattering;
  p.octave_b = r.raymarch.octaveExtinction;
  p.octave_c = r.raymarch.octavePhase;
  p.depth_factor = r.lobe.depthFactor;
  p.lobe_radius = r.lobe.lobeRadius;
  p.lobe_points = r.lobe.lobePoints;
  // The variants' defaults where the scene leaves the key out (0): eq7 the dissertation's.
  int lobeShadowAreaSamples = 1, lobeViewSteps = 24;
  switch (r.lobe.variant) {
    case LobeVariant::Eq7: p.lobe_variant = LOBE_EQ7; break;
    case LobeVariant::Corrected:
      p.lobe_variant = LOBE_CORRECTED;
      lobeShadowAreaSamples = 4;
      lobeViewSteps = 16;
      break;
  }
  if (r.lobe.shadowAreaSamples > 0) lobeShadowAreaSamples = r.lobe.shadowAreaSamples;
  if (r.lobe.viewSteps > 0) lobeViewSteps = r.lobe.viewSteps;
  p.view_steps = lobeViewSteps;
  p.area_light_samples = lobe ? r.lobe.areaLightSamples : r.raymarch.areaLightSamples;
  p.shadow_area_samples = lobe ? lobeShadowAreaSamples : r.raymarch.shadowAreaSamples;
  switch (lobe ? r.lobe.areaLightPhase : r.raymarch.areaLightPhase) {
    case AreaLightPhase::Points: p.area_light_phase = AREA_LIGHT_POINTS; break;
    case AreaLightPhase::Exact: p.area_light_phase = AREA_LIGHT_EXACT; break;
  }
  p.light_cache = lightCacheLayout(ds, r.lightCache.resolution, maxAllocBytes);
  p.shadow_weighting = SHADOW_WEIGHTING_AREA;  // the lobe's, and the ray marcher's by default
  if (!lobe && r.raymarch.shadowWeighting == ShadowWeighting::Phase) p.shadow_weighting = SHADOW_WEIGHTING_PHASE;
  const MsCacheSettings& mc = r.raymarch.msCache;
  const bool msCache = !lobe && r.raymarch.multipleScattering == MultipleScattering::Cache;
  p.ms_cache_tile = mc.tile;
  switch (mc.layout) {
    case MsCacheLayout::Grid:
      p.ms_cache_layout = MS_CACHE_LAYOUT_GRID;
      if (msCache) p.ms_cache = nodeGridLayout(ds, mc.resolution);
      break;
    case MsCacheLayout::View:  // columns over the image, slices along them (ms_cache_view.h)
      p.ms_cache_layout = MS_CACHE_LAYOUT_VIEW;
      if (msCache && ds.params.has_medium) {
        p.ms_cache.nx = (ds.params.camera.width + mc.tile - 1) / mc.tile;
        p.ms_cache.ny = (ds.params.camera.height + mc.tile - 1) / mc.tile;
        p.ms_cache.nz = mc.slices;
      }
      break;
  }
  switch (mc.closure) {
    case MsCacheClosure::Linear: p.ms_cache_closure = MS_CACHE_CLOSURE_LINEAR; break;
    case MsCacheClosure::Hg: p.ms_cache_closure = MS_CACHE_CLOSURE_HG; break;
    case MsCacheClosure::Camera: p.ms_cache_closure = MS_CACHE_CLOSURE_CAMERA; break;
  }
  if (mc.layout == MsCacheLayout::View) p.ms_cache_closure = MS_CACHE_CLOSURE_CAMERA;  // its paths aim at the camera
  p.ms_cache_direct = msCache && mc.direct;
  // The guide draws about the lights where the paths draw from the phase function (phase_guide.h).
  p.ms_cache_guide = msCache && p.ms_cache_closure == MS_CACHE_CLOSURE_CAMERA ? mc.guide : 0.0f;
  if (mc.layout == MsCacheLayout::View) {  // the filter over the view nodes (ms_cache_filter.h)
    p.ms_cache_filter = mc.filter;
    p.ms_cache_filter_tolerance = mc.filterTolerance;
    p.ms_cache_filter_twicing = mc.filter > 0 && mc.filterTwicing;
  }
  if (p.ms_cache_direct) p.light_cache = node_grid_params{};  // no light loop: no shadow rays to cache
  switch (r.raymarch.msCache.interpolation) {
    case MsCacheInterpolation::Geometric: p.ms_cache_interpolation = MS_CACHE_INTERPOLATION_GEOMETRIC; break;
    case MsCacheInterpolation::Linear: p.ms_cache_interpolation = MS_CACHE_INTERPOLATION_LINEAR; break;
  }
  return p;
}

RealtimeRenderer::RealtimeRenderer(ClRuntime& rt, const Scene& scene, SceneGrids grid,
                                   const RenderOptions& options)
    : rt_(rt), view_(scene), options_(options), dev_(rt, checkedScene(scene, options), grid) {
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
  const realtime_params params = realtimeParams(view, dev_.scene, rt_.selected.info.maxAllocBytes);
  if (rawBytes(params) != rawBytes(params_) || !paramBuf_()) {
    paramBuf_ = constantBuffer(rt_, params);
    kernel_.set("params", paramBuf_);
    if (params.light_cache.nx == 0) kernel_.set("light_cache", noCache_);
    if (params.ms_cache.nx == 0) kernel_.set("ms_cache", noCache_);
  }
  // The lobe's directions depend on its point count (and g, seed: the scene's); one dummy otherwise.
  if (params.lobe_points != params_.lobe_points || !dirBuf_()) {
    std::vector<nv_float4> dirs = view.renderer.algorithm == Algorithm::Lobe
                                      ? lobeDirections(params.lobe_points, dev_.scene.params, view.renderer.seed)
                                      : std::vector<nv_float4>(1, nv_float4{0, 0, 1, 0});
    dirCount_ = dirs.size();
    dirBuf_ = cl::Buffer(rt_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, dirs.size() * sizeof(nv_float4),
                         dirs.data());
    kernel_.set("lobe_directions", dirBuf_);
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

double RealtimeRenderer::renderFrame(bool progressiveCache, double* wallMs) {
  if (params_.light_cache.nx > 0) {  // a no-op unless the medium or a light changed
    lightCache_.update(rt_, dev_, params_, view_.sourcePath);
    kernel_.set("light_cache", lightCache_.buffer());
  }
  if (params_.ms_cache.nx > 0) {  // built to its paths (progressively: one launch a frame), then kept
    const MsCacheSettings& mc = view_.renderer.raymarch.msCache;
    const int target = progressiveCache ? std::min(mc.paths, msCache_.paths() + mc.pathsPerLaunch) : mc.paths;
    MsCacheAllocation allocation;
    allocation.perceptual =
        mc.layout == MsCacheLayout::View && mc.allocation == MsCacheAllocationKind::Perceptual;
    allocation.meanPaths = mc.paths;
    allocation.toneMapping = view_.renderer.toneMapping;
    allocation.exposure = view_.renderer.exposure;
    msCache_.refine(rt_, dev_, params_, target, mc.pathsPerLaunch, view_.sourcePath, allocation);
    kernel_.set("ms_cache", msCache_.buffer());
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
  st.status |= lightCache_.status();
  st.lightCacheMs = lightCache_.buildMs();
  st.lightCacheBuilds = lightCache_.slabsBuilt();
  st.lightCacheBytes = lightCache_.bytes();
  nodeGridCells(params_.light_cache, st.lightCacheCells);
  st.status |= msCache_.status();
  st.msCacheMs = msCache_.buildMs();
  st.msCachePaths = msCache_.paths();
  st.msCacheBuilds = msCache_.rebuilds();
  st.msCacheView = params_.ms_cache_layout == MS_CACHE_LAYOUT_VIEW;
  if (st.msCacheView) {  // its nodes are not cell corners: columns, rows, slices
    st.msCacheCells[0] = params_.ms_cache.nx;
    st.msCacheCells[1] = params_.ms_cache.ny;
    st.msCacheCells[2] = params_.ms_cache.nz;
    st.msCacheFilter = params_.ms_cache_filter;
    st.msCacheFilterTolerance = params_.ms_cache_filter > 0 ? params_.ms_cache_filter_tolerance : 0;
    st.msCacheFilterTwicing = params_.ms_cache_filter_twicing != 0;
  } else {
    nodeGridCells(params_.ms_cache, st.msCacheCells);
  }
  st.msCacheGuide = params_.ms_cache_guide;
  st.msCacheBudgetMin = msCache_.budgetMin();
  st.msCacheBudgetMax = msCache_.budgetMax();
  result.image = imageFromRgba(rgba, W, H, 1.0f, &st.nanPixels);
  return result;
}

RenderResult renderRealtime(ClRuntime& rt, const Scene& scene, SceneGrids grid, int frames,
                            const RenderOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  RealtimeRenderer renderer(rt, scene, grid, options);
  rt.queue.finish();
  const double buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // One launch per frame, each timed by its profiling event and by the wall clock around it.
  const int requested = std::max(1, frames);
  std::vector<double> kernelMs, wallMs;
  for (int f = 0; f < requested && !cancelled(options); ++f) {
    double wall = 0;
    kernelMs.push_back(renderer.renderFrame(false, &wall));
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
