// renderer_load.h: the scene's "renderer" object (docs/scene-format.md), read into RendererSettings
// by renderer_load.cpp for scene_load.cpp.
#pragma once

#include <string>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace narval::scene_detail {

// `emits`: some material emits (the lobe's firstHitSteps then serves both variants).
RendererSettings readRenderer(JsonContext& ctx, const json& value, const std::string& key, bool emits);

}  // namespace narval::scene_detail
