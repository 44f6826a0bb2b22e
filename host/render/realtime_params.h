// realtime_params.h: the real-time kernels' parameter blocks (kernels/shared/structs.h), each built
// from its own settings and bound to the kernels by argument name: the marches' (march_params, from
// renderer.raymarch or renderer.lobe), the lobe's (lobe_params), the light-transmittance cache's
// node grid (renderer.lightCache) and the multiple-scattering cache's (ms_cache_params).
#pragma once

#include <cstddef>
#include <cstdint>

#include "render/device_scene.h"
#include "scene/scene.h"
#include "shared/structs.h"

namespace narval {

struct RealtimeParams {
  march_params march{};
  lobe_params lobe{};
  node_grid_params lightCache{};  // nx = 0: off
  ms_cache_params msCache{};      // grid.nx = 0: off
};

// The blocks for the scene's algorithm; the caches' layouts need the scene as uploaded.
// maxAllocBytes: the device's largest allocation, which an automatic cache resolution must fit.
// cachePixels: the image size the automatic caches are weighed against (lightCacheLayout, msCacheTile);
// 0 takes the scene's own resolution. gpu: the device is a GPU.
RealtimeParams realtimeParams(const Scene& scene, const DeviceScene& ds, size_t maxAllocBytes = SIZE_MAX,
                              double cachePixels = 0, bool gpu = false);

// msCache.tile, "auto" resolved: a column a pixel on a GPU; on a CPU the smallest tile that leaves the
// image of `pixels` at most the quality's columns (a build of minutes, not hours, on a few cores).
int msCacheTile(const RaymarchSettings& raymarch, double pixels, bool gpu);

}  // namespace narval
