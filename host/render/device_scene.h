// device_scene.h: a scene resident on one device: the scene and light buffers, the density grid
// and its majorant cells, the emission grid and the blackbody table, bound as the first six
// arguments every narval kernel takes (kernel_context.h's KERNEL_SCENE_ARGS: scene, lights, grid,
// majorant cells, emission grid, blackbody table).
#pragma once

#include "cl/cl_runtime.h"
#include "cl/kernel_args.h"
#include "render/scene_upload.h"

namespace narval {

struct DeviceSceneBuffers {
  DeviceScene scene;
  // renderer.storage resolved for the device and the grid (chooseGridStorage: auto falls back to
  // bricks, with a warning in scene.warnings, when its choice cannot hold the grid): what the
  // kernels are built for and the grids are uploaded as. Without a grid neither is used
  // (MEDIUM_HOMOGENEOUS); it is then the device's choice (resolveGridStorage).
  GridStorage storage = GridStorage::Image;
  cl::Buffer sceneBuf, lightBuf, majorantBuf;
  cl::Buffer emissionTableBuf;  // DeviceScene::emissionTable
  // One grid in `storage`: the image, or the buffer (buffer and bricks storage).
  struct StoredGrid {
    cl::Image3D image;
    cl::Buffer buffer;
    size_t bytes = 0, bricks = 0, bricksOccupied = 0;
    void bind(NamedKernel& kernel, const std::string& arg, GridStorage storage) const;
  };
  StoredGrid density;   // scene.grid; empty without one
  StoredGrid emission;  // scene.emissionGrid when it is not the density grid; empty otherwise
  // With bricks storage: how many bricks the density grid has and how many hold density (the pool).
  size_t bricks = 0, bricksOccupied = 0;

  DeviceSceneBuffers(ClRuntime& rt, const Scene& s, SceneGrids grids);
  // Sets the arguments every narval kernel starts with: scene, lights, grid (image or buffer, or an
  // unused int), grid_majorants, emission_grid (likewise) and emission_table (cl/kernel_args.h).
  void bind(NamedKernel& kernel) const;
  // The -D options of a kernel on this scene and storage (kernelBuildOptions; the path tracer adds
  // its majorant and counters).
  std::string buildOptions(const std::string& majorant = "", bool counters = false) const;

 private:
  StoredGrid upload(ClRuntime& rt, const DenseGrid& grid) const;
};

}  // namespace narval
