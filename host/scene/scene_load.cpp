// scene_load.cpp: the scene file (dissertation Listing 4.1 plus DESIGN.md's extensions) read into
// narval::Scene, validated so that nothing the renderer cannot honour gets past this file; the
// "renderer" object is read by renderer_load.cpp. Every key, its default and its range are in
// docs/scene-format.md, the schema (checked against the loader by
// tests/unit/scene_format_doc_test.cpp); scene.h holds the defaults.
//
// Unknown keys (anywhere, including keys of the other material type) are warnings, except a near
// miss of a key the same object takes ("sPP" for "spp": core/near_miss.h), which fails, and
// any unknown key under --set, where a key the loader does not know is a typo.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "core/enum_names.h"
#include "core/input_error.h"
#include "scene/json_override.h"
#include "scene/json_reader.h"
#include "scene/renderer_load.h"
#include "scene/scene.h"
#include "scene/scene_path.h"
#include "shared/phase.h"

namespace narval {

using namespace scene_detail;

namespace {

constexpr int kMaxJsonDepth = 128;       // nesting levels of the JSON (a scene needs 5)

const EnumNames<MaterialType> kMaterialTypes = {{"emitter", MaterialType::Emitter},
                                                {"volume", MaterialType::Volume}};
// The phase functions' names, from their list (phase_kinds.h).
const EnumNames<int> kPhaseFunctions = {
#define PHASE_KIND_NAME(id, value, name, prefix, key, lo, hi, fallback) {name, id},
    PHASE_KINDS(PHASE_KIND_NAME)
#undef PHASE_KIND_NAME
};
const EnumNames<GridSpace> kGridSpaces = {{"unit", GridSpace::Unit}, {"file", GridSpace::File}};
// A primitive's "type": a light kind's id (light_kinds.h), or kVolumeType.
constexpr int kVolumeType = -1;
const EnumNames<int> kPrimitiveTypes = {
#define LIGHT_KIND_NAME(id, value, name, prefix, scaled, area, vkey, key, lo, hi, fallback) {name, id},
    LIGHT_KINDS(LIGHT_KIND_NAME)
#undef LIGHT_KIND_NAME
    {"volume", kVolumeType}};
// A light kind's loader columns (light_kinds.h).
struct LightKindKeys {
  int id;
  const char* name;
  int scaled;  // transform.scale components that must be non-zero; -1: no transform
  const char* vectorKey;
  const char* key;
  float lo, hi, fallback;
};
const LightKindKeys kLightKindKeys[] = {
#define LIGHT_KIND_KEYS(id, value, name, prefix, scaled, area, vkey, key, lo, hi, fallback) \
  {id, name, scaled, vkey, key, lo, hi, fallback},
    LIGHT_KINDS(LIGHT_KIND_KEYS)
#undef LIGHT_KIND_KEYS
};
const LightKindKeys& lightKindKeys(int kind) {
  for (const LightKindKeys& k : kLightKindKeys)
    if (k.id == kind) return k;
  throw std::logic_error("lightKindKeys: unknown light kind " + std::to_string(kind));
}
const char* materialTypeName(MaterialType t) { return enumName(kMaterialTypes, t); }
const char* primitiveTypeName(const Primitive& p) {
  for (const auto& [name, id] : kPrimitiveTypes)
    if (id == (p.type == PrimitiveType::Volume ? kVolumeType : p.lightKind)) return name;
  return "?";
}

// --- sections ---

// The phase function's own parameter (phase_kinds.h: each kind names its key, range and default):
// read for the material's kind, range-checked, then as the kind uses it (phase_clamp: HG's ±1, a
// delta function, is held just inside, with a warning). Another kind's key is said to be ignored.
void readPhaseParameter(ObjectReader& r, Material& m) {
  struct KindKey {
    int id;
    const char* name;
    const char* key;
    float lo, hi, fallback;
  };
  static const KindKey kKinds[] = {
#define PHASE_KIND_KEY(id, value, name, prefix, key, lo, hi, fallback) {id, name, key, lo, hi, fallback},
      PHASE_KINDS(PHASE_KIND_KEY)
#undef PHASE_KIND_KEY
  };
  const char* ownName = "";
  for (const KindKey& k : kKinds)
    if (k.id == m.phase) ownName = k.name;
  // Every kind's key is checked where it is given; another kind's, set away from its default, is
  // named as ignored.
  for (const KindKey& k : kKinds) {
    if (!k.key) continue;
    if (k.id == m.phase) m.phaseParameter = k.fallback;
    const json* v = r.find(k.key);
    const std::string range = closedRange(k.lo, k.hi);
    r.note(k.key, "number", k.id == m.phase ? jsonNumber(k.fallback) : json(), range);
    if (!v) continue;
    const std::string key = r.keyOf(k.key);
    const float x = toFloat(r.context(), *v, key);
    if (!(x >= k.lo && x <= k.hi)) r.context().fail(key, "must be in " + range + ", got " + formatNumber(x));
    if (k.id != m.phase) {
      if (x != k.fallback)
        r.context().warn(key, std::string("ignored by the ") + ownName + " phase function (use \"phaseFunction\": \"" +
                                  k.name + "\")");
      continue;
    }
    m.phaseParameter = phase_clamp(m.phase, x);
    if (m.phaseParameter != x)
      r.context().warn(key, std::string(k.key) + " = " + formatNumber(x) + " makes the " + k.name +
                                " phase function degenerate; clamped to " + formatNumber(m.phaseParameter));
  }
}

// The volume's `emission` object (scene.h Emission). `hasFile`: the volume reads a grid file, so
// the emission may name grids of it.
Emission readEmission(JsonContext& ctx, const json& value, const std::string& key, bool hasFile) {
  ObjectReader r(ctx, value, key);
  Emission e;
  const json* grid = r.find("grid");
  const json* temperature = r.find("temperature");
  r.note("grid", "string", nullptr);
  r.note("temperature", "number or string", nullptr, ">= 0 (kelvin), or a grid's name");
  if (grid && temperature)
    ctx.fail(r.keyOf("temperature"), "give either \"grid\" (Le = color · scale · grid) or \"temperature\" "
                                     "(blackbody), not both");
  auto gridName = [&](const json& v, const std::string& name) {
    const std::string g = toString(ctx, v, r.keyOf(name));
    if (g.empty()) ctx.fail(r.keyOf(name), "must not be empty");
    if (!hasFile) ctx.fail(r.keyOf(name), "names a grid, but the volume has no grid file (\"path\")");
    return g;
  };
  if (temperature) {
    e.kind = EmissionKind::Blackbody;
    if (temperature->is_string()) {
      e.grid = gridName(*temperature, "temperature");
      e.temperatureOffset = r.getFloat("temperatureOffset", e.temperatureOffset);
      e.temperatureScale = r.getFloat("temperatureScale", e.temperatureScale);
    } else {
      e.temperature = toFloat(ctx, *temperature, r.keyOf("temperature"));
      checkNonNegative(ctx, r.keyOf("temperature"), e.temperature);
      for (const char* k : {"temperatureOffset", "temperatureScale"})
        if (r.has(k)) ctx.fail(r.keyOf(k), "applies to a temperature grid; \"temperature\" is a number here");
    }
    if (r.has("color")) ctx.fail(r.keyOf("color"), "does not apply to blackbody emission (\"temperature\")");
  } else {
    e.kind = EmissionKind::Color;
    if (grid) e.grid = gridName(*grid, "grid");
    e.color = r.getVec3("color", e.color);
    checkNonNegative(ctx, r.keyOf("color"), e.color);
    r.noteRange("color", ">= 0");
    for (const char* k : {"temperatureOffset", "temperatureScale"})
      if (r.has(k)) ctx.fail(r.keyOf(k), "applies to blackbody emission only (give \"temperature\")");
  }
  e.scale = readNonNegative(r, "scale", e.scale);
  r.reportUnknown();
  return e;
}

Material readMaterial(JsonContext& ctx, const json& value, const std::string& key) {
  ObjectReader r(ctx, value, key);
  Material m;
  m.name = r.requireString("name");
  if (m.name.empty()) ctx.fail(r.keyOf("name"), "must not be empty");
  m.type = requireEnum(r, "type", kMaterialTypes);
  if (m.type == MaterialType::Emitter) {
    m.albedo = r.requireVec3("albedo");
    checkNonNegative(ctx, r.keyOf("albedo"), m.albedo);
    r.noteRange("albedo", ">= 0");
  } else {
    m.scattering = r.requireVec3("scattering");
    checkNonNegative(ctx, r.keyOf("scattering"), m.scattering);
    r.noteRange("scattering", ">= 0");
    m.absorption = r.requireVec3("absorption");
    checkNonNegative(ctx, r.keyOf("absorption"), m.absorption);
    r.noteRange("absorption", ">= 0");
    m.phase = readEnum(r, "phaseFunction", kPhaseFunctions, m.phase);
    readPhaseParameter(r, m);
    r.note("path", "string", nullptr);
    if (const json* path = r.find("path")) {
      m.path = toString(ctx, *path, r.keyOf("path"));
      if (ctx.checkFiles) m.path = resolveVolumePath(m.path, ctx.file, r.keyOf("path"));
    }
    m.density = readNonNegative(r, "density", m.density);
    m.gridName = r.getString("grid", m.gridName);
    if (m.gridName.empty()) ctx.fail(r.keyOf("grid"), "must not be empty");
    m.gridSpace = readEnum(r, "gridSpace", kGridSpaces, m.gridSpace);
    // A homogeneous medium (no "path") has no grid to name or place: say so rather than ignore it.
    if (m.path.empty())
      for (const char* k : {"grid", "gridSpace"})
        ctx.warnIfChanged(r.keyOf(k), "ignored: the medium is homogeneous (no \"path\")");
    r.note("emission", "object", nullptr);
    if (const json* e = r.find("emission")) m.emission = readEmission(ctx, *e, r.keyOf("emission"), !m.path.empty());
  }
  r.reportUnknown();
  return m;
}

Transform readTransform(JsonContext& ctx, const json& value, const std::string& key, const Primitive& p) {
  ObjectReader r(ctx, value, key);
  Transform t;
  t.position = r.getVec3("position", t.position);
  t.scale = r.getVec3("scale", t.scale);
  t.rotation = r.getVec3("rotation", t.rotation);
  // A zero scale collapses the box (or the light's quad, which lies in local XY) to nothing.
  const int checked = p.type == PrimitiveType::Volume ? 3 : lightKindKeys(p.lightKind).scaled;
  for (int i = 0; i < checked; ++i)
    if (t.scale[size_t(i)] == 0) ctx.fail(indexKey(r.keyOf("scale"), size_t(i)), "must be non-zero, got 0");
  r.reportUnknown();
  return t;
}

// The light kinds' own keys (light_kinds.h): the primitive's kind's are read (its vector required
// and non-zero, its number in range); another kind's, given, are named as ignored.
void readLightKeys(ObjectReader& r, Primitive& p) {
  const LightKindKeys* mine = p.type == PrimitiveType::Light ? &lightKindKeys(p.lightKind) : nullptr;
  auto isMine = [&](const char* name) {
    return mine && ((mine->vectorKey && std::strcmp(name, mine->vectorKey) == 0) || (mine->key && std::strcmp(name, mine->key) == 0));
  };
  for (const LightKindKeys& k : kLightKindKeys) {
    for (const char* name : {k.vectorKey, k.key})
      if (name && !isMine(name) && r.find(name))
        r.context().warn(r.keyOf(name), std::string("ignored by a ") + primitiveTypeName(p) + " primitive");
    if (&k != mine) continue;
    if (k.vectorKey) {
      p.lightVector = r.requireVec3(k.vectorKey);
      if (p.lightVector == Vec3f{0, 0, 0}) r.context().fail(r.keyOf(k.vectorKey), "must be non-zero");
    }
    if (k.key) p.lightParameter = readInRange(r, k.key, k.fallback, k.lo, k.hi);
  }
}

Primitive readPrimitive(JsonContext& ctx, const json& value, const std::string& key) {
  ObjectReader r(ctx, value, key);
  Primitive p;
  p.name = r.getString("name", p.name);
  const int type = requireEnum(r, "type", kPrimitiveTypes);
  p.type = type == kVolumeType ? PrimitiveType::Volume : PrimitiveType::Light;
  p.lightKind = type == kVolumeType ? -1 : type;
  const json* t = r.find("transform");
  r.note("transform", "object", nullptr);
  if (p.type == PrimitiveType::Light && lightKindKeys(p.lightKind).scaled < 0) {
    if (t) ctx.warn(r.keyOf("transform"), std::string("ignored by a ") + primitiveTypeName(p) + " light");
  } else {
    static const json kIdentity = json::object();  // left out: every key its default
    p.transform = readTransform(ctx, t ? *t : kIdentity, r.keyOf("transform"), p);
  }
  readLightKeys(r, p);
  p.materialName = r.requireString("materialName");
  r.reportUnknown();
  return p;
}

Vec3f sub(const Vec3f& a, const Vec3f& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
float length(const Vec3f& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
Vec3f cross(const Vec3f& a, const Vec3f& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Camera readCamera(JsonContext& ctx, const json& value, const std::string& key) {
  ObjectReader r(ctx, value, key);
  Camera c;
  c.position = r.requireVec3("position");
  c.lookAt = r.requireVec3("lookAt");
  c.up = r.getVec3("up", c.up);
  c.vfov = r.getFloat("vfov", c.vfov);
  r.noteRange("vfov", "(0, 180) degrees");
  if (!(c.vfov > 0 && c.vfov < 180))
    ctx.fail(r.keyOf("vfov"), "must be in (0, 180) degrees, got " + formatNumber(c.vfov));
  c.aperture = readNonNegative(r, "aperture", c.aperture);
  c.focus = r.getFloat("focus", c.focus);
  r.noteRange("focus", "> 0");
  if (!(c.focus > 0)) ctx.fail(r.keyOf("focus"), "must be positive, got " + formatNumber(c.focus));
  c.speed = readNonNegative(r, "speed", c.speed);
  // The camera basis is built from these: a degenerate one would render NaNs.
  const Vec3f view = sub(c.lookAt, c.position);
  if (length(view) == 0) ctx.fail(r.keyOf("lookAt"), "must differ from camera.position");
  if (length(cross(view, c.up)) <= 1e-6f * length(view) * length(c.up))
    ctx.fail(r.keyOf("up"), "must be non-zero and not parallel to the viewing direction");
  r.reportUnknown();
  return c;
}

void readMaterials(JsonContext& ctx, ObjectReader& root, Scene& scene) {
  const json& list = toArray(ctx, root.require("materials"), "materials");
  root.note("materials", "array of objects", nullptr);
  std::map<std::string, size_t> byName;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = indexKey("materials", i);
    Material m = readMaterial(ctx, list[i], key);
    const auto [it, inserted] = byName.emplace(m.name, i);
    if (!inserted)
      ctx.fail(key + ".name", "duplicate material name \"" + m.name + "\" (first used by " +
                                  indexKey("materials", it->second) + ")");
    scene.materials.push_back(std::move(m));
  }
}

// Primitives name their material; the pairing decides what the renderer builds.
void linkMaterial(const JsonContext& ctx, const Scene& scene, Primitive& p, const std::string& key) {
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (scene.materials[i].name == p.materialName) p.materialIndex = static_cast<int>(i);
  if (p.materialIndex < 0) {
    std::string names;
    for (const Material& m : scene.materials) names += (names.empty() ? "\"" : ", \"") + m.name + "\"";
    ctx.fail(key, "no material named \"" + p.materialName + "\" (defined: " +
                      (names.empty() ? "none" : names) + ")");
  }
  const Material& m = scene.materials[p.materialIndex];
  const MaterialType wanted = p.type == PrimitiveType::Volume ? MaterialType::Volume : MaterialType::Emitter;
  if (m.type != wanted)
    ctx.fail(key, std::string("a ") + primitiveTypeName(p) + " primitive needs " +
                      (wanted == MaterialType::Volume ? "a volume" : "an emitter") + " material; \"" + m.name +
                      "\" is " + (m.type == MaterialType::Volume ? "a " : "an ") + materialTypeName(m.type));
}

void readPrimitives(JsonContext& ctx, ObjectReader& root, Scene& scene) {
  const json& list = toArray(ctx, root.require("primitives"), "primitives");
  root.note("primitives", "array of objects", nullptr);
  int volumes = 0;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = indexKey("primitives", i);
    Primitive p = readPrimitive(ctx, list[i], key);
    linkMaterial(ctx, scene, p, key + ".materialName");
    if (p.type == PrimitiveType::Volume && ++volumes > 1)
      ctx.fail(key, "only one volume primitive is supported");
    scene.primitives.push_back(std::move(p));
  }
}

// Nothing emits: every pixel would be black, which users mistake for a renderer bug.
void warnIfDark(const JsonContext& ctx, const Scene& scene) {
  for (const Primitive& p : scene.primitives) {
    if (p.type != PrimitiveType::Volume) return;
    if (scene.materials.at(size_t(p.materialIndex)).emission.kind != EmissionKind::None) return;  // it glows
  }
  if (scene.background != Vec3f{0, 0, 0}) return;
  ctx.warn("", "no light, no emission and a black background: the image will be black");
}

// A key written twice in one object: JSON parsers keep one of the two silently (nlohmann the last),
// so the other setting would be lost. Followed through the parser's events, with the key path of
// what is being parsed, for the message.
class DuplicateKeys {
 public:
  void see(const JsonContext& ctx, json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: frames_.push_back(Frame{true, {}, "", 0}); break;
      case json::parse_event_t::array_start: frames_.push_back(Frame{false, {}, "", 0}); break;
      case json::parse_event_t::key: {
        Frame& f = frames_.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second)
          ctx.fail(path(), "written twice in one object (JSON would keep only the last silently)");
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames_.pop_back();
        done();
        break;
      case json::parse_event_t::value: done(); break;
    }
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;  // objects: the key of the member being parsed
    size_t index;     // arrays: the index of the element being parsed
  };
  void done() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) p = f.object ? childKey(p, f.key) : indexKey(p, f.index);
    return p;
  }
  std::vector<Frame> frames_;
};

