// device_scene.h: a scene resident on one device: the scene and light buffers, the density grid
// and its majorant cells, bound as the first four arguments every narval kernel takes (scene,
// lights, then GRID_KERNEL_PARAM: grid, majorant cells).
#pragma once

#include "cl/cl_runtime.h"
#include "render/scene_upload.h"

namespace narval {

struct DeviceSceneBuffers {
  DeviceScene scene;
  cl::Buffer sceneBuf, lightBuf, majorantBuf;
  cl::Image3D gridImage;  // empty for a homogeneous medium or none

  DeviceSceneBuffers(ClRuntime& rt, const Scene& s, const DenseGrid* grid);
  // Sets kernel arguments 0 (scene), 1 (lights), 2 (grid image, or an unused int) and 3 (majorant
  // cells); kernel-specific arguments start at kFirstFreeArg.
  void bind(cl::Kernel& kernel) const;
  static constexpr cl_uint kFirstFreeArg = 4;
};

}  // namespace narval
