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
  const bool lobe = r.algorithm == "lobe";
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
  p.light_cache = lightCacheLayout(ds, r.lightCache.resolution, maxAllocBytes);
  if (!lobe && r.raymarch.multipleScattering == MultipleScattering::Cache)
    p.ms_cache = nodeGridLayout(ds, r.raymarch.msCache.resolution);
  return p;
}

RenderResult renderRealtime(ClRuntime& rt, const Scene& scene, const DenseGrid* grid, int frames,
                            const RenderOptions& options) {
  const std::string& algorithm = scene.renderer.algorithm;
  if (algorithm != "raymarch" && algorithm != "lobe")
    throw std::invalid_argument("renderRealtime: not a real-time algorithm: " + algorithm);
  const auto t0 = std::chrono::steady_clock::now();
  const int W = scene.renderer.width, H = scene.renderer.height;
  checkMajorantOptions(options);
  DeviceSceneBuffers dev(rt, scene, grid);

  RenderResult result;
  result.warnings = dev.scene.warnings;
  result.stats = initialStats(algorithm, rt, scene);
  RenderStats& st = result.stats;
  recordGridStorage(st, dev);
  st.majorant = "grid";  // the marches always skip empty cells (march.h); options.majorant is the path tracer's
  // The marches place their samples over the occupied cells of the majorant grid (march.h), so its
  // resolution is part of their quadrature: they keep buildDeviceScene's, whatever the path
  // tracer's --majorant-resolution says, and that flag changes no real-time pixel.
  applyMajorantResolution(rt, dev, 0, st);
  if (options.majorantResolution > 0)
    result.warnings.push_back("--majorant-resolution applies to the path tracer; " + algorithm +
                              " samples over the occupied cells of the default " +
                              std::to_string(kDefaultMajorantResolution) + "-cell grid");
  st.spp = st.sppRequested = 1;

  const realtime_params params = realtimeParams(scene, dev.scene, rt.selected.info.maxAllocBytes);
  DeviceLightCache lightCache;
  DeviceMsCache msCache;
  const scene_params& sp = dev.scene.params;
  const float g = sp.has_medium && sp.medium.phase == PHASE_HG ? sp.medium.g : 0.0f;
  std::vector<nv_float4> dirs = algorithm == "lobe" ? lobeDirections(params.lobe_points, g, scene.renderer.seed)
                                                    : std::vector<nv_float4>(1, nv_float4{0, 0, 1, 0});
  cl::Program program =
      buildProgram(rt, algorithm + ".cl", dev.scene.buildOptions, nullptr, &st.programFromCache);
  cl::Kernel kernel(program, algorithm.c_str());
  const size_t pixels = size_t(W) * size_t(H);
  cl::Buffer paramBuf = constantBuffer(rt, params);
  cl::Buffer dirBuf(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, dirs.size() * sizeof(nv_float4), dirs.data());
  const AllocationSite site{scene.sourcePath, "renderer.resolution",
                            "an image of " + std::to_string(W) + "x" + std::to_string(H) + " RGBA floats"};
  cl::Buffer outBuf = allocateBuffer(rt, CL_MEM_WRITE_ONLY, pixels * 4 * sizeof(float), site);
  cl::Buffer statusBuf(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
  rt.queue.enqueueFillBuffer(statusBuf, cl_uint(0), 0, sizeof(cl_uint));
  dev.bind(kernel);
  const cl_uint arg = DeviceSceneBuffers::kFirstFreeArg;
  kernel.setArg(arg + 0, paramBuf);
  kernel.setArg(arg + 1, dirBuf);
  kernel.setArg(arg + 4, outBuf);
  kernel.setArg(arg + 5, statusBuf);
  const cl::Buffer noCache(rt.context, CL_MEM_READ_ONLY, sizeof(float));  // for a cache that is off: never read
  if (params.light_cache.nx == 0) kernel.setArg(arg + 2, noCache);
  if (params.ms_cache.nx == 0) kernel.setArg(arg + 3, noCache);
  rt.queue.finish();
  st.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // One launch per frame, each timed by its profiling event and by the wall clock around it.
  const cl::NDRange global = paddedGlobalRange(W, H, options), local = localRange(options);
  const size_t deviceBytes = deviceSceneBytes(dev.scene) + pixels * 4 * sizeof(float) + sizeof(params) +
                             dirs.size() * sizeof(nv_float4);
  const int requested = std::max(1, frames);
  std::vector<double> kernelMs, wallMs;
  for (int f = 0; f < requested && !cancelled(options); ++f) {
    if (params.light_cache.nx > 0) {  // a no-op unless the scene changed (never, within one render)
      lightCache.update(rt, dev, params, scene.sourcePath);
      kernel.setArg(arg + 2, lightCache.buffer());
    }
    if (params.ms_cache.nx > 0) {  // likewise: built to its paths before the first frame, then kept
      const MsCacheSettings& mc = scene.renderer.raymarch.msCache;
      msCache.refine(rt, dev, params, mc.paths, mc.pathsPerLaunch, scene.sourcePath);
      kernel.setArg(arg + 3, msCache.buffer());
    }
    const auto tf = std::chrono::steady_clock::now();
    const cl::Event ev =
        launchAndWait(rt, kernel, global, local, algorithm, deviceBytes + lightCache.bytes() + msCache.bytes());
    wallMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tf).count());
    kernelMs.push_back(eventSeconds(ev) * 1e3);
    if (options.progress) options.progress(f + 1, requested);
  }
  st.interrupted = int(kernelMs.size()) < requested;
  if (kernelMs.empty()) {
    st.spp = 0;
    return result;
  }
  std::vector<float> rgba(pixels * 4);
  rt.queue.enqueueReadBuffer(outBuf, CL_TRUE, 0, rgba.size() * sizeof(float), rgba.data());
  rt.queue.enqueueReadBuffer(statusBuf, CL_TRUE, 0, sizeof(cl_uint), &st.status);
  st.passes = int(kernelMs.size());
  st.status |= lightCache.status();
  st.lightCacheMs = lightCache.buildMs();
  st.lightCacheBuilds = lightCache.slabsBuilt();
  st.lightCacheBytes = lightCache.bytes();
  nodeGridCells(params.light_cache, st.lightCacheCells);
  st.status |= msCache.status();
  st.msCacheMs = msCache.buildMs();
  st.msCachePaths = msCache.paths();
  st.msCacheBuilds = msCache.rebuilds();
  nodeGridCells(params.ms_cache, st.msCacheCells);
  st.frames = frameTimings(kernelMs, wallMs);
  for (double ms : kernelMs) st.kernelSeconds += ms * 1e-3;
  for (double ms : wallMs) st.seconds += ms * 1e-3;
  st.samplesPerSecond = st.seconds > 0 ? double(pixels) * st.passes / st.seconds : 0.0;
  result.image = imageFromRgba(rgba, W, H, 1.0f, &st.nanPixels);
  return result;
}

}  // namespace narval
