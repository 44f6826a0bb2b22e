// renderer_load.cpp: the scene's "renderer" object, a reader per section (docs/scene-format.md).
#include "scene/renderer_load.h"

#include <cstdint>
#include <limits>
#include <stdexcept>

namespace narval {
namespace scene_detail {
namespace {

constexpr int64_t kMaxImageSide = 16384;  // keeps width * height well inside an int

#define GRID_STORAGE_NAME(name, cxx, define) {name, GridStorage::cxx},
const EnumNames<GridStorage> kGridStorages = {{"auto", GridStorage::Auto}, GRID_STORAGE_KINDS(GRID_STORAGE_NAME)};
#undef GRID_STORAGE_NAME
const EnumNames<MultipleScattering> kMultipleScattering = {{"none", MultipleScattering::None},
                                                           {"octaves", MultipleScattering::Octaves},
                                                           {"cache", MultipleScattering::Cache}};
const EnumNames<LightSampling> kLightSamplings = {
    {"all", LightSampling::All}, {"power", LightSampling::Power}, {"fluence", LightSampling::Fluence}};
const EnumNames<AreaLightPhase> kAreaLightPhases = {{"points", AreaLightPhase::Points},
                                                     {"exact", AreaLightPhase::Exact}};
const EnumNames<MsCacheClosure> kMsCacheClosures = {
    {"linear", MsCacheClosure::Linear}, {"camera", MsCacheClosure::Camera}};
const EnumNames<ShadowWeighting> kShadowWeightings = {{"area", ShadowWeighting::Area},
                                                      {"phase", ShadowWeighting::Phase}};
const EnumNames<MsCacheLayout> kMsCacheLayouts = {{"grid", MsCacheLayout::Grid}, {"view", MsCacheLayout::View}};
const EnumNames<RaymarchQuality> kRaymarchQualities = {{"draft", RaymarchQuality::Draft},
                                                        {"interactive", RaymarchQuality::Interactive},
                                                        {"high", RaymarchQuality::High}};
const EnumNames<LobeVariant> kLobeVariants = {{"eq7", LobeVariant::Eq7}, {"corrected", LobeVariant::Corrected}};
#define ALGORITHM_NAME(cxx, name, realtime) {name, Algorithm::cxx},
const EnumNames<Algorithm> kAlgorithms = {ALGORITHMS(ALGORITHM_NAME)};
#undef ALGORITHM_NAME

const json kNoKeys = json::object();

// An integer in [lo, hi] or "auto" (autoValue): `what` names the integer in the message, `note` follows
// its range ("(0 = off)").
int readAutoInt(ObjectReader& r, const std::string& name, int current, int autoValue, int64_t lo, int64_t hi,
                const std::string& what, const std::string& note) {
  r.note(name, "integer or string", current == autoValue ? json("auto") : json(current),
         "\"auto\", or [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" + note);
  const json* v = r.find(name);
  if (!v) return current;
  if (v->is_string() && v->get<std::string>() == "auto") return autoValue;
  JsonContext& ctx = r.context();
  const std::string key = r.keyOf(name);
  if (v->is_number()) return static_cast<int>(checkIntRange(ctx, key, toInteger(ctx, *v, key), lo, hi));
  ctx.fail(key, "expected \"auto\" or " + what + note + ", got " +
                    (v->is_string() ? "\"" + v->get<std::string>() + "\"" : std::string(v->type_name())));
}

// A section of the renderer object, read whether given or not: every key of it gets its default
// (KeyRecord), which a resolved scene writes out.
const json& section(ObjectReader& r, const std::string& name) {
  const json* v = r.find(name);
  r.note(name, "object", nullptr);
  return v ? *v : kNoKeys;
}

// Sections set for an algorithm that does not read them: named, since nothing would change.
void warnSectionsThatDoNotApply(const JsonContext& ctx, const ObjectReader& r, const RendererSettings& s) {
  const std::string algorithm = algorithmName(s.algorithm);
  const bool cache = s.drawsMsCache();
  auto ignored = [&](const char* name, bool applies, const std::string& to) {
    if (!applies && ctx.changedUnder(r.keyOf(name)))
      ctx.warn(r.keyOf(name), "applies to " + to + "; algorithm \"" + algorithm + "\" ignores it");
  };
  ignored("pathtrace", s.algorithm == Algorithm::Pathtrace || cache,
          "the path tracer and the ray marcher's multiple-scattering cache");
  ignored("raymarch", s.algorithm == Algorithm::Raymarch, "algorithm \"raymarch\"");
  ignored("lobe", s.algorithm == Algorithm::Lobe, "algorithm \"lobe\"");
  ignored("lightCache", isRealtime(s.algorithm), "the real-time algorithms");
}

// A transmittance below which a march stops: [0, 1) (0 = never stops; 1 would stop at once).
float readMinTransmittance(ObjectReader& r, float fallback) {
  const float v = r.getFloat("minTransmittance", fallback);
  r.noteRange("minTransmittance", "[0, 1)");
  if (!(v >= 0 && v < 1))
    r.context().fail(r.keyOf("minTransmittance"), "must be in [0, 1) (0 = never stop), got " + formatNumber(v));
  return v;
}

// renderer.raymarch/lobe.areaLightPhase; with "exact", a given areaLightSamples is said to be ignored.
AreaLightPhase readAreaLightPhase(ObjectReader& r, AreaLightPhase fallback) {
  const AreaLightPhase v = readEnum(r, "areaLightPhase", kAreaLightPhases, fallback);
  if (v == AreaLightPhase::Exact)
    r.context().warnIfChanged(r.keyOf("areaLightSamples"),
                              "applies to areaLightPhase \"points\"; \"exact\" ignores it");
  return v;
}

ToneMapping readToneMapping(ObjectReader& r, ToneMapping fallback) {
  const json* v = r.find("toneMapping");
  r.note("toneMapping", "boolean or string", enumName(kToneMappingNames, fallback),
         "true (aces), false (none), " + enumNameList(kToneMappingNames));
  if (!v) return fallback;
  // Listing 4.1 writes a boolean; a name picks the operator.
  if (v->is_boolean()) return v->get<bool>() ? ToneMapping::Aces : ToneMapping::None;
  if (!v->is_string())
    r.context().fail(r.keyOf("toneMapping"), "expected a boolean or one of " + enumNameList(kToneMappingNames) +
                                                 ", got " + v->type_name());
  return toEnum(r.context(), *v, r.keyOf("toneMapping"), kToneMappingNames);
}

void readResolution(ObjectReader& r, RendererSettings& s) {
  const std::string key = r.keyOf("resolution");
  const json& v = r.require("resolution");
  r.note("resolution", "[2 integers]", nullptr, "[1, " + std::to_string(kMaxImageSide) + "] each");
  if (!v.is_array() || v.size() != 2)
    r.context().fail(key, std::string("expected an array of 2 integers [width, height], got ") +
                              (v.is_array() ? std::to_string(v.size()) + " elements" : v.type_name()));
  int* sides[2] = {&s.width, &s.height};
  for (size_t i = 0; i < 2; ++i)
    *sides[i] = static_cast<int>(checkIntRange(r.context(), indexKey(key, i),
                                               toInteger(r.context(), v[i], indexKey(key, i)), 1, kMaxImageSide));
}

PathtraceSettings readPathtrace(JsonContext& ctx, const json& value, const std::string& key, PathtraceSettings s) {
  ObjectReader p(ctx, value, key);
  s.lightSampling = readEnum(p, "lightSampling", kLightSamplings, s.lightSampling);
  s.shadowRoulette = readUnitInterval(p, "shadowRoulette", s.shadowRoulette);
  p.reportUnknown();
  return s;
}

MsCacheSettings readMsCache(JsonContext& ctx, const json& value, const std::string& key, MsCacheSettings s) {
  ObjectReader mc(ctx, value, key);
  s.layout = readEnum(mc, "layout", kMsCacheLayouts, s.layout);
  const bool view = s.layout == MsCacheLayout::View;
  s.closure = readEnum(mc, "closure", kMsCacheClosures, view ? MsCacheClosure::Camera : s.closure);
  if (view && s.closure != MsCacheClosure::Camera)
    ctx.fail(mc.keyOf("closure"), "must be \"camera\" with layout \"view\" (its paths aim at the camera)");
  s.resolution = readInt(mc, "resolution", s.resolution, 1, 256);
  s.tile = readAutoInt(mc, "tile", s.tile, kMsCacheTileAuto, 1, 256, "pixels per column side", "");
  // The direct light in the cache where a node can hold it (the camera's direction), else the march's.
  s.direct = mc.getBool("direct", view || s.closure == MsCacheClosure::Camera);
  if (s.direct && !view && s.closure != MsCacheClosure::Camera)
    ctx.fail(mc.keyOf("direct"), "needs closure \"camera\" or layout \"view\" (a node must hold the light "
                                 "scattered towards the camera)");
  s.slices = readInt(mc, "slices", s.slices, 2, 64);
  s.filter = readNonNegative(mc, "filter", s.filter);
  if (s.filter > 8) ctx.fail(mc.keyOf("filter"), "must be at most 8 (columns), got " + formatNumber(s.filter));
  mc.noteRange("filter", "[0, 8]");
  s.filterTwicing = mc.getBool("filterTwicing", s.filter > 0);  // on wherever the filter is (bench/RESULTS.md)
  if (s.filterTwicing && view && !(s.filter > 0))
    ctx.fail(mc.keyOf("filterTwicing"), "needs filter > 0 (it filters the filter's residual)");
  s.paths = readInt(mc, "paths", s.paths, 1, 1 << 20);
  if (view) ctx.warnIfChanged(mc.keyOf("resolution"), "applies to layout \"grid\"; \"view\" ignores it");
  for (const char* own : {"tile", "slices", "filter", "filterTwicing"})
    if (!view) ctx.warnIfChanged(mc.keyOf(own), "applies to layout \"view\"; \"grid\" ignores it");
  mc.reportUnknown();
  return s;
}

RaymarchSettings readRaymarch(JsonContext& ctx, const json& value, const std::string& key, RaymarchSettings s) {
  ObjectReader m(ctx, value, key);
  s.quality = readEnum(m, "quality", kRaymarchQualities, s.quality);
  const RaymarchQualityDefaults quality = raymarchQualityDefaults(s.quality);
  s.octaves = readInt(m, "octaves", s.octaves, 1, 16);
  s.multipleScattering = readEnum(m, "multipleScattering", kMultipleScattering,
                                  s.octaves > 1 ? MultipleScattering::Octaves : MultipleScattering::Cache);
  const bool cache = s.multipleScattering == MultipleScattering::Cache;
  s.steps = readInt(m, "steps", cache ? quality.steps : s.steps, 1);
  s.shadowSteps = readInt(m, "shadowSteps", s.shadowSteps, 1);
  s.octaveScattering = readUnitInterval(m, "octaveScattering", s.octaveScattering);
  s.octaveExtinction = readUnitInterval(m, "octaveExtinction", s.octaveExtinction);
  s.octavePhase = readUnitInterval(m, "octavePhase", s.octavePhase);
  if (s.octaveScattering > s.octaveExtinction)
    ctx.fail(m.keyOf("octaveScattering"),
             "must not exceed octaveExtinction (" + formatNumber(s.octaveExtinction) + ") or the octaves add energy");
  s.minTransmittance = readMinTransmittance(m, s.minTransmittance);
  s.areaLightSamples = readInt(m, "areaLightSamples", s.areaLightSamples, 1, 16);
  s.areaLightPhase = readAreaLightPhase(m, s.areaLightPhase);
  s.shadowAreaSamples = readInt(m, "shadowAreaSamples", s.shadowAreaSamples, 1, 16);
  s.shadowWeighting = readEnum(m, "shadowWeighting", kShadowWeightings, s.shadowWeighting);
  if (s.octaves > 1 && s.multipleScattering != MultipleScattering::Octaves)
    ctx.fail(m.keyOf("octaves"), "applies only with multipleScattering \"octaves\"");
  const char* ms = enumName(kMultipleScattering, s.multipleScattering);
  if (s.multipleScattering != MultipleScattering::Octaves)
    for (const char* k : {"octaveScattering", "octaveExtinction", "octavePhase"})
      ctx.warnIfChanged(m.keyOf(k),
                        std::string("applies to multipleScattering \"octaves\"; \"") + ms + "\" ignores it");
  s.msCache.paths = quality.paths;
  s.msCache = readMsCache(ctx, section(m, "msCache"), m.keyOf("msCache"), s.msCache);
  if (!cache && ctx.changedUnder(m.keyOf("msCache")))
    ctx.warn(m.keyOf("msCache"), std::string("applies to multipleScattering \"cache\"; \"") + ms + "\" ignores it");
  m.reportUnknown();
  return s;
}

// `emits`: some material emits (firstHitSteps then serves both variants).
LobeSettings readLobe(JsonContext& ctx, const json& value, const std::string& key, bool emits, LobeSettings s) {
  ObjectReader l(ctx, value, key);
  s.variant = readEnum(l, "variant", kLobeVariants, s.variant);
  s.depthFactor = readNonNegative(l, "depthFactor", s.depthFactor);
  s.lobePoints = readInt(l, "lobePoints", s.lobePoints, 1);
  s.lobeRadius = readNonNegative(l, "lobeRadius", s.lobeRadius);
  s.shadowSteps = readInt(l, "shadowSteps", s.shadowSteps, 1);
  s.firstHitSteps = readInt(l, "firstHitSteps", s.firstHitSteps, 1);
  // The corrected estimator has no first-hit search and no fixed depth (lobe.h, C2); the first
  // hit's step count still marches an emitting medium's light in both variants.
  if (s.variant == LobeVariant::Corrected)
    for (const char* k : {"depthFactor", "firstHitSteps"})
      if (!(emits && std::string(k) == "firstHitSteps"))
        ctx.warnIfChanged(l.keyOf(k), "applies to variant \"eq7\"; \"corrected\" ignores it");
  // Left out, these two take the variant's default (0 here); a resolved scene writes that value.
  const int viewSteps = lobeViewSteps(s), shadowAreaSamples = lobeShadowAreaSamples(s);
  if (l.find("viewSteps")) s.viewSteps = readInt(l, "viewSteps", 1, 1);
  l.note("viewSteps", "integer", viewSteps, ">= 1");
  s.minTransmittance = readMinTransmittance(l, s.minTransmittance);
  s.areaLightSamples = readInt(l, "areaLightSamples", s.areaLightSamples, 1, 16);
  s.areaLightPhase = readAreaLightPhase(l, s.areaLightPhase);
  if (l.find("shadowAreaSamples")) s.shadowAreaSamples = readInt(l, "shadowAreaSamples", 1, 1, 16);
  l.note("shadowAreaSamples", "integer", shadowAreaSamples, "[1, 16]");
  l.reportUnknown();
  return s;
}

LightCacheSettings readLightCache(JsonContext& ctx, const json& value, const std::string& key, LightCacheSettings s) {
  ObjectReader c(ctx, value, key);
  s.resolution = readAutoInt(c, "resolution", s.resolution, kLightCacheAuto, 0, 1024, "a number of cells", " (0 = off)");
  c.reportUnknown();
  return s;
}

}  // namespace

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
  r.noteRange("seed", "[0, " + std::to_string(std::numeric_limits<uint32_t>::max()) + "]");
  s.pathtrace = readPathtrace(ctx, section(r, "pathtrace"), r.keyOf("pathtrace"), s.pathtrace);
  s.raymarch = readRaymarch(ctx, section(r, "raymarch"), r.keyOf("raymarch"), s.raymarch);
  s.lobe = readLobe(ctx, section(r, "lobe"), r.keyOf("lobe"), emits, s.lobe);
  s.lightCache = readLightCache(ctx, section(r, "lightCache"), r.keyOf("lightCache"), s.lightCache);
  warnSectionsThatDoNotApply(ctx, r, s);
  r.reportUnknown();
  return s;
}

}  // namespace scene_detail

