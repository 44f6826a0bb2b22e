// majorant_options.h: RenderOptions' majorant choices (majorant, majorantResolution, counters)
// applied to a scene on the device: the majorant grid's resolution, re-uploaded when it changes, and
// the path tracer's -D options (kernels/shared/tracking.h: -DMAJORANT_GLOBAL, -DCOUNTERS).
//
// Defaults, by measurement (bench/majorant.py; numbers in bench/RESULTS.md):
// - majorant "auto": the grid on CPU devices (on PoCL faster than the global majorant on both
//   clouds), the global majorant on GPUs (on an H100 a DDA cell step costs about what a
//   hardware-filtered lookup saves: the grid at best no faster, slower with more cells).
// - the path tracer's automatic resolution: 32 cells along the longest axis on CPUs (best or tied on
//   both clouds), 16 elsewhere (where finer grids cost more); the real-time kernels keep
//   buildDeviceScene's kDefaultMajorantResolution (16).
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "render/device_scene.h"
#include "render/render_types.h"

namespace narval {

// Throws std::invalid_argument for a majorant other than "auto", "grid" or "global", or a negative
// resolution.
void checkMajorantOptions(const RenderOptions& options);

// "grid" or "global": `requested` ("auto", "grid", "global") for the device (see above).
std::string resolveMajorant(const std::string& requested, const DeviceInfo& device);

// The path tracer's automatic majorant resolution on the device (see above).
int pathtraceMajorantResolution(const DeviceInfo& device);

// Rebuilds dev's majorant grid at `target` cells along the longest axis (0: keeps the one
// buildDeviceScene made) and, if it changed, replaces the scene and majorant-cell buffers on the
// device. Fills stats.majorantCells.
void applyMajorantResolution(ClRuntime& rt, DeviceSceneBuffers& dev, int target, RenderStats& stats);

}  // namespace narval
