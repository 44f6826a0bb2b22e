// majorant_options.h: RenderOptions' majorant choices (majorant, majorantResolution, counters)
// applied to a scene on the device: the majorant grid's resolution, re-uploaded when it changes, and
// the path tracer's -D options (kernels/shared/tracking.h: -DMAJORANT_GLOBAL, -DCOUNTERS).
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "render/device_scene.h"
#include "render/render_types.h"

namespace narval {

// Throws std::invalid_argument for a majorant other than "grid" or "global" or a negative resolution.
void checkMajorantOptions(const RenderOptions& options);

// Rebuilds dev's majorant grid at options.majorantResolution (0: keeps the automatic one) and, if
// it changed, replaces the scene and majorant-cell buffers on the device. Fills stats.majorantCells.
void applyMajorantResolution(ClRuntime& rt, DeviceSceneBuffers& dev, const RenderOptions& options,
                             RenderStats& stats);

// The path tracer's extra build options: "-DMAJORANT_GLOBAL" for the global majorant, "-DCOUNTERS"
// with counters, space-separated ("" for the default grid without counters).
std::string pathtraceMajorantBuildOptions(const RenderOptions& options);

// `base` and `extra` joined by a space (either may be empty).
std::string joinBuildOptions(const std::string& base, const std::string& extra);

}  // namespace narval
