#include "render/realtime_params.h"

#include <algorithm>
#include <stdexcept>

#include "render/device_light_cache.h"
#include "render/node_grid_layout.h"

namespace narval {
namespace {

int areaLightPhase(AreaLightPhase a) {
  switch (a) {
    case AreaLightPhase::Points: return AREA_LIGHT_POINTS;
    case AreaLightPhase::Exact: return AREA_LIGHT_EXACT;
  }
  throw std::logic_error("areaLightPhase: not an AreaLightPhase");
}

// What both algorithms' marches take; the ray marcher adds its shadow weighting and octaves.
march_params marchParams(int steps, int shadowSteps, float minTransmittance, int areaLightSamples,
                         AreaLightPhase phase, int shadowAreaSamples) {
  march_params p{};
  p.steps = steps;
  p.shadow_steps = shadowSteps;
  p.min_transmittance = minTransmittance;
  p.area_light_samples = areaLightSamples;
  p.shadow_area_samples = shadowAreaSamples;
  p.area_light_phase = areaLightPhase(phase);
  p.shadow_weighting = SHADOW_WEIGHTING_AREA;
  p.octaves = 1;
  return p;
}

march_params raymarchMarch(const RaymarchSettings& r) {
  march_params p = marchParams(r.steps, r.shadowSteps, r.minTransmittance, r.areaLightSamples, r.areaLightPhase,
                               r.shadowAreaSamples);
  if (r.shadowWeighting == ShadowWeighting::Phase) p.shadow_weighting = SHADOW_WEIGHTING_PHASE;
  if (r.multipleScattering == MultipleScattering::Octaves) p.octaves = r.octaves;
  p.octave_a = r.octaveScattering;
  p.octave_b = r.octaveExtinction;
  p.octave_c = r.octavePhase;
  return p;
}

march_params lobeMarch(const LobeSettings& l) {
  return marchParams(l.firstHitSteps, l.shadowSteps, l.minTransmittance, l.areaLightSamples, l.areaLightPhase,
                     lobeShadowAreaSamples(l));
}

lobe_params lobeParams(const LobeSettings& l) {
  lobe_params p{};
  p.depth_factor = l.depthFactor;
  p.radius = l.lobeRadius;
  p.points = l.lobePoints;
  p.view_steps = lobeViewSteps(l);
  p.variant = l.variant == LobeVariant::Corrected ? LOBE_CORRECTED : LOBE_EQ7;
  return p;
}

// The view layout aims its paths at the camera (closure camera) and filters its columns.
ms_cache_params msCacheParams(const MsCacheSettings& mc, int tile, bool on, const DeviceScene& ds) {
  ms_cache_params p{};
  p.tile = tile;
  switch (mc.layout) {
    case MsCacheLayout::Grid:
      p.layout = MS_CACHE_LAYOUT_GRID;
      if (on) p.grid = nodeGridLayout(ds, mc.resolution);
      break;
    case MsCacheLayout::View:  // columns over the image, slices along them (ms_cache_view.h)
      p.layout = MS_CACHE_LAYOUT_VIEW;
      if (on && ds.params.has_medium) {
        p.grid.nx = (ds.params.camera.width + tile - 1) / tile;
        p.grid.ny = (ds.params.camera.height + tile - 1) / tile;
        p.grid.nz = mc.slices;
      }
      p.filter = mc.filter;
      p.filter_twicing = mc.filter > 0 && mc.filterTwicing;
      break;
  }
  switch (mc.closure) {
    case MsCacheClosure::Linear: p.closure = MS_CACHE_CLOSURE_LINEAR; break;
    case MsCacheClosure::Camera: p.closure = MS_CACHE_CLOSURE_CAMERA; break;
  }
  if (mc.layout == MsCacheLayout::View) p.closure = MS_CACHE_CLOSURE_CAMERA;
  // Only a node aimed at the camera can hold the direct light (the loader refuses it elsewhere; a scene
  // built in code keeps MsCacheSettings' default there).
  p.direct = on && mc.direct && p.closure == MS_CACHE_CLOSURE_CAMERA;
  return p;
}

}  // namespace

int msCacheTile(const RaymarchSettings& raymarch, double pixels, bool gpu) {
  if (raymarch.msCache.tile != kMsCacheTileAuto) return raymarch.msCache.tile;
  if (gpu) return 1;
  const double columns = raymarchQualityDefaults(raymarch.quality).cpuColumns;
  int tile = 1;
  while (pixels / (double(tile) * tile) > columns) ++tile;
  return tile;
}

RealtimeParams realtimeParams(const Scene& scene, const DeviceScene& ds, size_t maxAllocBytes, double cachePixels,
                              bool gpu) {
  const RendererSettings& r = scene.renderer;
  const double pixels = cachePixels > 0 ? cachePixels : double(r.width) * double(r.height);
  RealtimeParams p;
  switch (r.algorithm) {
    case Algorithm::Raymarch:
      p.march = raymarchMarch(r.raymarch);
      p.msCache = msCacheParams(r.raymarch.msCache, msCacheTile(r.raymarch, pixels, gpu),
                                r.raymarch.multipleScattering == MultipleScattering::Cache, ds);
      break;
    case Algorithm::Lobe:
      p.march = lobeMarch(r.lobe);
      p.lobe = lobeParams(r.lobe);
      break;
    case Algorithm::Pathtrace: throw std::logic_error("realtimeParams: the path tracer has none");
  }
  // No light loop when the multiple-scattering cache holds the direct light: no shadow rays to cache.
  // A pixel reads a shadow per light at each view step (the ray marcher) or lobe point (the lobe).
  const double raysPerPixel = std::max(1, r.algorithm == Algorithm::Lobe ? p.lobe.points : p.march.steps);
  if (!p.msCache.direct)
    p.lightCache = lightCacheLayout(ds, r.lightCache.resolution, pixels * raysPerPixel, maxAllocBytes);
  return p;
}

}  // namespace narval
