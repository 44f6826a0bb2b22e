// realtime_renderer.h: drives the real-time kernels (kernels/raymarch.cl, kernels/lobe.cl), which
// share one signature: (scene, lights, grid, realtime_params, lobe directions, RGBA out, status).
// A frame is one launch that writes the whole image; `frames` launches are timed one by one.
#pragma once

#include "cl/cl_runtime.h"
#include "render/render_types.h"
#include "scene/scene.h"
#include "shared/structs.h"
#include "volume/grid.h"

namespace narval {

// The kernel parameters from the scene's renderer.raymarch / renderer.lobe settings.
realtime_params realtimeParams(const Scene& scene);

// Renders scene.renderer.algorithm ("raymarch" or "lobe") `frames` times (>= 1); the image is the
// last frame (every frame is the same: the kernels are deterministic).
RenderResult renderRealtime(ClRuntime& rt, const Scene& scene, const DenseGrid* grid, int frames,
                            const RenderOptions& options = {});

}  // namespace narval
