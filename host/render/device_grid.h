// device_grid.h: a density grid on the device, in the storage kernels/shared/grid.h reads: a 3D
// image (CL_R, CL_FLOAT: PoCL 3.1 misreads single-channel half images, DESIGN.md) for the
// hardware sampler, a float buffer (GRID_BUFFER_HEADER, then the voxels) filtered by hand
// (-DGRID_STORAGE_BUFFER), or sparse bricks in one buffer (-DGRID_STORAGE_BRICKS,
// volume/brick_grid.h) for grids that fit neither. Each checks the device's limits first and fails
// with an error naming the grid's file and the limit.
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "scene/scene.h"
#include "volume/brick_grid.h"
#include "volume/dense_grid.h"

namespace narval {

// The storage `requested` (renderer.storage) comes to on `device`, from the device alone. Auto:
// the buffer on CPU devices (hand-written trilinear filtering outpaces PoCL's image sampler,
// DESIGN.md platform facts) and on devices without image support; the image elsewhere (GPUs filter
// in hardware); timings in bench/RESULTS.md. Image, Buffer and Bricks are returned as they are.
// chooseGridStorage refines Auto for a grid.
GridStorage resolveGridStorage(GridStorage requested, const DeviceInfo& device);

// The storage a render of `grid` (null: no grid) uses on `device`: resolveGridStorage, except that
// Auto falls back to Bricks when its choice cannot hold the grid (an image over the device's 3D
// image size or largest allocation, or without image support; a buffer over the largest
// allocation or with an x-y slice over 2^31 - 1 voxels). Then `*why` (when given) says so in one
// line, for a warning; otherwise it is left empty. A storage asked for by name is never changed:
// a grid it cannot hold is an error at upload that names the storage that can.
GridStorage chooseGridStorage(GridStorage requested, const DeviceInfo& device, const DenseGrid* grid,
                              std::string* why = nullptr);

// Whether one image or one buffer on `device` holds `grid`; when not, `*why` says which limit it
// exceeds ("grid 2049x1x1 exceeds the device's 3D image limit 2048x2048x2048").
bool gridFitsImage(const DeviceInfo& device, const DenseGrid& grid, std::string* why = nullptr);
bool gridFitsBuffer(const DeviceInfo& device, const DenseGrid& grid, std::string* why = nullptr);


// A 3D image. Throws InputError naming the grid's file when the device has no image support or
// the grid exceeds its 3D image size or largest allocation; the message names renderer.storage
// "buffer" when one buffer would hold the grid, else "bricks".
cl::Image3D uploadGridImage(ClRuntime& rt, const DenseGrid& grid);

// A read-only buffer: GRID_BUFFER_HEADER ints (nx, ny, nz, 0), then the voxels. Throws InputError
// naming the bytes asked for and the device's CL_DEVICE_MAX_MEM_ALLOC_SIZE when they exceed it; a
// driver refusal is a DeviceFault (host/cl/device_allocation.h).
cl::Buffer uploadGridBuffer(ClRuntime& rt, const DenseGrid& grid);

// Bytes of the buffer storage of a grid (header included).
size_t gridBufferBytes(const DenseGrid& grid);

// The bricks of `grid` (planned by planBricks(grid)) in one read-only buffer: header, index table,
// pool (kernels/shared/grid.h). Written in chunks of about 64 MiB, so the host holds no second copy
// of the pool. Throws InputError naming the bytes asked for, the grid's dense size and the device's
// CL_DEVICE_MAX_MEM_ALLOC_SIZE when even the occupied bricks exceed it; a driver refusal is a
// DeviceFault (host/cl/device_allocation.h).
cl::Buffer uploadGridBricks(ClRuntime& rt, const DenseGrid& grid, const BrickLayout& layout);

}  // namespace narval
