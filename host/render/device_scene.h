// device_scene.h: a scene resident on one device: the scene and light buffers, the density grid
// and its majorant cells, bound as the first four arguments every narval kernel takes (scene,
// lights, then GRID_KERNEL_PARAM: grid, majorant cells).
#pragma once

#include "cl/cl_runtime.h"
#include "cl/kernel_args.h"
#include "render/scene_upload.h"

namespace narval {

struct DeviceSceneBuffers {
  DeviceScene scene;
  // renderer.storage resolved for the device and the grid (chooseGridStorage: auto falls back to
  // bricks, with a warning in scene.warnings, when its choice cannot hold the grid): what the
  // kernels are built for and the grid is uploaded as. Without a grid neither is used
  // (MEDIUM_HOMOGENEOUS); it is then the device's choice (resolveGridStorage).
  GridStorage storage = GridStorage::Image;
  cl::Buffer sceneBuf, lightBuf, majorantBuf;
  cl::Image3D gridImage;  // the grid with image storage; empty otherwise
  cl::Buffer gridBuffer;  // the grid with buffer or bricks storage; empty otherwise
  // With bricks storage: how many bricks the grid has and how many hold density (the pool).
  size_t bricks = 0, bricksOccupied = 0;

  DeviceSceneBuffers(ClRuntime& rt, const Scene& s, const DenseGrid* grid);
  // Sets the arguments every narval kernel starts with: scene, lights, grid (image or buffer, or an
  // unused int) and grid_majorants (cl/kernel_args.h).
  void bind(NamedKernel& kernel) const;
  // The -D options of a kernel on this scene and storage (kernelBuildOptions; the path tracer adds
  // its majorant and counters).
  std::string buildOptions(const std::string& majorant = "", bool counters = false) const;
};

}  // namespace narval
