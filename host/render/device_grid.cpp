#include "render/device_grid.h"

#include <climits>
#include <stdexcept>
#include <sstream>

#include "render/device_allocation.h"
#include "scene/input_error.h"
#include "shared/grid.h"

namespace narval {
namespace {

std::string dimsText(const DenseGrid& grid) {
  std::ostringstream dims;
  dims << grid.nx << "x" << grid.ny << "x" << grid.nz;
  return dims.str();
}

// What to add to an image error when the buffer storage would hold the grid.
std::string bufferAdvice(const DeviceInfo& d, const DenseGrid& grid) {
  if (gridBufferBytes(grid) > d.maxAllocBytes) return "";
  return "; renderer.storage \"buffer\" (--storage buffer) holds it in one buffer";
}

}  // namespace

GridStorage resolveGridStorage(GridStorage requested, const DeviceInfo& device) {
  if (requested != GridStorage::Auto) return requested;
  return device.type == "CPU" || !device.imageSupport ? GridStorage::Buffer : GridStorage::Image;
}

std::string gridStorageBuildOption(GridStorage storage) {
  return storage == GridStorage::Buffer ? "-DGRID_STORAGE_BUFFER" : "";
}

size_t gridBufferBytes(const DenseGrid& grid) { return (GRID_BUFFER_HEADER + grid.voxelCount()) * sizeof(float); }

cl::Image3D uploadGridImage(ClRuntime& rt, const DenseGrid& grid) {
  const DeviceInfo& d = rt.selected.info;
  const size_t bytes = grid.voxelCount() * sizeof(float);
  if (!d.imageSupport)
    throw inputError(grid.source, "grid", "device '" + d.name + "' has no image support" + bufferAdvice(d, grid));
  if (size_t(grid.nx) > d.image3dMax[0] || size_t(grid.ny) > d.image3dMax[1] || size_t(grid.nz) > d.image3dMax[2]) {
    std::ostringstream msg;
    msg << "grid " << dimsText(grid) << " exceeds the device's 3D image limit " << d.image3dMax[0] << "x"
        << d.image3dMax[1] << "x" << d.image3dMax[2] << bufferAdvice(d, grid);
    throw inputError(grid.source, "grid", msg.str());
  }
  if (bytes > d.maxAllocBytes) {
    std::ostringstream msg;
    msg << "grid " << dimsText(grid) << " needs " << bytes << " bytes, over the device's largest allocation of "
        << d.maxAllocBytes << " bytes";
    throw inputError(grid.source, "grid", msg.str());
  }
  return cl::Image3D(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, cl::ImageFormat(CL_R, CL_FLOAT),
                     size_t(grid.nx), size_t(grid.ny), size_t(grid.nz), 0, 0,
                     const_cast<float*>(grid.data.data()));
}

cl::Buffer uploadGridBuffer(ClRuntime& rt, const DenseGrid& grid) {
  const DeviceInfo& d = rt.selected.info;
  const size_t bytes = gridBufferBytes(grid);
  if (bytes > d.maxAllocBytes)
    throw inputError(grid.source, "grid",
                     "grid " + dimsText(grid) + " as a float buffer needs " + byteCount(bytes) + ", over device '" +
                         d.name + "''s largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE) of " +
                         byteCount(d.maxAllocBytes));
  if (grid.nx < 1 || grid.ny < 1 || grid.nz < 1 || grid.data.size() != grid.voxelCount())
    throw std::invalid_argument("uploadGridBuffer: grid dimensions do not match its data");
  if (size_t(grid.nx) * size_t(grid.ny) > size_t(INT_MAX))  // grid_trilinear's int slice stride
    throw inputError(grid.source, "grid",
                     "grid " + dimsText(grid) + ": an x-y slice over 2^31 - 1 voxels does not fit the buffer storage");
  const AllocationSite site{grid.source, "grid", "grid " + dimsText(grid) + " as a float buffer"};
  cl::Buffer buf = allocateBuffer(rt, CL_MEM_READ_ONLY, bytes, site);
  const cl_int header[GRID_BUFFER_HEADER] = {grid.nx, grid.ny, grid.nz, 0};
  rt.queue.enqueueWriteBuffer(buf, CL_TRUE, 0, sizeof(header), header);
  rt.queue.enqueueWriteBuffer(buf, CL_TRUE, sizeof(header), grid.voxelCount() * sizeof(float), grid.data.data());
  return buf;
}

}  // namespace narval
