// device_grid.h: a density grid as a 3D image on the device (CL_R, CL_FLOAT: PoCL 3.1 misreads
// single-channel half images, DESIGN.md), after checking it fits the device's limits.
#pragma once

#include "cl/cl_runtime.h"
#include "volume/grid.h"

namespace narval {

// Throws InputError naming the grid's file and the limit it exceeds.
cl::Image3D uploadGrid(ClRuntime& rt, const DenseGrid& grid);

}  // namespace narval
