#include "render/device_grid.h"

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <sstream>
#include <vector>

#include "cl/device_allocation.h"
#include "core/input_error.h"
#include "shared/grid.h"

namespace narval {
namespace {

std::string dimsText(const DenseGrid& grid) {
  std::ostringstream dims;
  dims << grid.nx << "x" << grid.ny << "x" << grid.nz;
  return dims.str();
}

const char* const kBricksAdvice = "; renderer.storage \"bricks\" (--storage bricks) stores only its non-empty 8^3 bricks";

// What to add to an image error: the storage that holds the grid.
std::string imageAdvice(const DeviceInfo& d, const DenseGrid& grid) {
  if (gridFitsBuffer(d, grid)) return "; renderer.storage \"buffer\" (--storage buffer) holds it in one buffer";
  return kBricksAdvice;
}

}  // namespace

GridStorage resolveGridStorage(GridStorage requested, const DeviceInfo& device) {
  if (requested != GridStorage::Auto) return requested;
  return device.type == "CPU" || !device.imageSupport ? GridStorage::Buffer : GridStorage::Image;
}

bool gridFitsImage(const DeviceInfo& d, const DenseGrid& grid, std::string* why) {
  std::ostringstream msg;
  if (!d.imageSupport) {
    msg << "device '" << d.name << "' has no image support";
  } else if (size_t(grid.nx) > d.image3dMax[0] || size_t(grid.ny) > d.image3dMax[1] ||
             size_t(grid.nz) > d.image3dMax[2]) {
    msg << "grid " << dimsText(grid) << " exceeds the device's 3D image limit " << d.image3dMax[0] << "x"
        << d.image3dMax[1] << "x" << d.image3dMax[2];
  } else if (grid.voxelCount() * sizeof(float) > d.maxAllocBytes) {
    msg << "grid " << dimsText(grid) << " needs " << grid.voxelCount() * sizeof(float)
        << " bytes, over the device's largest allocation of " << d.maxAllocBytes << " bytes";
  } else {
    return true;
  }
  if (why) *why = msg.str();
  return false;
}

bool gridFitsBuffer(const DeviceInfo& d, const DenseGrid& grid, std::string* why) {
  const size_t bytes = gridBufferBytes(grid);
  std::string reason;
  if (bytes > d.maxAllocBytes)
    reason = "grid " + dimsText(grid) + " as a float buffer needs " + byteCount(bytes) + ", over device '" + d.name +
             "''s largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE) of " + byteCount(d.maxAllocBytes);
  else if (size_t(grid.nx) * size_t(grid.ny) > size_t(INT_MAX))  // grid_trilinear's int slice stride
    reason = "grid " + dimsText(grid) + ": an x-y slice over 2^31 - 1 voxels does not fit the buffer storage";
  else
    return true;
  if (why) *why = reason;
  return false;
}

GridStorage chooseGridStorage(GridStorage requested, const DeviceInfo& device, const DenseGrid* grid,
                              std::string* why) {
  const GridStorage s = resolveGridStorage(requested, device);
  if (requested != GridStorage::Auto || !grid) return s;
  std::string reason;
  const bool fits = s == GridStorage::Image ? gridFitsImage(device, *grid, &reason)
                                            : gridFitsBuffer(device, *grid, &reason);
  if (fits) return s;
  if (why)
    *why = grid->source + ": " + reason + ": renderer.storage \"auto\" stores it as sparse 8^3 bricks (\"bricks\") instead of " +
           (s == GridStorage::Image ? "a 3D image" : "one buffer");
  return GridStorage::Bricks;
}

size_t gridBufferBytes(const DenseGrid& grid) { return (GRID_BUFFER_HEADER + grid.voxelCount()) * sizeof(float); }

cl::Image3D uploadGridImage(ClRuntime& rt, const DenseGrid& grid) {
  const DeviceInfo& d = rt.selected.info;
  std::string why;
  if (!gridFitsImage(d, grid, &why)) throw inputError(grid.source, "grid", why + imageAdvice(d, grid));
  return cl::Image3D(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, cl::ImageFormat(CL_R, CL_FLOAT),
                     size_t(grid.nx), size_t(grid.ny), size_t(grid.nz), 0, 0,
                     const_cast<float*>(grid.data.data()));
}

cl::Buffer uploadGridBuffer(ClRuntime& rt, const DenseGrid& grid) {
  const DeviceInfo& d = rt.selected.info;
  std::string why;
  if (!gridFitsBuffer(d, grid, &why)) throw inputError(grid.source, "grid", why + kBricksAdvice);
  if (grid.nx < 1 || grid.ny < 1 || grid.nz < 1 || grid.data.size() != grid.voxelCount())
    throw std::invalid_argument("uploadGridBuffer: grid dimensions do not match its data");
  const AllocationSite site{grid.source, "grid", "grid " + dimsText(grid) + " as a float buffer"};
  cl::Buffer buf = allocateBuffer(rt, CL_MEM_READ_ONLY, gridBufferBytes(grid), site);
  const cl_int header[GRID_BUFFER_HEADER] = {grid.nx, grid.ny, grid.nz, 0};
  rt.queue.enqueueWriteBuffer(buf, CL_TRUE, 0, sizeof(header), header);
  rt.queue.enqueueWriteBuffer(buf, CL_TRUE, sizeof(header), grid.voxelCount() * sizeof(float), grid.data.data());
  return buf;
}

cl::Buffer uploadGridBricks(ClRuntime& rt, const DenseGrid& grid, const BrickLayout& layout) {
  if (grid.nx != layout.nx || grid.ny != layout.ny || grid.nz != layout.nz)
    throw std::invalid_argument("uploadGridBricks: the layout is not the grid's");
  const size_t bytes = layout.bufferBytes();
  std::ostringstream what;
  what << "grid " << dimsText(grid) << " as sparse bricks (" << layout.occupiedCount() << " of "
       << layout.brickCount() << " 8^3 bricks occupied; dense " << byteCount(grid.voxelCount() * sizeof(float)) << ")";
  cl::Buffer buf = allocateBuffer(rt, CL_MEM_READ_ONLY, bytes, {grid.source, "grid", what.str()});
  std::vector<float> staging(layout.poolOffsetFloats());
  writeBrickHeader(layout, staging.data());
  rt.queue.enqueueWriteBuffer(buf, CL_TRUE, 0, staging.size() * sizeof(float), staging.data());
  // The pool in chunks of about 64 MiB (at least one brick).
  const size_t chunk = std::max<size_t>(1, (size_t(64) << 20) / (kBrickFloats * sizeof(float)));
  staging.assign(std::min(chunk, layout.occupiedCount()) * kBrickFloats, 0.0f);
  for (size_t first = 0; first < layout.occupiedCount(); first += chunk) {
    const size_t n = std::min(chunk, layout.occupiedCount() - first);
    writeBricks(grid, layout, first, n, staging.data());
    rt.queue.enqueueWriteBuffer(buf, CL_TRUE, (layout.poolOffsetFloats() + first * kBrickFloats) * sizeof(float),
                                n * kBrickFloats * sizeof(float), staging.data());
  }
  return buf;
}

}  // namespace narval
