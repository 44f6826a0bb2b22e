// scene.h: the scene as loaded from JSON (dissertation Listing 4.1 plus DESIGN.md's extensions).
// Plain data: validation happens in the loader (scene_load.cpp), which throws narval::InputError.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "image/display_transform.h"
#include "shared/grid_storage_kinds.h"
#include "shared/light_kinds.h"
#include "shared/phase_kinds.h"

namespace narval {

using Vec3f = std::array<float, 3>;

struct Transform {
  Vec3f position{0, 0, 0};
  Vec3f scale{1, 1, 1};
  Vec3f rotation{0, 0, 0};  // degrees, applied X then Y then Z: M = T · Rz · Ry · Rx · S
};

enum class MaterialType { Emitter, Volume };
enum class GridSpace { Unit, File };

// A volume's emission (pbrt-v4's model; kernels/shared/emission.h): σa(x)·Le(x) per unit length, Le =
// color · scale · v(x) (Color; v: grid `grid`, else 1) or scale · B((v(x) − temperatureOffset) · temperatureScale)
// (Blackbody; v: temperature grid `grid`, else `temperature` K; B: host/colour/blackbody.h, 0 at or below 100 K).
enum class EmissionKind { None, Color, Blackbody };
struct Emission {
  EmissionKind kind = EmissionKind::None;
  std::string grid;          // the emission or temperature grid's name in the volume's file; empty: none
  Vec3f color{1, 1, 1};      // Color only
  float scale = 1.0f;
  float temperature = 0.0f;  // kelvin, Blackbody without a grid
  float temperatureOffset = 0.0f, temperatureScale = 1.0f;  // Blackbody with a grid
};

struct Material {
  std::string name;
  MaterialType type = MaterialType::Emitter;
  Vec3f albedo{0, 0, 0};  // emitter: radiance (rectangle) or intensity W/sr (point)
  // volume
  Vec3f scattering{0, 0, 0};
  Vec3f absorption{0, 0, 0};
  int phase = PHASE_ISOTROPIC;  // a phase_kinds.h id
  float phaseParameter = 0.0f;  // the kind's one parameter (its registry key: HG's "g"), as loaded
  std::string path;          // resolved against the scene file's folder; empty: homogeneous
  std::string gridName = "density";
  float density = 1.0f;      // multiplier D
  GridSpace gridSpace = GridSpace::Unit;
  Emission emission;
};

enum class PrimitiveType { Volume, Light };

struct Primitive {
  std::string name;
  PrimitiveType type = PrimitiveType::Volume;
  int lightKind = -1;  // a light_kinds.h id when type is Light (its "type" names the kind)
  Vec3f lightVector{0, 0, 0};  // the kind's own vector key (light_kinds.h), as loaded
  float lightParameter = 0.0f;  // the kind's own number key, as loaded
  Transform transform;
  std::string materialName;
  int materialIndex = -1;  // resolved by the loader
};

struct Camera {
  Vec3f position{0, 0, -5};
  Vec3f lookAt{0, 0, 0};
  Vec3f up{0, 1, 0};
  float vfov = 45.0f;        // degrees
  float aperture = 0.0f;     // lens radius, world units (0: pinhole)
  float focus = 1.0f;        // focus distance, world units
  float speed = 1.0f;        // viewer navigation only
};

// How the density grid lives on the device (kernels/shared/grid.h, grid_storage_kinds.h): a 3D image
// (hardware sampler), a float buffer (grid_trilinear), or sparse 8³ bricks (same filter, bit for bit; only
// bricks holding density take memory). Auto, resolved with its reasons by render/device_grid.h: the buffer
// on CPUs and without image support, else the image; Bricks, with a warning, when that cannot hold the grid.
#define GRID_STORAGE_ENUMERATOR(name, cxx, define) cxx,
enum class GridStorage { Auto, GRID_STORAGE_KINDS(GRID_STORAGE_ENUMERATOR) };
#undef GRID_STORAGE_ENUMERATOR

// What the ray marcher adds for light scattered more than once: nothing, Wrenninge's octaves, or
// the path-traced multiple-scattering cache (kernels/shared/ms_cache.h).
enum class MultipleScattering { None, Octaves, Cache };

// How the real-time kernels integrate the phase function over a rectangle light
// (kernels/shared/march.h, march_light_phase): K×K points (areaLightSamples; 1, the centre, is the
// dissertation's), or exactly over the light's solid angle (kernels/shared/phase_polygon.h).
enum class AreaLightPhase { Points, Exact };

// How a rectangle light's shadow weights its K×K points (kernels/shared/march.h, march_light_column): by
// the light reaching a point, or by that scattered to the camera (the light cache then follows the camera).
enum class ShadowWeighting { Area, Phase };

// What the cache's two moments (directional average R, first moment b) say about the in-scattering in a
// direction (kernels/shared/ms_cache.h, "Closure"): the truncated linear expansion, or none: the paths aim
// at the camera.
enum class MsCacheClosure { Linear, Camera };
// Its nodes: a grid over the medium's box, or image columns with nodes along their optical depth from the
// camera (kernels/shared/ms_cache_view.h).
enum class MsCacheLayout { Grid, View };
// renderer.raymarch.quality: what the multiple-scattering cache's defaults aim for. Each sets the
// march's steps (with the cache on), the cache's paths per node and, for msCache.tile "auto", how
// many columns a CPU device gets (realtime_params.h, msCacheTile); explicit keys override it.
enum class RaymarchQuality { Draft, Interactive, High };
struct RaymarchQualityDefaults {
  int steps, paths;
  double cpuColumns;  // the most view-cache columns on a CPU device (a GPU takes a column a pixel)
};
RaymarchQualityDefaults raymarchQualityDefaults(RaymarchQuality q);

constexpr int kMsCacheTileAuto = 0;
struct MsCacheSettings {
  MsCacheClosure closure = MsCacheClosure::Linear;
  MsCacheLayout layout = MsCacheLayout::View;
  int resolution = 32;      // grid: cells on the medium box's longest axis (measured: bench/RESULTS.md)
  int tile = kMsCacheTileAuto;  // view: pixels per column side (auto: realtime_params.h, msCacheTile)
  int slices = 8;           // view: nodes per column
  // The lights' unscattered light: added by the march (false) or held by the cache with the rest
  // (kernels/shared/ms_cache.h, "Direct"; closure "camera" or layout "view" only).
  bool direct = true;  // the default where it applies (layout view or closure camera), else false
  // view: the node filter (kernels/shared/ms_cache_filter.h): σ_s in columns (0: off).
  float filter = 1.5f;
  // The filter's residual filtered and added back (ms_cache_filter.h, "Twicing"); default: filter > 0.
  bool filterTwicing = true;
  // Paths per node; default: the quality's.
  int paths = 100;
};

struct RaymarchSettings {
  RaymarchQuality quality = RaymarchQuality::Interactive;
  int steps = 60;  // the dissertation's march; with the cache on, the quality's
  int shadowSteps = 10;
  // Multiple-scattering octaves (Wrenninge et al. 2013; Hillaire 2016): octave i uses σs·aⁱ,
  // σt·bⁱ and g·cⁱ. 1 = plain single scattering. a <= b keeps it energy-conserving.
  int octaves = 1;
  float octaveScattering = 0.5f;  // a
  float octaveExtinction = 0.5f;  // b
  float octavePhase = 0.5f;       // c
  // The view march stops once every channel's transmittance is below this (error bound: raymarch.h); 0: never.
  float minTransmittance = 1e-3f;
  // Absent from the scene: Octaves when octaves > 1, else Cache (None is the dissertation's march).
  MultipleScattering multipleScattering = MultipleScattering::Cache;
  MsCacheSettings msCache;
  // A rectangle light is K×K points for the phase and 1/d² (march.h, march_light_phase_sum: K² evaluations a
  // sample; 1 = its centre, the dissertation's) and for its shadow (march_light_column: light cache build only).
  int areaLightSamples = 1;
  AreaLightPhase areaLightPhase = AreaLightPhase::Points;
  int shadowAreaSamples = 4;
  ShadowWeighting shadowWeighting = ShadowWeighting::Area;
};

// Next-event estimation (kernels/shared/light_select.h): a shadow ray to every light at each scattering
// event, or to one picked by power or by estimated fluence over the medium (render/light_selection.h).
enum class LightSampling { All, Power, Fluence };

struct PathtraceSettings {
  LightSampling lightSampling = LightSampling::All;
  // Ratio-tracked shadow rays play Russian roulette below this transmittance in every channel (tracking.h);
  // 0 = never. pbrt-v4's threshold; more efficient on both clouds (bench/pathtrace_sampling.py, bench/RESULTS.md).
  float shadowRoulette = 0.05f;
};

// The Lobe Estimator: the dissertation's Eq. 7, or the corrected estimator (kernels/shared/lobe.h).
enum class LobeVariant { Eq7, Corrected };

// What renders the scene (renderer.algorithm): the path tracer, the ray marcher or the Lobe Estimator.
// Columns: enumerator; name (scene key value, name in outputs, real-time kernel kernels/NAME.cl `NAME`);
// whether it renders frames (one launch each, no samples to accumulate: render/realtime_renderer.h).
#define ALGORITHMS(X)                  \
  X(Pathtrace, "pathtrace", false)      \
  X(Raymarch, "raymarch", true)         \
  X(Lobe, "lobe", true)
#define ALGORITHM_ENUMERATOR(cxx, name, realtime) cxx,
enum class Algorithm { ALGORITHMS(ALGORITHM_ENUMERATOR) };
#undef ALGORITHM_ENUMERATOR
// The ALGORITHMS table's name (scene key value, name in outputs) and frames column.
const char* algorithmName(Algorithm a);
bool isRealtime(Algorithm a);
// The algorithm called `name` (algorithmName's inverse); false, *out untouched, for any other name.
bool algorithmFromName(const std::string& name, Algorithm* out);

struct LobeSettings {
  LobeVariant variant = LobeVariant::Corrected;  // eq7: the dissertation's, as it records it
  float depthFactor = 20.0f;
  int lobePoints = 30;
  float lobeRadius = 1.0f;       // eq7: world units; corrected: mean free paths of unit density
  int shadowSteps = 100;
  int firstHitSteps = 60;        // first-hit search samples (then 6 bisections); also the emission march's
  int viewSteps = 0;             // samples of each transmittance from the first hit to a lobe point
                                 // (corrected: of its one view march); 0 = the variant's: eq7 24, corrected 16
  float minTransmittance = 1e-3f;  // those transmittances stop below it (lobe.h: error < it · L_b)
  int areaLightSamples = 1;        // as the ray marcher's
  AreaLightPhase areaLightPhase = AreaLightPhase::Points;  // as the ray marcher's
  int shadowAreaSamples = 0;       // as the ray marcher's; 0 = the variant's: eq7 1, corrected 4
};
// What the lobe kernels take for the two keys whose default is the variant's.
int lobeViewSteps(const LobeSettings& l);
int lobeShadowAreaSamples(const LobeSettings& l);

// The light-transmittance cache of the real-time kernels (kernels/shared/light_cache.h).
constexpr int kLightCacheAuto = -1;
struct LightCacheSettings {
  int resolution = kLightCacheAuto;  // cells on the medium box's longest axis; 0 = off; auto: measured
};

struct RendererSettings {
  int width = 1200, height = 600;
  int spp = 1000;
  int bounces = 3;
  bool hdr = true;
  ToneMapping toneMapping = ToneMapping::Aces;  // JSON true -> Aces, false -> None, or a name
  float exposure = 0.0f;                        // stops
  Algorithm algorithm = Algorithm::Pathtrace;
  uint32_t seed = 0;
  GridStorage storage = GridStorage::Auto;
  PathtraceSettings pathtrace;
  RaymarchSettings raymarch;
  LobeSettings lobe;
  LightCacheSettings lightCache;
  // The ray marcher with its multiple-scattering cache: what traces bounces and builds a cache.
  bool drawsMsCache() const {
    return algorithm == Algorithm::Raymarch && raymarch.multipleScattering == MultipleScattering::Cache;
  }
};

struct Scene {
  std::string sourcePath;  // the JSON file this came from
  std::vector<Material> materials;
  std::vector<Primitive> primitives;
  Camera camera;
  RendererSettings renderer;
  Vec3f background{0, 0, 0};
  std::vector<std::string> warnings;  // unknown keys and other non-fatal findings
  std::vector<std::string> overrides;  // the --set PATH=VALUE strings applied, in order
  // The scene as rendered: the file with the overrides applied and every default the loader took
  // written out (`narval scene --resolved`); it reads back to the same settings.
  nlohmann::json document;
};

// Loads and validates a scene. `overrides` are "dotted.path=value" strings (--set) applied to the
// JSON before validation. Throws InputError ("FILE: KEY: what is wrong") on any bad input.
Scene loadScene(const std::string& path, const std::vector<std::string>& overrides = {});
// The same from JSON text in memory; `path` names it in messages and anchors relative paths.
Scene parseScene(const std::string& jsonText, const std::string& path,
                 const std::vector<std::string>& overrides = {});

// One key of the scene format as the loader reads it ("materials[].g": indices dropped), learnt by
// reading scenes that between them take every branch of the loader (scene_keys.cpp).
struct SceneKey {
  std::string key, type, range;
  std::vector<nlohmann::json> defaults;  // the distinct defaults taken (more than one: it depends on another key)
  bool required = false;
};
std::vector<SceneKey> sceneKeyTable();

// "auto", "image", "buffer" or "bricks": the scene file's spelling.
const char* gridStorageName(GridStorage s);

}  // namespace narval
