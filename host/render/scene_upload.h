// scene_upload.h: turns a validated Scene (and its loaded grid) into the structs the kernels read
// (kernels/shared/structs.h) and the -D options that specialise the kernel for it.
#pragma once

#include <string>
#include <vector>

#include "render/scene_grids.h"
#include "scene/scene.h"
#include "shared/structs.h"
#include "volume/dense_grid.h"

namespace narval {

// Entries of the blackbody table an emitting medium's kernels read (kernels/shared/emission.h):
// over [0, T_max] that is a step of T_max/4095 kelvin, 0.8 K for a fire's 3200 K, where linear
// interpolation of the colour is within 2e-5 of its largest channel from 1000 K up and 4e-4 from
// 500 K (tests/unit/emission_test.cpp measures it; 500 K glows 1e-7 as brightly as 3000 K).
constexpr int kBlackbodyTableSize = 4096;

struct DeviceScene {
  scene_params params{};
  std::vector<light_params> lights;
  const DenseGrid* grid = nullptr;  // null: homogeneous medium or none
  const DenseGrid* emissionGrid = nullptr;  // null: none (medium.emission.grid_dims.x = 0)
  // The blackbody table (medium.emission.table_size rgb triples over [0, table_max] kelvin); one
  // triple of zeros when the medium has no blackbody emission (a buffer may not be empty).
  std::vector<float> emissionTable;
  // Per-cell density bounds of the majorant grid (medium.majorant_grid): one cell of 1 for a
  // homogeneous medium, one cell of 0 without a medium.
  std::vector<float> majorants;
  // Bytes the grid takes on the device in its storage (render/device_scene.h sets it at upload);
  // 0 before the upload (deviceSceneBytes then counts the dense floats).
  size_t gridBytes = 0;
  std::string buildOptions;         // -D defines for this scene
  std::vector<std::string> warnings;
};

// The primitive transform M = T · Rz · Ry · Rx · S (rotation in degrees, X applied first) as a
// row-major 3x4 matrix.
nv_affine transformMatrix(const Transform& t);
nv_affine affineMultiply(const nv_affine& a, const nv_affine& b);
// Throws std::domain_error for a singular map.
nv_affine affineInverse(const nv_affine& m);

// The camera of `scene` at its renderer.resolution (a viewer changes both between frames).
camera_params buildCamera(const Scene& scene);

// The world-space bounding box of the medium's box (its index box [0, dims] through the inverse of
// medium.world_to_index), e.g. for a viewer to frame it. False (lo, hi untouched) without a medium.
bool mediumWorldBounds(const DeviceScene& ds, float lo[3], float hi[3]);

// `grids` must be the volume's loaded grids (density null for a homogeneous medium / no volume;
// emission the grid its emission names, or null). Throws InputError for geometry the renderer
// cannot use (a singular volume transform) and for an emission grid that is missing.
DeviceScene buildDeviceScene(const Scene& scene, SceneGrids grids);

// Rebuilds the majorant grid of `ds` (its cells and medium.majorant_grid) with about `target` cells
// along the grid's longest axis (chooseMajorantResolution); target 0 keeps the automatic choice
// buildDeviceScene made. No-op without a grid (homogeneous or no medium: one cell). Returns whether
// the cells changed. Throws std::invalid_argument for a negative target.
bool setMajorantResolution(DeviceScene& ds, int target);

}  // namespace narval
