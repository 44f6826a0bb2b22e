// device_grid.h: a density grid on the device as kernels/shared/grid.h reads it: a 3D image (CL_R, CL_FLOAT:
// PoCL 3.1 misreads single-channel half images, DESIGN.md), a float buffer (GRID_BUFFER_HEADER, then voxels;
// -DGRID_STORAGE_BUFFER), or sparse bricks in one buffer (-DGRID_STORAGE_BRICKS, volume/brick_grid.h). Each
// checks the device's limits first, failing with an error naming the grid's file and the limit.
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "scene/scene.h"
#include "volume/brick_grid.h"
#include "volume/dense_grid.h"

namespace narval {

// What `requested` (renderer.storage) comes to on `device` alone: Auto is the buffer on CPU devices
// (hand-written trilinear beats PoCL's image sampler: DESIGN.md platform facts, bench/RESULTS.md) and
// without image support, else the image (GPUs filter in hardware); chooseGridStorage refines it for a grid.
GridStorage resolveGridStorage(GridStorage requested, const DeviceInfo& device);

// resolveGridStorage for a render of `grid` (null: none), but Auto falls back to Bricks when its choice
// cannot hold the grid (image: over the 3D image size or largest allocation, or no image support; buffer:
// over the largest allocation, or an x-y slice over 2^31 - 1 voxels), saying so in `*why` (if given; else
// left empty). An explicit storage never changes: if it cannot hold the grid, upload fails naming one that can.
GridStorage chooseGridStorage(GridStorage requested, const DeviceInfo& device, const DenseGrid* grid,
                              std::string* why = nullptr);

// Whether one image or one buffer on `device` holds `grid`; when not, `*why` says which limit it
// exceeds ("grid 2049x1x1 exceeds the device's 3D image limit 2048x2048x2048").
bool gridFitsImage(const DeviceInfo& device, const DenseGrid& grid, std::string* why = nullptr);
bool gridFitsBuffer(const DeviceInfo& device, const DenseGrid& grid, std::string* why = nullptr);


// A 3D image. InputError naming the grid's file without image support or over the 3D image size or largest
// allocation, suggesting renderer.storage "buffer" when one buffer would hold the grid, else "bricks".
cl::Image3D uploadGridImage(ClRuntime& rt, const DenseGrid& grid);

// A read-only buffer: GRID_BUFFER_HEADER ints (nx, ny, nz, 0), then the voxels. InputError naming the bytes
// and CL_DEVICE_MAX_MEM_ALLOC_SIZE when over it; a driver refusal is a DeviceFault (host/cl/device_allocation.h).
cl::Buffer uploadGridBuffer(ClRuntime& rt, const DenseGrid& grid);

// Bytes of the buffer storage of a grid (header included).
size_t gridBufferBytes(const DenseGrid& grid);

// The bricks of `grid` (planBricks(grid)) in one read-only buffer: header, index table, pool (grid.h),
// written in ~64 MiB chunks so the host holds no second pool. InputError naming the bytes, the dense size
// and CL_DEVICE_MAX_MEM_ALLOC_SIZE when even the occupied bricks exceed it; driver refusal: DeviceFault.
cl::Buffer uploadGridBricks(ClRuntime& rt, const DenseGrid& grid, const BrickLayout& layout);

}  // namespace narval
