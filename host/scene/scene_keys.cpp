// scene_keys.cpp: the scene format's key table, learnt from the loader itself. Two scenes that
// between them take every branch of the loader (a material per phase function and per kind of
// emission, a primitive per light kind, both Lobe Estimator variants, both cache layouts, the march
// with and without the cache) are read
// with the volume files not looked for; every key looked up leaves its type, default and range
// (json_reader.h, KeyRecord). docs/scene-format.md is checked against this table.
#include <algorithm>
#include <map>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace narval {

using namespace scene_detail;

namespace {

json schemaScene(const json& renderer) {
  json materials = json::array({{{"name", "light"}, {"type", "emitter"}, {"albedo", {1, 1, 1}}}});
  auto volume = [](const std::string& name) {
    return json{{"name", name}, {"type", "volume"}, {"scattering", {1, 1, 1}}, {"absorption", {0, 0, 0}}};
  };
#define PHASE_KIND_MATERIAL(id, value, name, prefix, key, lo, hi, fallback) \
  materials.push_back(volume(name));                                       \
  materials.back()["phaseFunction"] = name;
  PHASE_KINDS(PHASE_KIND_MATERIAL)
#undef PHASE_KIND_MATERIAL
  // Emission in each of its forms: a colour over a grid, a temperature grid, one temperature.
  const json emissions[] = {{{"grid", "heat"}},
                            {{"temperature", "temperature"}},
                            {{"temperature", 1500}}};
  for (const json& e : emissions) {
    materials.push_back(volume("emitting" + std::to_string(materials.size())));
    materials.back()["path"] = "grid.vdb";
    materials.back()["emission"] = e;
  }
  json primitives = json::array();
  auto light = [&](const char* type, const char* vectorKey) {  // the kind's vector key is required
    primitives.push_back({{"type", type}, {"materialName", "light"}});
    if (vectorKey) primitives.back()[vectorKey] = {0, -1, 0};
  };
#define LIGHT_KIND_PRIMITIVE(id, value, name, prefix, scaled, area, vkey, key, lo, hi, fallback) light(name, vkey);
  LIGHT_KINDS(LIGHT_KIND_PRIMITIVE)
#undef LIGHT_KIND_PRIMITIVE
  primitives.push_back({{"type", "volume"}, {"materialName", "isotropic"}});
  return {{"materials", materials},
          {"primitives", primitives},
          {"camera", {{"position", {0, 0, -5}}, {"lookAt", {0, 0, 0}}}},
          {"renderer", renderer}};
}

}  // namespace

std::vector<SceneKey> sceneKeyTable() {
  const json renderers[] = {
      {{"resolution", {8, 8}}},
      {{"resolution", {8, 8}},
       {"algorithm", "raymarch"},
       {"raymarch", {{"multipleScattering", "none"}, {"msCache", {{"layout", "grid"}}}}},  // not the defaults
       {"lobe", {{"variant", LobeSettings{}.variant == LobeVariant::Eq7 ? "corrected" : "eq7"}}}},  // not the default
  };
  std::map<std::string, SceneKey> table;
  for (const json& renderer : renderers) {
    JsonContext ctx{"(key table)", nullptr, {}, {}, false, {}};
    parseScene(ctx, schemaScene(renderer).dump(), {});
    for (const auto& [path, record] : ctx.keys) {
      SceneKey& k = table[schemaKey(path)];
      k.key = schemaKey(path);
      if (k.type.empty()) k.type = record.type;
      if (k.range.empty()) k.range = record.range;
      k.required = k.required || record.required;
      if (!record.fallback.is_null() &&
          std::find(k.defaults.begin(), k.defaults.end(), record.fallback) == k.defaults.end())
        k.defaults.push_back(record.fallback);
    }
  }
  std::vector<SceneKey> out;
  for (auto& [key, k] : table) out.push_back(std::move(k));
  return out;
}

}  // namespace narval
