// scene_grids.h: the grids a scene's medium reads (its density grid, and the emission or
// temperature grid its emission names), loaded once for a render, a sweep or a viewer.
#pragma once

#include "scene/scene.h"
#include "volume/dense_grid.h"

namespace narval {

// The grids a scene's medium reads: its density grid and, for an emitting medium that names one,
// its emission or temperature grid (the same object when both name one grid of the file: it is
// uploaded once). Converts from the density grid alone, for scenes without an emission grid.
struct SceneGrids {
  const DenseGrid* density = nullptr;   // null: homogeneous medium or none
  const DenseGrid* emission = nullptr;  // null: no emission grid
  SceneGrids() = default;
  SceneGrids(const DenseGrid* densityGrid, const DenseGrid* emissionGrid = nullptr)  // NOLINT: implicit
      : density(densityGrid), emission(emissionGrid) {}
};

// The grids a scene loads (loadSceneGrids fills it; SceneGrids points into it).
struct SceneGridStorage {
  DenseGrid density, emission;
};

// Loads the grids of the scene's volume primitive into `storage`: its density grid (material key
// "grid") and the grid its emission names (emission.grid or emission.temperature; the density
// grid itself when it names that one). Null grids: no volume, a homogeneous one, no emission grid.
// Throws InputError from the grid loader; for the emission grid its message names the scene file
// and the emission key.
SceneGrids loadSceneGrids(const Scene& scene, SceneGridStorage& storage);

}  // namespace narval
