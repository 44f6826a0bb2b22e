// node_grid.h: the host side of kernels/shared/node_grid.h, the node layout of the real-time caches.
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "render/scene_upload.h"
#include "shared/structs.h"

namespace narval {

// `cells` cells along the longest world-space axis of the medium's box, the other axes in
// proportion (at least one cell each), nodes = cells + 1 per axis. nx = 0 (no grid) for cells <= 0
// or a scene without a medium.
node_grid_params nodeGridLayout(const DeviceScene& ds, int cells);

// Nodes of the layout (0 when off).
size_t nodeGridCount(const node_grid_params& c);

// Cells per axis (nodes − 1; 0 0 0 when off), as the stats report them.
void nodeGridCells(const node_grid_params& c, int cells[3]);

// One launch of a cache's build kernel over `nodes` work-items (1D, padded to a work-group of 64;
// the kernels return past the last node), waited for: launchAndWait's errors name `what` and the
// `deviceBytes` held. Returns the launch's milliseconds by its profiling event.
double launchOverNodes(ClRuntime& rt, const cl::Kernel& kernel, size_t nodes, const std::string& what,
                       size_t deviceBytes);

// The status word a build kernel ORed into `statusBuf` (one cl_uint).
uint32_t readStatusWord(ClRuntime& rt, const cl::Buffer& statusBuf);

}  // namespace narval
