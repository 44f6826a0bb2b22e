#include "render/device_grid.h"

#include <sstream>

#include "scene/input_error.h"

namespace narval {

cl::Image3D uploadGrid(ClRuntime& rt, const DenseGrid& grid) {
  const DeviceInfo& d = rt.selected.info;
  const size_t bytes = grid.voxelCount() * sizeof(float);
  std::ostringstream dims;
  dims << grid.nx << "x" << grid.ny << "x" << grid.nz;
  if (!d.imageSupport)
    throw inputError(grid.source, "grid", "device '" + d.name + "' has no image support");
  if (size_t(grid.nx) > d.image3dMax[0] || size_t(grid.ny) > d.image3dMax[1] || size_t(grid.nz) > d.image3dMax[2]) {
    std::ostringstream msg;
    msg << "grid " << dims.str() << " exceeds the device's 3D image limit " << d.image3dMax[0] << "x"
        << d.image3dMax[1] << "x" << d.image3dMax[2];
    throw inputError(grid.source, "grid", msg.str());
  }
  if (bytes > d.maxAllocBytes) {
    std::ostringstream msg;
    msg << "grid " << dims.str() << " needs " << bytes << " bytes, over the device's largest allocation of "
        << d.maxAllocBytes << " bytes";
    throw inputError(grid.source, "grid", msg.str());
  }
  return cl::Image3D(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, cl::ImageFormat(CL_R, CL_FLOAT),
                     size_t(grid.nx), size_t(grid.ny), size_t(grid.nz), 0, 0,
                     const_cast<float*>(grid.data.data()));
}

}  // namespace narval
