// device_grid.h: a density grid on the device, in the storage kernels/shared/grid.h reads: a 3D
// image (CL_R, CL_FLOAT: PoCL 3.1 misreads single-channel half images, DESIGN.md) for the
// hardware sampler, or a float buffer (GRID_BUFFER_HEADER, then the voxels) filtered by hand
// (-DGRID_STORAGE_BUFFER). Both check the device's limits first and fail with an error naming the
// grid's file and the limit.
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "scene/scene.h"
#include "volume/grid.h"

namespace narval {

// The storage `requested` (renderer.storage) comes to on `device`. Auto: the buffer on CPU
// devices (hand-written trilinear filtering does 3-4x the lookups per second of PoCL's image
// sampler, DESIGN.md platform facts; whole renders 1.3-1.7x) and on devices without image support;
// the image elsewhere (GPUs filter in hardware: 1.1-1.5x faster renders on an H100). It depends on the device alone, never on the grid: a grid the chosen storage cannot
// hold is an error that says which storage can (uploadGridImage), so a render never changes
// storage, and speed, behind the user's back. Image and Buffer are returned as they are.
GridStorage resolveGridStorage(GridStorage requested, const DeviceInfo& device);

// The -D option that builds a kernel for `storage` ("" for the image, the default in grid.h).
// `storage` must be resolved (not Auto).
std::string gridStorageBuildOption(GridStorage storage);

// A 3D image. Throws InputError naming the grid's file when the device has no image support or
// the grid exceeds its 3D image size or largest allocation; the message names renderer.storage
// "buffer" when one buffer would hold the grid.
cl::Image3D uploadGridImage(ClRuntime& rt, const DenseGrid& grid);
// The image storage's historical name.
inline cl::Image3D uploadGrid(ClRuntime& rt, const DenseGrid& grid) { return uploadGridImage(rt, grid); }

// A read-only buffer: GRID_BUFFER_HEADER ints (nx, ny, nz, 0), then the voxels. Throws InputError
// naming the bytes asked for and the device's CL_DEVICE_MAX_MEM_ALLOC_SIZE when they exceed it; a
// driver refusal is a DeviceFault (render/device_allocation.h).
cl::Buffer uploadGridBuffer(ClRuntime& rt, const DenseGrid& grid);

// Bytes of the buffer storage of a grid (header included).
size_t gridBufferBytes(const DenseGrid& grid);

}  // namespace narval