using scene_detail::kAlgorithms;
using scene_detail::kGridStorages;

const char* gridStorageName(GridStorage s) { return enumName(kGridStorages, s); }

const char* algorithmName(Algorithm a) { return enumName(kAlgorithms, a); }

bool isRealtime(Algorithm a) {
#define ALGORITHM_REALTIME(cxx, name, realtime) \
  case Algorithm::cxx: return realtime;
  switch (a) { ALGORITHMS(ALGORITHM_REALTIME) }
#undef ALGORITHM_REALTIME
  throw std::logic_error("isRealtime: not an Algorithm");
}

bool algorithmFromName(const std::string& name, Algorithm* out) { return enumFromName(kAlgorithms, name, out); }

namespace {
// A lobe key the scene left out (0) takes its variant's default; eq7's are the dissertation's.
int lobeDefault(const LobeSettings& l, int value, int eq7, int corrected) {
  if (value > 0) return value;
  switch (l.variant) {
    case LobeVariant::Eq7: return eq7;
    case LobeVariant::Corrected: return corrected;
  }
  throw std::logic_error("lobeDefault: not a LobeVariant");
}
}  // namespace

int lobeViewSteps(const LobeSettings& l) { return lobeDefault(l, l.viewSteps, 24, 16); }
int lobeShadowAreaSamples(const LobeSettings& l) { return lobeDefault(l, l.shadowAreaSamples, 1, 4); }

RaymarchQualityDefaults raymarchQualityDefaults(RaymarchQuality q) {
  switch (q) {  // the interactive one is the cloud's and the smoke's pick (bench/RESULTS.md)
    case RaymarchQuality::Draft: return {20, 32, 160.0 * 120};
    case RaymarchQuality::Interactive: return {30, 100, 320.0 * 240};
    case RaymarchQuality::High: return {60, 400, 640.0 * 480};
  }
  throw std::logic_error("raymarchQualityDefaults: unknown quality");
}

}  // namespace narval
