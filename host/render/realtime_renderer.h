// realtime_renderer.h: drives the real-time kernels (kernels/raymarch.cl, kernels/lobe.cl), which
// share one signature: (scene, lights, grid, realtime_params, lobe directions, light cache, RGBA out,
// status). A frame is one launch that writes the whole image; `frames` launches are timed one by one.
// The light-transmittance cache (render/light_cache.h) is brought up to date before every frame,
// which rebuilds it only when what it was built from changed (counted in RenderStats).
#pragma once

#include <cstdint>

#include "cl/cl_runtime.h"
#include "render/render_types.h"
#include "render/scene_upload.h"
#include "scene/scene.h"
#include "shared/structs.h"
#include "volume/grid.h"

namespace narval {

// The kernel parameters from the scene's renderer.raymarch / renderer.lobe / renderer.lightCache
// settings; the light cache's layout (lightCacheLayout) needs the scene as uploaded.
// maxAllocBytes: the device's largest allocation, which an automatic cache resolution must fit.
realtime_params realtimeParams(const Scene& scene, const DeviceScene& ds, size_t maxAllocBytes = SIZE_MAX);

// Renders scene.renderer.algorithm ("raymarch" or "lobe") `frames` times (>= 1); the image is the
// last frame (every frame is the same: the kernels are deterministic).
RenderResult renderRealtime(ClRuntime& rt, const Scene& scene, const DenseGrid* grid, int frames,
                            const RenderOptions& options = {});

}  // namespace narval
