// cli_common.h: small pieces several subcommands share (option parsing, loading a scene's grid,
// writing text outputs).
#pragma once

#include <string>
#include <utility>

#include "image/atomic_file.h"  // writeTextAtomic
#include "render/scene_upload.h"  // SceneGrids
#include "scene/scene.h"
#include "volume/grid.h"

namespace narval {

// "WxH" -> {W, H} (positive); `what` names the option in the InputError.
std::pair<int, int> parseSize(const std::string& text, const std::string& what);

// --resolution WxH as the scene override "renderer.resolution=[W,H]" (parseSize's errors name the flag).
std::string resolutionOverride(const std::string& text);

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
