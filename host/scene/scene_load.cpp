// scene_load.cpp: the scene file (dissertation Listing 4.1 plus DESIGN.md's extensions) read into
// narval::Scene, validated so that nothing the renderer cannot honour gets past this file.
//
// Parameters. "req" = required; every other key may be left out and takes the default shown
// (scene.h holds the same defaults). Vectors are arrays of exactly 3 finite numbers.
//
// | key                     | type                            | req | default     | constraint                 |
// |-------------------------|---------------------------------|-----|-------------|----------------------------|
// | materials               | array of objects                | req |             |                            |
// |   [i].name              | string                          | req |             | non-empty, unique          |
// |   [i].type              | emitter, volume                 | req |             |                            |
// |   emitter: albedo       | vec3: radiance (point: W/sr)    | req |             | >= 0                       |
// |   volume: scattering    | vec3, per world unit            | req |             | >= 0                       |
// |   volume: absorption    | vec3, per world unit            | req |             | >= 0                       |
// |   volume: phaseFunction | isotropic, hg                   |     | isotropic   |                            |
// |   volume: g             | number                          |     | 0           | [-1, 1]; ±1 -> ±0.9999     |
// |   volume: path          | string: .vdb or .vol file       |     | homogeneous | exists; ${VAR}, ${VAR:-d}; |
// |                         |                                 |     |             | relative to the scene file |
// |   volume: density       | number: multiplier D            |     | 1           | >= 0                       |
// |   volume: grid          | string: grid name in the .vdb   |     | density     | non-empty                  |
// |   volume: gridSpace     | unit, file                      |     | unit        |                            |
// |   volume: emission      | object (pbrt-v4's emission:     |     | none        | grid or temperature, not   |
// |                         | σa·Le per unit length)          |     |             | both                       |
// |     .grid               | string: grid of the file, Le =  |     | none: 1     | needs path; a float grid   |
// |                         | color·scale·grid                |     |             |                            |
// |     .color              | vec3 (with grid or alone)       |     | [1, 1, 1]   | >= 0; not with temperature |
// |     .temperature        | string: temperature grid, or    |     |             | grid: needs path;          |
// |                         | number: kelvin; Le = scale·B(T) |     |             | number >= 0                |
// |     .temperatureOffset  | number, T = (v - offset)·tscale |     | 0           | temperature grid only      |
// |     .temperatureScale   | number                          |     | 1           | temperature grid only      |
// |     .scale              | number                          |     | 1           | >= 0                       |
// | primitives              | array of objects                | req |             | at most one volume         |
// |   [i].name              | string                          |     | ""          |                            |
// |   [i].type              | rectangle, volume, point        | req |             |                            |
// |   [i].transform         | object                          |     | identity    |                            |
// |     .position           | vec3                            |     | [0, 0, 0]   |                            |
// |     .scale              | vec3                            |     | [1, 1, 1]   | non-zero (volume: x, y, z; |
// |                         |                                 |     |             | rectangle: x, y)           |
// |     .rotation           | vec3, degrees                   |     | [0, 0, 0]   |                            |
// |   [i].materialName      | string                          | req |             | a material of the matching |
// |                         |                                 |     |             | type: volume for volume,   |
// |                         |                                 |     |             | emitter for rectangle/point|
// | camera                  | object                          | req |             |                            |
// |   position              | vec3                            | req |             |                            |
// |   lookAt                | vec3                            | req |             | != position                |
// |   up                    | vec3                            |     | [0, 1, 0]   | not parallel to the view   |
// |   vfov                  | number, degrees                 |     | 45          | (0, 180)                   |
// |   aperture              | number: lens radius             |     | 0           | >= 0                       |
// |   focus                 | number: focus distance          |     | 1           | > 0                        |
// |   speed                 | number: viewer navigation       |     | 1           | >= 0                       |
// | renderer                | object                          | req |             |                            |
// |   resolution            | [width, height] integers        | req |             | each in [1, 16384]         |
// |   spp                   | integer                         |     | 1000        | >= 1                       |
// |   bounces               | integer                         |     | 3           | >= 0                       |
// |   HDR                   | boolean                         |     | true        |                            |
// |   toneMapping           | bool, or none, reinhard, aces   |     | true        | true = aces, false = none  |
// |   exposure              | number, stops                   |     | 0           |                            |
// |   algorithm             | pathtrace, raymarch, lobe       |     | pathtrace   |                            |
// |   seed                  | integer                         |     | 0           | [0, 2^32 - 1]              |
// |   storage               | auto, image, buffer, bricks:    |     | auto        | auto: buffer on CPU        |
// |                         | the grid on the device          |     |             | devices, image elsewhere;  |
// |                         | (--storage)                     |     |             | bricks if those can't hold |
// |   pathtrace.lightSampling | all, power, fluence: NEE aims  |     | all         |                            |
// |                         | at every light, or at one       |     |             |                            |
// |   pathtrace.shadowRoulette | number: shadow-ray Tr below  |     | 0.05        | [0, 1]; 0 = never          |
// |                         | which Russian roulette plays    |     |             |                            |
// |   raymarch.steps        | integer                         |     | 60          | >= 1                       |
// |   raymarch.shadowSteps  | integer                         |     | 10          | >= 1                       |
// |   raymarch.octaves      | integer                         |     | 1           | [1, 16]; 1 = off           |
// |   raymarch.octaveScattering, .octaveExtinction, .octavePhase (a, b, c) | number | | 0.5 | [0, 1], a <= b   |
// |   raymarch.minTransmittance | number: view march stops   |     | 0.001       | [0, 1); 0 = never          |
// |   raymarch.multipleScattering | none, octaves, cache      |     | none        | octaves when octaves > 1   |
// |   raymarch.areaLightSamples | integer: K×K points per     |     | 1           | [1, 16]; 1 = the centre    |
// |                         | rectangle light (phase, 1/d²)   |     |             |                            |
// |   raymarch.areaLightPhase | points, exact: the phase over |     | points      | exact: its solid-angle     |
// |                         | a rectangle light               |     |             | integral (phase_polygon.h) |
// |   raymarch.shadowAreaSamples | integer: K×K points per    |     | 4           | [1, 16]; 1 = the centre    |
// |                         | rectangle light (shadow)        |     |             |                            |
// |   raymarch.shadowWeighting | area, phase: how a rectangle's|     | area        | phase: the light cache     |
// |                         | shadow points are averaged      |     |             | follows the camera         |
// |   raymarch.msCache.closure | linear, hg: the in-scattering  |     | linear      | ms_cache.h, "Closure";     |
// |                         | its two moments give a direction;|    |             | camera: rebuilt when the   |
// |                         | camera: estimated towards it    |     |             | camera moves               |
// |   raymarch.msCache.interpolation | geometric, linear: how   |     | geometric   | ms_cache.h, "Interpolation"|
// |                         | the nodes are mixed             |     |             |                            |
// |   raymarch.msCache.layout | grid, view: nodes over the     |     | grid        | view: aims at the camera   |
// |                         | medium's box, or columns over   |     |             | (closure "camera"); rebuilt|
// |                         | the image (ms_cache_view.h)     |     |             | when the camera moves      |
// |   raymarch.msCache.resolution | integer: cells, longest axis |  | 16          | [1, 256]; grid             |
// |   raymarch.msCache.direct | boolean: the cache holds the  |     | false       | closure camera or layout   |
// |                         | lights' unscattered light too   |     |             | view; no light loop        |
// |   raymarch.msCache.tile | integer: pixels per column side |     | 4           | [1, 256]; view             |
// |   raymarch.msCache.slices | integer: nodes per column     |     | 8           | [2, 64]; view              |
// |   raymarch.msCache.filter | number: the nodes' filter's   |     | 0 (off)     | [0, 8]; view               |
// |                         | σ_s in columns (ms_cache_filter.h)|   |             |                            |
// |   raymarch.msCache.filterTolerance | number: its k, in     |     | 1           | > 0; view                  |
// |                         | standard errors                 |     |             |                            |
// |   raymarch.msCache.filterTwicing | boolean: the filter's  |     | false       | view; needs filter > 0     |
// |                         | residual filtered, added back   |     |             |                            |
// |   raymarch.msCache.allocation | even, perceptual: the   |     | even        | view                       |
// |                         | paths per column (ms_cache_allocation.h) |  |          |                            |
// |   raymarch.msCache.guide | number: share of the paths' first |   | 0 (off)     | [0, 1); closure camera or  |
// |                         | directions drawn towards lights |     |             | layout view (phase_guide.h)|
// |   raymarch.msCache.paths, .pathsPerLaunch | integer: per node |   | 256, 32     | [1, 2^20]                  |
// |   lobe.variant          | eq7, corrected (lobe.h)         |     | eq7         |                            |
// |   lobe.depthFactor      | number (eq7)                    |     | 20          | >= 0                       |
// |   lobe.lobePoints       | integer                         |     | 30          | >= 1                       |
// |   lobe.lobeRadius       | number: eq7 world units,        |     | 1           | >= 0                       |
// |                         | corrected mean free paths       |     |             |                            |
// |   lobe.shadowSteps      | integer                         |     | 100         | >= 1                       |
// |   lobe.firstHitSteps    | integer (eq7; both: emission)   |     | 60          | >= 1                       |
// |   lobe.viewSteps        | integer: Tr(x0 -> P_i) samples; |     | eq7 24,     | >= 1                       |
// |                         | corrected: the one view march   |     | corrected 16|                            |
// |   lobe.minTransmittance | number: Tr(x0 -> P_i) stops     |     | 0.001       | [0, 1); 0 = never          |
// |   lobe.areaLightSamples | integer, as raymarch's          |     | 1           | [1, 16]                    |
// |   lobe.areaLightPhase   | points, exact: as raymarch's    |     | points      |                            |
// |   lobe.shadowAreaSamples | integer, as raymarch's         |     | eq7 1,      | [1, 16]                    |
// |                         |                                 |     | corrected 4 |                            |
// |   lightCache.resolution | "auto" or integer: cells on the |     | auto        | [0, 1024]; 0 = off (exact  |
// |                         | box's longest axis              |     |             | shadow marches)            |
// | background              | vec3: radiance of escaping rays |     | [0, 0, 0]   | >= 0                       |
//
// Unknown keys (anywhere, including keys of the other material type) are warnings, except a near
// miss of a key the same object takes ("sPP" for "spp": json_reader.h, nearMiss), which fails, and
// any unknown key under --set, where a key the loader does not know is a typo. Every key is
// documented in docs/scene-format.md (checked by tests/unit/scene_format_doc_test.cpp).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include "scene/input_error.h"
#include "scene/json_override.h"
#include "scene/json_reader.h"
#include "scene/scene.h"
#include "scene/scene_path.h"
#include "shared/phase.h"

