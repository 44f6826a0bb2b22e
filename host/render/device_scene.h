// device_scene.h: a scene resident on one device: the scene and light buffers, the density grid
// and its majorant cells, bound as the first four arguments every narval kernel takes (scene,
// lights, then GRID_KERNEL_PARAM: grid, majorant cells).
#pragma once

#include "cl/cl_runtime.h"
#include "render/scene_upload.h"

namespace narval {

struct DeviceSceneBuffers {
  DeviceScene scene;  // buildOptions include the grid storage's -D option
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
  // Sets kernel arguments 0 (scene), 1 (lights), 2 (grid image or buffer, or an unused int) and
  // 3 (majorant cells); kernel-specific arguments start at kFirstFreeArg.
  void bind(cl::Kernel& kernel) const;
  static constexpr cl_uint kFirstFreeArg = 4;
};

}  // namespace narval
