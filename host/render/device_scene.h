// device_scene.h: a scene resident on one device: the scene and light buffers and the density
// grid, bound as the first three arguments every narval kernel takes (scene, lights, grid).
#pragma once

#include "cl/cl_runtime.h"
#include "render/scene_upload.h"

namespace narval {

struct DeviceSceneBuffers {
  DeviceScene scene;
  cl::Buffer sceneBuf, lightBuf;
  cl::Image3D gridImage;  // empty for a homogeneous medium or none

  DeviceSceneBuffers(ClRuntime& rt, const Scene& s, const DenseGrid* grid);
  // Sets kernel arguments 0 (scene), 1 (lights) and 2 (grid image, or an unused int).
  void bind(cl::Kernel& kernel) const;
};

}  // namespace narval