// The scene as narval renders it: `doc` with every key the loader took a default for written out,
// so that it reads back to the same settings with nothing left to a default.
json resolvedDocument(const json& doc, const std::map<std::string, KeyRecord>& keys) {
  json out = doc;
  for (const auto& [key, record] : keys) {
    if (record.given || record.fallback.is_null()) continue;
    std::string pointer = "/";  // "materials[1].g" -> "/materials/1/g"
    for (char c : key) {
      switch (c) {
        case '.': case '[': pointer += '/'; break;
        case ']': break;
        case '~': pointer += "~0"; break;
        case '/': pointer += "~1"; break;
        default: pointer += c;
      }
    }
    out[json::json_pointer(pointer)] = record.fallback;
  }
  return out;
}

std::string parseMessage(const json::exception& e) {
  // Drop nlohmann's "[json.exception.parse_error.101] " tag; keep its line/column text.
  const std::string what = e.what();
  const size_t tag = what.find("] ");
  return tag == std::string::npos ? what : what.substr(tag + 2);
}

}  // namespace

namespace scene_detail {

Scene parseScene(JsonContext& ctx, const std::string& jsonText, const std::vector<std::string>& overrides) {
  Scene scene;
  scene.sourcePath = ctx.file;
  scene.overrides = overrides;
  ctx.warnings = &scene.warnings;
  const std::string& path = ctx.file;

  json doc;
  try {
    // Scenes nest 5 levels (primitives[i].transform.position[j]). nlohmann's copy and dump recurse
    // once per level, so a document nested thousands deep would overflow the stack later on.
    DuplicateKeys duplicates;
    doc = json::parse(jsonText, [&ctx, &duplicates](int depth, json::parse_event_t event, json& parsed) {
      if (depth > kMaxJsonDepth)
        ctx.fail("", "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels (a scene needs 5)");
      duplicates.see(ctx, event, parsed);
      return true;
    });
  } catch (const json::exception& e) {  // parse_error, and out_of_range for 1e999
    ctx.fail("", "invalid JSON: " + parseMessage(e));
  }
  if (!doc.is_object()) ctx.fail("", std::string("expected a JSON object at the top level, got ") + doc.type_name());

  std::vector<std::pair<std::string, std::string>> overridden;  // (as written, loader key)
  for (const std::string& spec : overrides)
    overridden.emplace_back(spec.substr(0, spec.find('=')), applyOverride(doc, spec, path));

  ObjectReader root(ctx, doc, "");
  readMaterials(ctx, root, scene);
  readPrimitives(ctx, root, scene);
  scene.camera = readCamera(ctx, root.require("camera"), "camera");
  root.note("camera", "object", nullptr);
  root.note("renderer", "object", nullptr);
  bool emits = false;
  for (const Material& m : scene.materials) emits = emits || m.emission.kind != EmissionKind::None;
  scene.renderer = readRenderer(ctx, root.require("renderer"), "renderer", emits);
  scene.background = root.getVec3("background", scene.background);
  checkNonNegative(ctx, "background", scene.background);
  root.noteRange("background", ">= 0");
  root.reportUnknown();
  scene.document = resolvedDocument(doc, ctx.keys);

  // In a file an unknown key is a warning; on the command line it is a typo the user is waiting on.
  for (const auto& [written, key] : overridden)
    for (const std::string& unknown : ctx.unknownKeys)
      if (key == unknown || key.rfind(unknown + ".", 0) == 0 || key.rfind(unknown + "[", 0) == 0) {
        std::string meant;
        for (const auto& [miss, suggestion] : ctx.nearMisses)
          if (miss == unknown) meant = "; did you mean " + suggestion + "?";
        ctx.fail("--set " + written, "not a scene setting (unknown key " + unknown + meant + ")");
      }
  // A near miss of a known key in the file is a typo too: its default would run silently.
  if (!ctx.nearMisses.empty())
    ctx.fail(ctx.nearMisses.front().first, "unknown key (did you mean " + ctx.nearMisses.front().second + "?)");

  warnIfDark(ctx, scene);
  return scene;
}

}  // namespace scene_detail

Scene parseScene(const std::string& jsonText, const std::string& path, const std::vector<std::string>& overrides) {
  JsonContext ctx{path, nullptr, {}, {}, true, {}};
  return parseScene(ctx, jsonText, overrides);
}

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(path, ec)) throw inputError(path, "", "cannot open scene file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseScene(text.str(), path, overrides);
}

}  // namespace narval
