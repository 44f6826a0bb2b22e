// node_grid.h: the host side of kernels/shared/node_grid.h, the node layout of the real-time caches.
#pragma once

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

}  // namespace narval