namespace narval {

using namespace scene_detail;

namespace {

constexpr int64_t kIntMax = std::numeric_limits<int>::max();
constexpr int64_t kMaxImageSide = 16384;  // keeps width * height well inside an int
constexpr int kMaxJsonDepth = 128;       // nesting levels of the JSON (a scene needs 5)

template <typename E>
using EnumNames = std::vector<std::pair<const char*, E>>;

template <typename E>
std::string allowedList(const EnumNames<E>& names) {
  std::string out;
  for (const auto& [name, value] : names) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

template <typename E>
E toEnum(const JsonContext& ctx, const json& v, const std::string& key, const EnumNames<E>& names) {
  const std::string s = toString(ctx, v, key);
  for (const auto& [name, value] : names)
    if (s == name) return value;
  ctx.fail(key, "unknown value \"" + s + "\" (allowed: " + allowedList(names) + ")");
}

template <typename E>
E readEnum(ObjectReader& r, const std::string& name, const EnumNames<E>& names, E fallback) {
  const json* v = r.find(name);
  return v ? toEnum(r.context(), *v, r.keyOf(name), names) : fallback;
}

template <typename E>
E requireEnum(ObjectReader& r, const std::string& name, const EnumNames<E>& names) {
  return toEnum(r.context(), r.require(name), r.keyOf(name), names);
}

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
const EnumNames<ToneMapping> kToneMappings = {{"none", ToneMapping::None},
                                              {"reinhard", ToneMapping::Reinhard},
                                              {"aces", ToneMapping::Aces}};
const EnumNames<GridStorage> kGridStorages = {{"auto", GridStorage::Auto},
                                              {"image", GridStorage::Image},
                                              {"buffer", GridStorage::Buffer},
                                              {"bricks", GridStorage::Bricks}};
const EnumNames<MultipleScattering> kMultipleScattering = {{"none", MultipleScattering::None},
                                                           {"octaves", MultipleScattering::Octaves},
                                                           {"cache", MultipleScattering::Cache}};
const EnumNames<LightSampling> kLightSamplings = {
    {"all", LightSampling::All}, {"power", LightSampling::Power}, {"fluence", LightSampling::Fluence}};
const EnumNames<AreaLightPhase> kAreaLightPhases = {{"points", AreaLightPhase::Points},
                                                     {"exact", AreaLightPhase::Exact}};
const EnumNames<MsCacheClosure> kMsCacheClosures = {
    {"linear", MsCacheClosure::Linear}, {"hg", MsCacheClosure::Hg}, {"camera", MsCacheClosure::Camera}};
const EnumNames<MsCacheInterpolation> kMsCacheInterpolations = {{"geometric", MsCacheInterpolation::Geometric},
                                                                {"linear", MsCacheInterpolation::Linear}};
const EnumNames<ShadowWeighting> kShadowWeightings = {{"area", ShadowWeighting::Area},
                                                      {"phase", ShadowWeighting::Phase}};
const EnumNames<MsCacheLayout> kMsCacheLayouts = {{"grid", MsCacheLayout::Grid}, {"view", MsCacheLayout::View}};
const EnumNames<MsCacheAllocationKind> kMsCacheAllocations = {{"even", MsCacheAllocationKind::Even},
                                                              {"perceptual", MsCacheAllocationKind::Perceptual}};
const EnumNames<LobeVariant> kLobeVariants = {{"eq7", LobeVariant::Eq7}, {"corrected", LobeVariant::Corrected}};
const EnumNames<Algorithm> kAlgorithms = {{"pathtrace", Algorithm::Pathtrace},
                                          {"raymarch", Algorithm::Raymarch},
                                          {"lobe", Algorithm::Lobe}};

const char* materialTypeName(MaterialType t) { return t == MaterialType::Emitter ? "emitter" : "volume"; }
const char* primitiveTypeName(const Primitive& p) {
  for (const auto& [name, id] : kPrimitiveTypes)
    if (id == (p.type == PrimitiveType::Volume ? kVolumeType : p.lightKind)) return name;
  return "?";
}

// --- range checks: the message names the value as the user wrote it ---

void checkNonNegative(const JsonContext& ctx, const std::string& key, float v) {
  if (!(v >= 0)) ctx.fail(key, "must be non-negative, got " + formatNumber(v));
}

void checkNonNegative(const JsonContext& ctx, const std::string& key, const Vec3f& v) {
  for (size_t i = 0; i < 3; ++i) checkNonNegative(ctx, indexKey(key, i), v[i]);
}

int64_t checkIntRange(const JsonContext& ctx, const std::string& key, int64_t v, int64_t lo, int64_t hi) {
  if (v < lo) ctx.fail(key, "must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
  if (v > hi) ctx.fail(key, "must be at most " + std::to_string(hi) + ", got " + std::to_string(v));
  return v;
}

int readInt(ObjectReader& r, const std::string& name, int fallback, int64_t lo, int64_t hi = kIntMax) {
  return static_cast<int>(checkIntRange(r.context(), r.keyOf(name), r.getInteger(name, fallback), lo, hi));
}

float readNonNegative(ObjectReader& r, const std::string& name, float fallback) {
  const float v = r.getFloat(name, fallback);
  checkNonNegative(r.context(), r.keyOf(name), v);
  return v;
}

float readUnitInterval(ObjectReader& r, const std::string& name, float fallback) {
  const float v = r.getFloat(name, fallback);
  if (!(v >= 0 && v <= 1)) r.context().fail(r.keyOf(name), "must be in [0, 1], got " + formatNumber(v));
  return v;
}

// A transmittance below which a march stops: [0, 1) (0 = never stops; 1 would stop at once).
float readMinTransmittance(ObjectReader& r, float fallback) {
  const float v = r.getFloat("minTransmittance", fallback);
  if (!(v >= 0 && v < 1))
    r.context().fail(r.keyOf("minTransmittance"), "must be in [0, 1) (0 = never stop), got " + formatNumber(v));
  return v;
}

// renderer.raymarch/lobe.areaLightPhase; with "exact", a given areaLightSamples is said to be ignored.
AreaLightPhase readAreaLightPhase(ObjectReader& r, AreaLightPhase fallback) {
  const AreaLightPhase v = readEnum(r, "areaLightPhase", kAreaLightPhases, fallback);
  if (v == AreaLightPhase::Exact && r.find("areaLightSamples"))
    r.context().warn(r.keyOf("areaLightSamples"), "applies to areaLightPhase \"points\"; \"exact\" ignores it");
  return v;
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
    if (!v) continue;
    const std::string key = r.keyOf(k.key);
    const float x = toFloat(r.context(), *v, key);
    if (!(x >= k.lo && x <= k.hi))
      r.context().fail(key, "must be in [" + formatNumber(k.lo) + ", " + formatNumber(k.hi) + "], got " + formatNumber(x));
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
  } else {
    m.scattering = r.requireVec3("scattering");
    checkNonNegative(ctx, r.keyOf("scattering"), m.scattering);
    m.absorption = r.requireVec3("absorption");
    checkNonNegative(ctx, r.keyOf("absorption"), m.absorption);
    m.phase = readEnum(r, "phaseFunction", kPhaseFunctions, m.phase);
    readPhaseParameter(r, m);
    if (const json* path = r.find("path"))
      m.path = resolveVolumePath(toString(ctx, *path, r.keyOf("path")), ctx.file, r.keyOf("path"));
    m.density = readNonNegative(r, "density", m.density);
    m.gridName = r.getString("grid", m.gridName);
    if (m.gridName.empty()) ctx.fail(r.keyOf("grid"), "must not be empty");
    m.gridSpace = readEnum(r, "gridSpace", kGridSpaces, m.gridSpace);
    // A homogeneous medium (no "path") has no grid to name or place: say so rather than ignore it.
    if (m.path.empty())
      for (const char* k : {"grid", "gridSpace"})
        if (r.has(k)) ctx.warn(r.keyOf(k), "ignored: the medium is homogeneous (no \"path\")");
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
    if (k.key) {
      p.lightParameter = r.getFloat(k.key, k.fallback);
      if (!(p.lightParameter >= k.lo && p.lightParameter <= k.hi))
        r.context().fail(r.keyOf(k.key), "must be in [" + formatNumber(k.lo) + ", " + formatNumber(k.hi) + "], got " +
                                             formatNumber(p.lightParameter));
    }
  }
}

Primitive readPrimitive(JsonContext& ctx, const json& value, const std::string& key) {
  ObjectReader r(ctx, value, key);
  Primitive p;
  p.name = r.getString("name", p.name);
  const int type = requireEnum(r, "type", kPrimitiveTypes);
  p.type = type == kVolumeType ? PrimitiveType::Volume : PrimitiveType::Light;
  p.lightKind = type == kVolumeType ? -1 : type;
  if (const json* t = r.find("transform")) {
    if (p.type == PrimitiveType::Light && lightKindKeys(p.lightKind).scaled < 0)
      ctx.warn(r.keyOf("transform"), std::string("ignored by a ") + primitiveTypeName(p) + " light");
    else
      p.transform = readTransform(ctx, *t, r.keyOf("transform"), p);
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
  if (!(c.vfov > 0 && c.vfov < 180))
    ctx.fail(r.keyOf("vfov"), "must be in (0, 180) degrees, got " + formatNumber(c.vfov));
  c.aperture = readNonNegative(r, "aperture", c.aperture);
  c.focus = r.getFloat("focus", c.focus);
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

ToneMapping readToneMapping(ObjectReader& r, ToneMapping fallback) {
  const json* v = r.find("toneMapping");
  if (!v) return fallback;
  // Listing 4.1 writes a boolean; a name picks the operator.
  if (v->is_boolean()) return v->get<bool>() ? ToneMapping::Aces : ToneMapping::None;
  if (!v->is_string())
    r.context().fail(r.keyOf("toneMapping"), "expected a boolean or one of " + allowedList(kToneMappings) +
                                                 ", got " + v->type_name());
  return toEnum(r.context(), *v, r.keyOf("toneMapping"), kToneMappings);
}

void readResolution(ObjectReader& r, RendererSettings& s) {
  const std::string key = r.keyOf("resolution");
  const json& v = r.require("resolution");
  if (!v.is_array() || v.size() != 2)
    r.context().fail(key, std::string("expected an array of 2 integers [width, height], got ") +
                              (v.is_array() ? std::to_string(v.size()) + " elements" : v.type_name()));
  int* sides[2] = {&s.width, &s.height};
  for (size_t i = 0; i < 2; ++i)
    *sides[i] = static_cast<int>(checkIntRange(r.context(), indexKey(key, i),
                                               toInteger(r.context(), v[i], indexKey(key, i)), 1, kMaxImageSide));
}

// `emits`: some material emits (the lobe's firstHitSteps then serves both variants).
RendererSettings readRenderer(JsonContext& ctx, const json& value, const std::string& key, bool emits) {
  ObjectReader r(ctx, value, key);
  RendererSettings s;
  readResolution(r, s);
  s.spp = readInt(r, "spp", s.spp, 1);
  s.bounces = readInt(r, "bounces", s.bounces, 0);
  s.hdr = r.getBool("HDR", s.hdr);
  s.toneMapping = readToneMapping(r, s.toneMapping);
  s.exposure = r.getFloat("exposure", s.exposure);
  s.algorithm = readEnum(r, "algorithm", kAlgorithms, s.algorithm);
  s.storage = readEnum(r, "storage", kGridStorages, s.storage);
  s.seed = static_cast<uint32_t>(checkIntRange(ctx, r.keyOf("seed"), r.getInteger("seed", s.seed), 0,
                                               std::numeric_limits<uint32_t>::max()));
  if (const json* v = r.find("pathtrace")) {
    ObjectReader p(ctx, *v, r.keyOf("pathtrace"));
    s.pathtrace.lightSampling = readEnum(p, "lightSampling", kLightSamplings, s.pathtrace.lightSampling);
    s.pathtrace.shadowRoulette = readUnitInterval(p, "shadowRoulette", s.pathtrace.shadowRoulette);
    p.reportUnknown();
  }
  if (const json* v = r.find("raymarch")) {
    ObjectReader m(ctx, *v, r.keyOf("raymarch"));
    s.raymarch.steps = readInt(m, "steps", s.raymarch.steps, 1);
    s.raymarch.shadowSteps = readInt(m, "shadowSteps", s.raymarch.shadowSteps, 1);
    s.raymarch.octaves = readInt(m, "octaves", s.raymarch.octaves, 1, 16);
    s.raymarch.octaveScattering = readUnitInterval(m, "octaveScattering", s.raymarch.octaveScattering);
    s.raymarch.octaveExtinction = readUnitInterval(m, "octaveExtinction", s.raymarch.octaveExtinction);
    s.raymarch.octavePhase = readUnitInterval(m, "octavePhase", s.raymarch.octavePhase);
    if (s.raymarch.octaveScattering > s.raymarch.octaveExtinction)
      ctx.fail(m.keyOf("octaveScattering"), "must not exceed octaveExtinction (" +
                                                formatNumber(s.raymarch.octaveExtinction) +
                                                ") or the octaves add energy");
    s.raymarch.minTransmittance = readMinTransmittance(m, s.raymarch.minTransmittance);
    s.raymarch.areaLightSamples = readInt(m, "areaLightSamples", s.raymarch.areaLightSamples, 1, 16);
    s.raymarch.areaLightPhase = readAreaLightPhase(m, s.raymarch.areaLightPhase);
    s.raymarch.shadowAreaSamples = readInt(m, "shadowAreaSamples", s.raymarch.shadowAreaSamples, 1, 16);
    s.raymarch.shadowWeighting = readEnum(m, "shadowWeighting", kShadowWeightings, s.raymarch.shadowWeighting);
    s.raymarch.multipleScattering =
        readEnum(m, "multipleScattering", kMultipleScattering,
                 s.raymarch.octaves > 1 ? MultipleScattering::Octaves : MultipleScattering::None);
    if (s.raymarch.octaves > 1 && s.raymarch.multipleScattering != MultipleScattering::Octaves)
      ctx.fail(m.keyOf("octaves"), "applies only with multipleScattering \"octaves\"");
    if (const json* c = m.find("msCache")) {
      ObjectReader mc(ctx, *c, m.keyOf("msCache"));
      s.raymarch.msCache.closure = readEnum(mc, "closure", kMsCacheClosures, s.raymarch.msCache.closure);
      s.raymarch.msCache.interpolation =
          readEnum(mc, "interpolation", kMsCacheInterpolations, s.raymarch.msCache.interpolation);
      s.raymarch.msCache.layout = readEnum(mc, "layout", kMsCacheLayouts, s.raymarch.msCache.layout);
      if (s.raymarch.msCache.layout == MsCacheLayout::View && s.raymarch.msCache.closure != MsCacheClosure::Camera &&
          mc.find("closure"))
        ctx.fail(mc.keyOf("closure"), "must be \"camera\" with layout \"view\" (its paths aim at the camera)");
      const bool view = s.raymarch.msCache.layout == MsCacheLayout::View;
      for (const std::string key :
           {"resolution", "interpolation", "tile", "slices", "filter", "filterTolerance", "filterTwicing", "allocation"})
        if (mc.find(key) && view != (key == "tile" || key == "slices" || key == "filter" || key == "filterTolerance" ||
                                     key == "filterTwicing" || key == "allocation"))
          ctx.warn(mc.keyOf(key), std::string("applies to layout \"") + (view ? "grid" : "view") + "\"; \"" +
                                      (view ? "view" : "grid") + "\" ignores it");
      s.raymarch.msCache.resolution = readInt(mc, "resolution", s.raymarch.msCache.resolution, 1, 256);
      s.raymarch.msCache.tile = readInt(mc, "tile", s.raymarch.msCache.tile, 1, 256);
      s.raymarch.msCache.direct = mc.getBool("direct", s.raymarch.msCache.direct);
      if (s.raymarch.msCache.direct && !view && s.raymarch.msCache.closure != MsCacheClosure::Camera)
        ctx.fail(mc.keyOf("direct"), "needs closure \"camera\" or layout \"view\" (a node must hold the light "
                                     "scattered towards the camera)");
      s.raymarch.msCache.slices = readInt(mc, "slices", s.raymarch.msCache.slices, 2, 64);
      s.raymarch.msCache.filter = readNonNegative(mc, "filter", s.raymarch.msCache.filter);
      if (s.raymarch.msCache.filter > 8)
        ctx.fail(mc.keyOf("filter"), "must be at most 8 (columns), got " + formatNumber(s.raymarch.msCache.filter));
      s.raymarch.msCache.filterTolerance = mc.getFloat("filterTolerance", s.raymarch.msCache.filterTolerance);
      if (!(s.raymarch.msCache.filterTolerance > 0))
        ctx.fail(mc.keyOf("filterTolerance"),
                 "must be positive, got " + formatNumber(s.raymarch.msCache.filterTolerance));
      s.raymarch.msCache.filterTwicing = mc.getBool("filterTwicing", s.raymarch.msCache.filterTwicing);
      if (s.raymarch.msCache.filterTwicing && view && !(s.raymarch.msCache.filter > 0))
        ctx.fail(mc.keyOf("filterTwicing"), "needs filter > 0 (it filters the filter's residual)");
      s.raymarch.msCache.allocation = readEnum(mc, "allocation", kMsCacheAllocations, s.raymarch.msCache.allocation);
      s.raymarch.msCache.guide = readNonNegative(mc, "guide", s.raymarch.msCache.guide);
      if (!(s.raymarch.msCache.guide < 1))
        ctx.fail(mc.keyOf("guide"), "must be below 1 (the phase function's share covers every direction), got " +
                                        formatNumber(s.raymarch.msCache.guide));
      else if (s.raymarch.msCache.guide > 0 && !view && s.raymarch.msCache.closure != MsCacheClosure::Camera)
        ctx.fail(mc.keyOf("guide"), "needs closure \"camera\" or layout \"view\" (the uniform closures draw no "
                                    "phase-function directions to guide)");
      s.raymarch.msCache.paths = readInt(mc, "paths", s.raymarch.msCache.paths, 1, 1 << 20);
      s.raymarch.msCache.pathsPerLaunch = readInt(mc, "pathsPerLaunch", s.raymarch.msCache.pathsPerLaunch, 1, 1 << 20);
      mc.reportUnknown();
    }
    m.reportUnknown();
  }
  if (const json* v = r.find("lobe")) {
    ObjectReader l(ctx, *v, r.keyOf("lobe"));
    s.lobe.variant = readEnum(l, "variant", kLobeVariants, s.lobe.variant);
    // The corrected estimator has no first-hit search and no fixed depth (lobe.h, C2); the first
    // hit's step count still marches an emitting medium's light in both variants.
    if (s.lobe.variant == LobeVariant::Corrected)
      for (const char* key : {"depthFactor", "firstHitSteps"})
        if (l.find(key) && !(emits && std::string(key) == "firstHitSteps"))
          ctx.warn(l.keyOf(key), "applies to variant \"eq7\"; \"corrected\" ignores it");
    s.lobe.depthFactor = readNonNegative(l, "depthFactor", s.lobe.depthFactor);
    s.lobe.lobePoints = readInt(l, "lobePoints", s.lobe.lobePoints, 1);
    s.lobe.lobeRadius = readNonNegative(l, "lobeRadius", s.lobe.lobeRadius);
    s.lobe.shadowSteps = readInt(l, "shadowSteps", s.lobe.shadowSteps, 1);
    s.lobe.firstHitSteps = readInt(l, "firstHitSteps", s.lobe.firstHitSteps, 1);
    if (l.find("viewSteps")) s.lobe.viewSteps = readInt(l, "viewSteps", 1, 1);
    s.lobe.minTransmittance = readMinTransmittance(l, s.lobe.minTransmittance);
    s.lobe.areaLightSamples = readInt(l, "areaLightSamples", s.lobe.areaLightSamples, 1, 16);
    s.lobe.areaLightPhase = readAreaLightPhase(l, s.lobe.areaLightPhase);
    if (l.find("shadowAreaSamples")) s.lobe.shadowAreaSamples = readInt(l, "shadowAreaSamples", 1, 1, 16);
    l.reportUnknown();
  }
  if (const json* v = r.find("lightCache")) {
    ObjectReader c(ctx, *v, r.keyOf("lightCache"));
    if (const json* res = c.find("resolution")) {
      if (res->is_string() && res->get<std::string>() == "auto")
        s.lightCache.resolution = kLightCacheAuto;
      else if (res->is_number())
        s.lightCache.resolution = static_cast<int>(
            checkIntRange(ctx, c.keyOf("resolution"), toInteger(ctx, *res, c.keyOf("resolution")), 0, 1024));
      else
        ctx.fail(c.keyOf("resolution"), "expected \"auto\" or a number of cells (0 = off), got " +
                                            (res->is_string() ? "\"" + res->get<std::string>() + "\"" : std::string(res->type_name())));
    }
    c.reportUnknown();
  }
  r.reportUnknown();
  return s;
}

void readMaterials(JsonContext& ctx, ObjectReader& root, Scene& scene) {
  const json& list = toArray(ctx, root.require("materials"), "materials");
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

std::string parseMessage(const json::exception& e) {
  // Drop nlohmann's "[json.exception.parse_error.101] " tag; keep its line/column text.
  const std::string what = e.what();
  const size_t tag = what.find("] ");
  return tag == std::string::npos ? what : what.substr(tag + 2);
}

}  // namespace

Scene parseScene(const std::string& jsonText, const std::string& path, const std::vector<std::string>& overrides,
                 std::set<std::string>* keysAsked) {
  Scene scene;
  scene.sourcePath = path;
  scene.overrides = overrides;
  JsonContext ctx{path, &scene.warnings, {}, keysAsked, {}};

  json doc;
  try {
    // Scenes nest 5 levels (primitives[i].transform.position[j]). nlohmann's copy and dump recurse
    // once per level, so a document nested thousands deep would overflow the stack later on.
    doc = json::parse(jsonText, [&ctx](int depth, json::parse_event_t, json&) {
      if (depth > kMaxJsonDepth)
        ctx.fail("", "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels (a scene needs 5)");
      return true;
    });
  } catch (const json::exception& e) {  // parse_error, and out_of_range for 1e999
    ctx.fail("", "invalid JSON: " + parseMessage(e));
  }
  if (!doc.is_object()) ctx.fail("", std::string("expected a JSON object at the top level, got ") + doc.type_name());

  std::vector<std::pair<std::string, std::string>> overridden;  // (as written, loader key)
  for (const std::string& spec : overrides)
    overridden.emplace_back(spec.substr(0, spec.find('=')), applyOverride(doc, spec, path));
  scene.document = doc;

  ObjectReader root(ctx, doc, "");
  readMaterials(ctx, root, scene);
  readPrimitives(ctx, root, scene);
  scene.camera = readCamera(ctx, root.require("camera"), "camera");
  bool emits = false;
  for (const Material& m : scene.materials) emits = emits || m.emission.kind != EmissionKind::None;
  scene.renderer = readRenderer(ctx, root.require("renderer"), "renderer", emits);
  scene.background = root.getVec3("background", scene.background);
  checkNonNegative(ctx, "background", scene.background);
  root.reportUnknown();

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

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(path, ec)) throw inputError(path, "", "cannot open scene file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseScene(text.str(), path, overrides);
}

bool toneMappingFromName(const std::string& name, ToneMapping* out) {
  for (const auto& [text, value] : kToneMappings)
    if (text == name) {
      *out = value;
      return true;
    }
  return false;
}

const char* toneMappingName(ToneMapping t) {
  switch (t) {
    case ToneMapping::None: return "none";
    case ToneMapping::Reinhard: return "reinhard";
    case ToneMapping::Aces: return "aces";
  }
  return "none";
}

const char* gridStorageName(GridStorage s) {
  for (const auto& [name, value] : kGridStorages)
    if (value == s) return name;
  return "auto";
}

const char* algorithmName(Algorithm a) {
  switch (a) {
    case Algorithm::Pathtrace: return "pathtrace";
    case Algorithm::Raymarch: return "raymarch";
    case Algorithm::Lobe: return "lobe";
  }
  throw std::logic_error("algorithmName: not an Algorithm");
}

bool isRealtime(Algorithm a) {
  switch (a) {
    case Algorithm::Pathtrace: return false;
    case Algorithm::Raymarch:
    case Algorithm::Lobe: return true;
  }
  throw std::logic_error("isRealtime: not an Algorithm");
}

bool algorithmFromName(const std::string& name, Algorithm* out) {
  for (const auto& [n, a] : kAlgorithms)
    if (name == n) {
      *out = a;
      return true;
    }
  return false;
}

}  // namespace narval
