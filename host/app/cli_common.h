// cli_common.h: small pieces several subcommands share (option parsing, loading a scene's grid,
// writing text outputs).
#pragma once

#include <string>
#include <utility>

#include "image/atomic_file.h"  // writeTextAtomic
#include "render/scene_grids.h"  // loadSceneGrids
#include "scene/scene.h"
#include "volume/grid.h"

namespace narval {

// "WxH" -> {W, H} (positive); `what` names the option in the InputError.
std::pair<int, int> parseSize(const std::string& text, const std::string& what);

// --resolution WxH as the scene override "renderer.resolution=[W,H]" (parseSize's errors name the flag).
std::string resolutionOverride(const std::string& text);


}  // namespace narval
