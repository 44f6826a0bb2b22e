// pathtrace_renderer.h: drives kernels/pathtrace.cl: upload, passes, compensated accumulation.
#pragma once

#include "cl/cl_runtime.h"
#include "render/render_types.h"
#include "scene/scene.h"
#include "volume/grid.h"

namespace narval {

// Samples per launch: about 2^20 paths, at least 1, at most spp. It depends only on the image size
// and spp, never on timings, so a render's pixels are the same on every run.
int pathtraceSamplesPerPass(int width, int height, int spp);

// Renders `scene` (already validated; `grid` is the volume's grid or null) on rt's device.
RenderResult renderPathtrace(ClRuntime& rt, const Scene& scene, const DenseGrid* grid,
                             const RenderOptions& options = {});

}  // namespace narval
