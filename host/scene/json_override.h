// json_override.h: `--set PATH=VALUE` applied to a scene's JSON before it is validated, so an
// override goes through exactly the checks a value written in the file would.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace narval::scene_detail {

// PATH is dotted; a numeric component indexes an array ("materials.1.g", also "materials[1].g").
// VALUE is parsed as JSON when it parses ("16", "[1,1,1]", "true"), else taken as a string ("lobe").
// A missing object key is created (with any missing objects above it, so that
// "renderer.lobe.lobePoints=10" works on a scene without a lobe section); an array index out of
// range or a path through a number/string fails with "FILE: --set PATH: no such key".
// Returns PATH in the loader's key notation (materials[1].g) so unknown keys can be traced back.
std::string applyOverride(nlohmann::json& doc, const std::string& spec, const std::string& file);

}  // namespace narval::scene_detail
