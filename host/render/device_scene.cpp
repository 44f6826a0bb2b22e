#include "render/device_scene.h"

#include "render/device_grid.h"

namespace narval {

DeviceSceneBuffers::DeviceSceneBuffers(ClRuntime& rt, const Scene& s, const DenseGrid* grid)
    : scene(buildDeviceScene(s, grid)) {
  sceneBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(scene_params), &scene.params);
  lightBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                        sizeof(light_params) * scene.lights.size(), scene.lights.data());
  majorantBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                           sizeof(float) * scene.majorants.size(), scene.majorants.data());
  if (scene.grid) gridImage = uploadGrid(rt, *scene.grid);
}

void DeviceSceneBuffers::bind(cl::Kernel& kernel) const {
  kernel.setArg(0, sceneBuf);
  kernel.setArg(1, lightBuf);
  if (scene.grid)
    kernel.setArg(2, gridImage);
  else
    kernel.setArg(2, cl_int(0));
  kernel.setArg(3, majorantBuf);
}

}  // namespace narval
