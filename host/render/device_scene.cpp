#include "render/device_scene.h"

#include <algorithm>
#include <cstdio>

#include "render/device_allocation.h"
#include "render/device_grid.h"
#include "render/kernel_features.h"

namespace narval {

DeviceSceneBuffers::DeviceSceneBuffers(ClRuntime& rt, const Scene& s, const DenseGrid* grid)
    : scene(buildDeviceScene(s, grid)) {
  std::string fallback;
  storage = chooseGridStorage(s.renderer.storage, rt.selected.info, scene.grid, &fallback);
  sceneBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(scene_params), &scene.params);
  lightBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                        sizeof(light_params) * scene.lights.size(), scene.lights.data());
  majorantBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                           sizeof(float) * scene.majorants.size(), scene.majorants.data());
  if (!scene.grid) return;
  if (storage == GridStorage::Buffer) {
    gridBuffer = uploadGridBuffer(rt, *scene.grid);
    scene.gridBytes = gridBufferBytes(*scene.grid);
  } else if (storage == GridStorage::Bricks) {
    const BrickLayout layout = planBricks(*scene.grid);
    gridBuffer = uploadGridBricks(rt, *scene.grid, layout);
    scene.gridBytes = layout.bufferBytes();
    bricks = layout.brickCount();
    bricksOccupied = layout.occupiedCount();
    if (!fallback.empty()) {
      char share[32];
      std::snprintf(share, sizeof share, "%.1f%%", 100.0 * double(bricksOccupied) / double(std::max<size_t>(1, bricks)));
      scene.warnings.push_back(fallback + ": " + std::to_string(bricksOccupied) + " of " + std::to_string(bricks) +
                               " bricks occupied (" + share + "), " + byteCount(scene.gridBytes));
    }
  } else {
    gridImage = uploadGridImage(rt, *scene.grid);
    scene.gridBytes = scene.grid->voxelCount() * sizeof(float);
  }
}

std::string DeviceSceneBuffers::buildOptions(const std::string& majorant, bool counters) const {
  return kernelBuildOptions(scene, KernelBuild{storage, majorant, counters});
}

void DeviceSceneBuffers::bind(NamedKernel& kernel) const {
  kernel.set("scene", sceneBuf);
  kernel.set("lights", lightBuf);
  if (!scene.grid)
    kernel.set("grid", cl_int(0));
  else if (storage == GridStorage::Buffer || storage == GridStorage::Bricks)
    kernel.set("grid", gridBuffer);
  else
    kernel.set("grid", gridImage);
  kernel.set("grid_majorants", majorantBuf);
}

}  // namespace narval
