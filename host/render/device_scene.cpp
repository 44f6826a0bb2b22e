#include "render/device_scene.h"

#include "render/device_grid.h"

namespace narval {

DeviceSceneBuffers::DeviceSceneBuffers(ClRuntime& rt, const Scene& s, const DenseGrid* grid)
    : scene(buildDeviceScene(s, grid)), storage(resolveGridStorage(s.renderer.storage, rt.selected.info)) {
  sceneBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(scene_params), &scene.params);
  lightBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                        sizeof(light_params) * scene.lights.size(), scene.lights.data());
  majorantBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                           sizeof(float) * scene.majorants.size(), scene.majorants.data());
  if (!scene.grid) return;
  if (storage == GridStorage::Buffer)
    gridBuffer = uploadGridBuffer(rt, *scene.grid);
  else
    gridImage = uploadGridImage(rt, *scene.grid);
  const std::string option = gridStorageBuildOption(storage);
  if (!option.empty()) scene.buildOptions += (scene.buildOptions.empty() ? "" : " ") + option;
}

void DeviceSceneBuffers::bind(cl::Kernel& kernel) const {
  kernel.setArg(0, sceneBuf);
  kernel.setArg(1, lightBuf);
  if (!scene.grid)
    kernel.setArg(2, cl_int(0));
  else if (storage == GridStorage::Buffer)
    kernel.setArg(2, gridBuffer);
  else
    kernel.setArg(2, gridImage);
  kernel.setArg(3, majorantBuf);
}

}  // namespace narval
