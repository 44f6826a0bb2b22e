#include "render/device_scene.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "cl/device_allocation.h"
#include "render/device_grid.h"
#include "render/kernel_features.h"

namespace narval {

DeviceSceneBuffers::DeviceSceneBuffers(ClRuntime& rt, const Scene& s, SceneGrids grids)
    : scene(buildDeviceScene(s, grids)) {
  std::string fallback;
  storage = chooseGridStorage(s.renderer.storage, rt.selected.info, scene.grid, &fallback);
  sceneBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(scene_params), &scene.params);
  lightBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                        sizeof(light_params) * scene.lights.size(), scene.lights.data());
  majorantBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                           sizeof(float) * scene.majorants.size(), scene.majorants.data());
  emissionTableBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                sizeof(float) * scene.emissionTable.size(), scene.emissionTable.data());
  if (!scene.grid) return;
  density = upload(rt, *scene.grid);
  scene.gridBytes = density.bytes;
  bricks = density.bricks;
  bricksOccupied = density.bricksOccupied;
  if (storage == GridStorage::Bricks && !fallback.empty()) {
    char share[32];
    std::snprintf(share, sizeof share, "%.1f%%", 100.0 * double(bricksOccupied) / double(std::max<size_t>(1, bricks)));
    scene.warnings.push_back(fallback + ": " + std::to_string(bricksOccupied) + " of " + std::to_string(bricks) +
                             " bricks occupied (" + share + "), " + byteCount(scene.gridBytes));
  }
  // The emission grid in the same storage (the kernels read both through one GRID_STORAGE type),
  // uploaded once: a material that emits from its density grid shares the density's upload.
  if (scene.emissionGrid && scene.emissionGrid != scene.grid) {
    emission = upload(rt, *scene.emissionGrid);
    scene.gridBytes += emission.bytes;
  }
}

DeviceSceneBuffers::StoredGrid DeviceSceneBuffers::upload(ClRuntime& rt, const DenseGrid& grid) const {
  StoredGrid g;
  switch (storage) {
    case GridStorage::Buffer:
      g.buffer = uploadGridBuffer(rt, grid);
      g.bytes = gridBufferBytes(grid);
      return g;
    case GridStorage::Bricks: {
      const BrickLayout layout = planBricks(grid);
      g.buffer = uploadGridBricks(rt, grid, layout);
      g.bytes = layout.bufferBytes();
      g.bricks = layout.brickCount();
      g.bricksOccupied = layout.occupiedCount();
      return g;
    }
    case GridStorage::Image:
      g.image = uploadGridImage(rt, grid);
      g.bytes = grid.voxelCount() * sizeof(float);
      return g;
    case GridStorage::Auto: break;
  }
  throw std::logic_error("DeviceSceneBuffers: the grid storage must be resolved (not auto)");
}

void DeviceSceneBuffers::StoredGrid::bind(NamedKernel& kernel, const std::string& arg, GridStorage storage) const {
  switch (storage) {
    case GridStorage::Buffer:
    case GridStorage::Bricks: kernel.set(arg, buffer); return;
    case GridStorage::Image: kernel.set(arg, image); return;
    case GridStorage::Auto: break;
  }
  throw std::logic_error("DeviceSceneBuffers: the grid storage must be resolved (not auto)");
}

std::string DeviceSceneBuffers::buildOptions(const std::string& majorant, bool counters) const {
  return kernelBuildOptions(scene, KernelBuild{storage, majorant, counters});
}

void DeviceSceneBuffers::bind(NamedKernel& kernel) const {
  kernel.set("scene", sceneBuf);
  kernel.set("lights", lightBuf);
  kernel.set("grid_majorants", majorantBuf);
  kernel.set("emission_table", emissionTableBuf);
  if (!scene.grid) {  // MEDIUM_HOMOGENEOUS: both grids are unused ints
    kernel.set("grid", cl_int(0));
    kernel.set("emission_grid", cl_int(0));
    return;
  }
  density.bind(kernel, "grid", storage);
  // Without an emission grid of its own the argument is the density grid again: a kernel reads it
  // only where medium.emission names a grid.
  (scene.emissionGrid && scene.emissionGrid != scene.grid ? emission : density).bind(kernel, "emission_grid", storage);
}

}  // namespace narval
