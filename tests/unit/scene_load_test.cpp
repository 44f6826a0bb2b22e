// scene_load_test.cpp: the scene loader against Listing 4.1, its defaults, every error message
// (exactly, since users and scripts read them), warnings, --set overrides and path resolution.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "render/render_exr.h"
#include "scene/scene.h"
#include "test_support.h"

namespace narval {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

using test::listing41Json;
using test::readFile;
using test::ScopedEnv;

// The smallest valid scene: a light and a homogeneous medium (no file to find).
json minimalScene() {
  return json::parse(R"({
    "materials": [
      {"name": "light", "type": "emitter", "albedo": [1, 1, 1]},
      {"name": "fog", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1]}
    ],
    "primitives": [
      {"type": "rectangle", "materialName": "light"},
      {"type": "volume", "materialName": "fog"}
    ],
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
    "renderer": {"resolution": [64, 32]}
  })");
}

// The InputError message parseScene gives, or "(no error)".
std::string errorOfText(const std::string& text, const std::vector<std::string>& overrides = {},
                    const std::string& path = "s.json") {
  try {
    parseScene(text, path, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string errorOf(const json& scene, const std::vector<std::string>& overrides = {}) {
  return errorOfText(scene.dump(), overrides);
}

// A fresh folder per test for scene files and (empty) volume files.
class SceneFiles : public ::testing::Test {
 protected:
  // Creates an empty file (the loader only checks that volume files exist) and returns its path.
  std::string touch(const std::string& relative) {
    const fs::path p = dir_ / relative;
    fs::create_directories(p.parent_path());
    std::ofstream(p).put('\n');
    return p.string();
  }
  std::string write(const std::string& relative, const std::string& text) {
    const fs::path p = dir_ / relative;
    test::writeFile(p, text);
    return p.string();
  }
  std::string scenePath() const { return (dir_ / "scene.json").string(); }

  static std::string withPath(json scene, const std::string& path) {
    scene["materials"][1]["path"] = path;
    return scene.dump();
  }

  test::TempDir tmp_{"narval_scene"};
  const fs::path dir_ = fs::canonical(tmp_.path());  // expected paths below are compared as strings
};

// ---------------------------------------------------------------- Listing 4.1 and defaults

TEST_F(SceneFiles, Listing41LoadsAsPrinted) {
  const std::string vdb = touch("vdb/wdas_cloud_quarter.vdb");
  const std::string path = write("scene.json", listing41Json());
  const Scene s = loadScene(path);

  EXPECT_EQ(s.sourcePath, path);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& e = s.materials[0];
  EXPECT_EQ(e.name, "emitter");
  EXPECT_EQ(e.type, MaterialType::Emitter);
  EXPECT_EQ(e.albedo, (Vec3f{20, 20, 20}));
  const Material& v = s.materials[1];
  EXPECT_EQ(v.name, "cloudVolMat");
  EXPECT_EQ(v.type, MaterialType::Volume);
  EXPECT_EQ(v.scattering, (Vec3f{1.1f, 1.1f, 1.1f}));
  EXPECT_EQ(v.absorption, (Vec3f{0.01f, 0.01f, 0.01f}));
  EXPECT_EQ(v.phase, PHASE_HG);
  EXPECT_EQ(v.phaseParameter, 0.9f);
  EXPECT_EQ(v.path, vdb);  // relative to the scene file, absolute afterwards
  EXPECT_EQ(v.density, 10.0f);
  EXPECT_EQ(v.gridName, "density");
  EXPECT_EQ(v.gridSpace, GridSpace::Unit);

  ASSERT_EQ(s.primitives.size(), 2u);
  const Primitive& light = s.primitives[0];
  EXPECT_EQ(light.name, "rectLight");
  EXPECT_EQ(light.type, PrimitiveType::Light);
  EXPECT_EQ(light.lightKind, LIGHT_RECTANGLE);
  EXPECT_EQ(light.transform.position, (Vec3f{0, 0, 80}));
  EXPECT_EQ(light.transform.scale, (Vec3f{150, 100, 1}));
  EXPECT_EQ(light.transform.rotation, (Vec3f{0, 0, 0}));
  EXPECT_EQ(light.materialName, "emitter");
  EXPECT_EQ(light.materialIndex, 0);
  const Primitive& cloud = s.primitives[1];
  EXPECT_EQ(cloud.name, "cloud");
  EXPECT_EQ(cloud.type, PrimitiveType::Volume);
  EXPECT_EQ(cloud.transform.position, (Vec3f{0, 0, 0}));
  EXPECT_EQ(cloud.transform.scale, (Vec3f{15.9f, 9.51f, 13.5f}));
  EXPECT_EQ(cloud.transform.rotation, (Vec3f{0, 0, 0}));
  EXPECT_EQ(cloud.materialName, "cloudVolMat");
  EXPECT_EQ(cloud.materialIndex, 1);

  EXPECT_EQ(s.camera.position, (Vec3f{0, 0, -17}));
  EXPECT_EQ(s.camera.lookAt, (Vec3f{0, 0, 0}));
  EXPECT_EQ(s.camera.up, (Vec3f{0, 1, 0}));
  EXPECT_EQ(s.camera.speed, 5.0f);
  EXPECT_EQ(s.camera.vfov, 45.0f);
  EXPECT_EQ(s.camera.aperture, 0.0001f);
  EXPECT_EQ(s.camera.focus, 1.0f);

  EXPECT_EQ(s.renderer.width, 1200);
  EXPECT_EQ(s.renderer.height, 600);
  EXPECT_EQ(s.renderer.spp, 1000);
  EXPECT_EQ(s.renderer.bounces, 3);
  EXPECT_TRUE(s.renderer.hdr);
  EXPECT_EQ(s.renderer.toneMapping, ToneMapping::Aces);
  // Extensions the listing leaves out take their defaults.
  EXPECT_EQ(s.renderer.exposure, 0.0f);
  EXPECT_EQ(s.renderer.algorithm, Algorithm::Pathtrace);
  EXPECT_EQ(s.renderer.seed, 0u);
  EXPECT_EQ(s.renderer.storage, GridStorage::Auto);
  EXPECT_EQ(s.background, (Vec3f{0, 0, 0}));
}

TEST(SceneDefaults, OptionalKeysTakeTheDocumentedDefaults) {
  const Scene s = parseScene(minimalScene().dump(), "s.json");
  EXPECT_TRUE(s.warnings.empty());
  const Material& fog = s.materials[1];
  EXPECT_EQ(fog.phase, PHASE_ISOTROPIC);
  EXPECT_EQ(fog.phaseParameter, 0.0f);
  EXPECT_EQ(fog.path, "");  // homogeneous
  EXPECT_EQ(fog.gridName, "density");
  EXPECT_EQ(fog.density, 1.0f);
  EXPECT_EQ(fog.gridSpace, GridSpace::Unit);
  const Primitive& p = s.primitives[0];
  EXPECT_EQ(p.name, "");
  EXPECT_EQ(p.transform.position, (Vec3f{0, 0, 0}));
  EXPECT_EQ(p.transform.scale, (Vec3f{1, 1, 1}));
  EXPECT_EQ(p.transform.rotation, (Vec3f{0, 0, 0}));
  EXPECT_EQ(s.camera.up, (Vec3f{0, 1, 0}));
  EXPECT_EQ(s.camera.vfov, 45.0f);
  EXPECT_EQ(s.camera.aperture, 0.0f);
  EXPECT_EQ(s.camera.focus, 1.0f);
  EXPECT_EQ(s.camera.speed, 1.0f);
  const RendererSettings& r = s.renderer;
  EXPECT_EQ(r.width, 64);
  EXPECT_EQ(r.height, 32);
  EXPECT_EQ(r.spp, 1000);
  EXPECT_EQ(r.bounces, 3);
  EXPECT_TRUE(r.hdr);
  EXPECT_EQ(r.toneMapping, ToneMapping::Aces);
  EXPECT_EQ(r.exposure, 0.0f);
  EXPECT_EQ(r.algorithm, Algorithm::Pathtrace);
  EXPECT_EQ(r.seed, 0u);
  // The ray marcher draws multiple scattering by default: the view cache at the interactive quality
  // (30 steps, 100 paths a node, the tile chosen at render time).
  EXPECT_EQ(r.raymarch.multipleScattering, MultipleScattering::Cache);
  EXPECT_EQ(r.raymarch.quality, RaymarchQuality::Interactive);
  EXPECT_EQ(r.raymarch.steps, 30);
  EXPECT_EQ(r.raymarch.msCache.layout, MsCacheLayout::View);
  EXPECT_EQ(r.raymarch.msCache.tile, kMsCacheTileAuto);
  EXPECT_EQ(r.raymarch.msCache.paths, 100);
  EXPECT_TRUE(r.raymarch.msCache.direct);
  EXPECT_EQ(r.raymarch.msCache.filter, 1.5f);
  EXPECT_TRUE(r.raymarch.msCache.filterTwicing);  // wherever the filter is on
  EXPECT_EQ(r.raymarch.shadowSteps, 10);
  EXPECT_EQ(r.lobe.depthFactor, 20.0f);
  EXPECT_EQ(r.lobe.lobePoints, 30);
  EXPECT_EQ(r.lobe.lobeRadius, 1.0f);
  EXPECT_EQ(r.lobe.shadowSteps, 100);
  EXPECT_EQ(s.background, (Vec3f{0, 0, 0}));
}

TEST(SceneDefaults, ExtensionsAreRead) {
  json j = minimalScene();
  j["materials"][1]["phaseFunction"] = "hg";
  j["materials"][1]["g"] = -0.3;
  j["materials"][1]["grid"] = "smoke";
  j["materials"][1]["gridSpace"] = "file";
  j["materials"][1]["density"] = 0;
  j["primitives"].push_back({{"name", "p"}, {"type", "point"}, {"materialName", "light"},
                             {"transform", {{"position", {1, 2, 3}}}}});
  j["renderer"].update(json::parse(R"({"spp": 16.0, "bounces": 0, "HDR": false, "toneMapping": "reinhard",
      "exposure": -1.5, "algorithm": "lobe", "seed": 4294967295,
      "raymarch": {"steps": 7, "shadowSteps": 3},
      "lobe": {"variant": "eq7", "depthFactor": 0, "lobePoints": 5, "lobeRadius": 0.25, "shadowSteps": 9}})"));
  j["background"] = {0.05, 0.07, 0.1};
  const Scene s = parseScene(j.dump(), "s.json");
  // Read all the same; the medium has no "path", which the two grid keys are told about, and the
  // ray marcher's keys are said to be ignored by the Lobe Estimator.
  EXPECT_EQ(s.warnings.size(), 3u);
  EXPECT_EQ(s.materials[1].phase, PHASE_HG);
  EXPECT_EQ(s.materials[1].phaseParameter, -0.3f);
  EXPECT_EQ(s.materials[1].gridName, "smoke");
  EXPECT_EQ(s.materials[1].gridSpace, GridSpace::File);
  EXPECT_EQ(s.materials[1].density, 0.0f);
  ASSERT_EQ(s.primitives.size(), 3u);
  EXPECT_EQ(s.primitives[2].type, PrimitiveType::Light);
  EXPECT_EQ(s.primitives[2].lightKind, LIGHT_POINT);
  EXPECT_EQ(s.primitives[2].materialIndex, 0);
  EXPECT_EQ(s.primitives[2].transform.position, (Vec3f{1, 2, 3}));
  EXPECT_EQ(s.primitives[2].transform.scale, (Vec3f{1, 1, 1}));
  const RendererSettings& r = s.renderer;
  EXPECT_EQ(r.spp, 16);
  EXPECT_EQ(r.bounces, 0);
  EXPECT_FALSE(r.hdr);
  EXPECT_EQ(r.toneMapping, ToneMapping::Reinhard);
  EXPECT_EQ(r.exposure, -1.5f);
  EXPECT_EQ(r.algorithm, Algorithm::Lobe);
  EXPECT_EQ(r.seed, 4294967295u);
  EXPECT_EQ(r.raymarch.steps, 7);
  EXPECT_EQ(r.raymarch.shadowSteps, 3);
  EXPECT_EQ(r.lobe.depthFactor, 0.0f);
  EXPECT_EQ(r.lobe.lobePoints, 5);
  EXPECT_EQ(r.lobe.lobeRadius, 0.25f);
  EXPECT_EQ(r.lobe.shadowSteps, 9);
  EXPECT_EQ(s.background, (Vec3f{0.05f, 0.07f, 0.1f}));
}

TEST(SceneDefaults, ToneMappingBooleansAndNames) {
  for (const auto& [value, expected] : std::vector<std::pair<json, ToneMapping>>{
           {true, ToneMapping::Aces}, {false, ToneMapping::None}, {"none", ToneMapping::None},
           {"reinhard", ToneMapping::Reinhard}, {"aces", ToneMapping::Aces}}) {
    json j = minimalScene();
    j["renderer"]["toneMapping"] = value;
    EXPECT_EQ(parseScene(j.dump(), "s.json").renderer.toneMapping, expected) << value;
  }
  EXPECT_STREQ(toneMappingName(ToneMapping::None), "none");
  EXPECT_STREQ(toneMappingName(ToneMapping::Reinhard), "reinhard");
  EXPECT_STREQ(toneMappingName(ToneMapping::Aces), "aces");
}

// ---------------------------------------------------------------- errors

TEST_F(SceneFiles, MissingOrUnreadableFile) {
  const std::string missing = (dir_ / "nope.json").string();
  try {
    loadScene(missing);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), missing + ": cannot open scene file");
  }
  try {
    loadScene(dir_.string());  // a folder
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir_.string() + ": cannot open scene file");
  }
}

TEST(SceneErrors, MalformedJson) {
  EXPECT_EQ(errorOfText("{\n  \"materials\": [,\n}"),
            "s.json: invalid JSON: parse error at line 2, column 17: syntax error while parsing value - "
            "unexpected ','; expected '[', '{', or a literal");
  EXPECT_EQ(errorOfText(""),
            "s.json: invalid JSON: parse error at line 1, column 1: syntax error while parsing value - "
            "unexpected end of input; expected '[', '{', or a literal");
  EXPECT_EQ(errorOfText("{\"a\": 1e999}"), "s.json: invalid JSON: number overflow parsing '1e999'");
  EXPECT_EQ(errorOfText("[1, 2]"), "s.json: expected a JSON object at the top level, got array");
}

TEST(SceneErrors, MissingRequiredKeys) {
  const std::vector<std::pair<json::json_pointer, std::string>> cases = {
      {json::json_pointer("/materials"), "materials"},
      {json::json_pointer("/primitives"), "primitives"},
      {json::json_pointer("/camera"), "camera"},
      {json::json_pointer("/renderer"), "renderer"},
      {json::json_pointer("/materials/0/name"), "materials[0].name"},
      {json::json_pointer("/materials/0/type"), "materials[0].type"},
      {json::json_pointer("/materials/0/albedo"), "materials[0].albedo"},
      {json::json_pointer("/materials/1/scattering"), "materials[1].scattering"},
      {json::json_pointer("/materials/1/absorption"), "materials[1].absorption"},
      {json::json_pointer("/primitives/1/type"), "primitives[1].type"},
      {json::json_pointer("/primitives/1/materialName"), "primitives[1].materialName"},
      {json::json_pointer("/camera/position"), "camera.position"},
      {json::json_pointer("/camera/lookAt"), "camera.lookAt"},
      {json::json_pointer("/renderer/resolution"), "renderer.resolution"},
  };
  for (const auto& [pointer, key] : cases) {
    json j = minimalScene();
    j[pointer.parent_pointer()].erase(pointer.back());
    EXPECT_EQ(errorOf(j), "s.json: " + key + ": missing required key");
  }
}

// One bad value per row: JSON pointer, value, the exact message.
struct BadValue {
  const char* pointer;
  json value;
  const char* message;
};

TEST(SceneErrors, BadValuesNameFileKeyAndProblem) {
  const std::vector<BadValue> cases = {
      // wrong types
      {"/materials/1/g", "0.5", "s.json: materials[1].g: expected a number, got string"},
      {"/materials/0/name", 3, "s.json: materials[0].name: expected a string, got number"},
      {"/materials", json::object(), "s.json: materials: expected an array, got object"},
      {"/materials/1", 1, "s.json: materials[1]: expected an object, got number"},
      {"/camera", json::array(), "s.json: camera: expected an object, got array"},
      {"/primitives/0/transform", "identity", "s.json: primitives[0].transform: expected an object, got string"},
      {"/renderer/HDR", 1, "s.json: renderer.HDR: expected a boolean, got number"},
      {"/renderer/spp", 2.5, "s.json: renderer.spp: expected an integer, got 2.5"},
      {"/renderer/bounces", "3", "s.json: renderer.bounces: expected an integer, got string"},
      {"/renderer/toneMapping", 1, "s.json: renderer.toneMapping: expected a boolean or one of none, reinhard, aces, got number"},
      // arrays of 3 finite numbers
      {"/camera/position", {0, 0}, "s.json: camera.position: expected an array of 3 numbers, got 2 elements"},
      {"/camera/position", 5, "s.json: camera.position: expected an array of 3 numbers, got number"},
      {"/camera/up", {0, "1", 0}, "s.json: camera.up[1]: expected a number, got string"},
      {"/background", {0, 0, 0, 1}, "s.json: background: expected an array of 3 numbers, got 4 elements"},
      {"/materials/1/density", 1e39, "s.json: materials[1].density: must be finite as a 32-bit float, got 1e+39"},
      // unknown enum values
      {"/materials/0/type", "light", "s.json: materials[0].type: unknown value \"light\" (allowed: emitter, volume)"},
      {"/materials/1/phaseFunction", "rayleigh", "s.json: materials[1].phaseFunction: unknown value \"rayleigh\" (allowed: isotropic, hg, mie)"},
      {"/materials/1/gridSpace", "world", "s.json: materials[1].gridSpace: unknown value \"world\" (allowed: unit, file)"},
      {"/primitives/1/type", "sphere", "s.json: primitives[1].type: unknown value \"sphere\" (allowed: rectangle, point, distant, volume)"},
      {"/renderer/algorithm", "mlt", "s.json: renderer.algorithm: unknown value \"mlt\" (allowed: pathtrace, raymarch, lobe)"},
      {"/renderer/storage", "texture", "s.json: renderer.storage: unknown value \"texture\" (allowed: auto, image, buffer, bricks)"},
      {"/renderer/storage", true, "s.json: renderer.storage: expected a string, got boolean"},
      {"/renderer/toneMapping", "filmic", "s.json: renderer.toneMapping: unknown value \"filmic\" (allowed: none, reinhard, aces)"},
      // out of range
      {"/materials/1/g", 1.5, "s.json: materials[1].g: must be in [-1, 1], got 1.5"},
      {"/materials/1/g", -1.01, "s.json: materials[1].g: must be in [-1, 1], got -1.01"},
      {"/materials/1/scattering", {1, -1, 1}, "s.json: materials[1].scattering[1]: must be non-negative, got -1"},
      {"/materials/1/absorption", {0, 0, -0.5}, "s.json: materials[1].absorption[2]: must be non-negative, got -0.5"},
      {"/materials/1/density", -2, "s.json: materials[1].density: must be non-negative, got -2"},
      {"/materials/0/albedo", {-1, 0, 0}, "s.json: materials[0].albedo[0]: must be non-negative, got -1"},
      {"/materials/0/name", "", "s.json: materials[0].name: must not be empty"},
      {"/materials/1/grid", "", "s.json: materials[1].grid: must not be empty"},
      {"/primitives/1/transform", {{"scale", {1, 0, 1}}}, "s.json: primitives[1].transform.scale[1]: must be non-zero, got 0"},
      {"/primitives/0/transform", {{"scale", {0, 1, 1}}}, "s.json: primitives[0].transform.scale[0]: must be non-zero, got 0"},
      {"/camera/vfov", 0, "s.json: camera.vfov: must be in (0, 180) degrees, got 0"},
      {"/camera/vfov", 180, "s.json: camera.vfov: must be in (0, 180) degrees, got 180"},
      {"/camera/aperture", -0.1, "s.json: camera.aperture: must be non-negative, got -0.1"},
      {"/camera/focus", 0, "s.json: camera.focus: must be positive, got 0"},
      {"/camera/speed", -1, "s.json: camera.speed: must be non-negative, got -1"},
      {"/camera/lookAt", {0, 0, -5}, "s.json: camera.lookAt: must differ from camera.position"},
      {"/camera/up", {0, 0, 2}, "s.json: camera.up: must be non-zero and not parallel to the viewing direction"},
      {"/camera/up", {0, 0, 0}, "s.json: camera.up: must be non-zero and not parallel to the viewing direction"},
      {"/renderer/resolution", {0, 32}, "s.json: renderer.resolution[0]: must be at least 1, got 0"},
      {"/renderer/resolution", {64, -32}, "s.json: renderer.resolution[1]: must be at least 1, got -32"},
      {"/renderer/resolution", {20000, 32}, "s.json: renderer.resolution[0]: must be at most 16384, got 20000"},
      {"/renderer/resolution", {64}, "s.json: renderer.resolution: expected an array of 2 integers [width, height], got 1 elements"},
      {"/renderer/resolution", "64x32", "s.json: renderer.resolution: expected an array of 2 integers [width, height], got string"},
      {"/renderer/spp", 0, "s.json: renderer.spp: must be at least 1, got 0"},
      {"/renderer/spp", 3000000000LL, "s.json: renderer.spp: must be at most 2147483647, got 3000000000"},
      {"/renderer/bounces", -1, "s.json: renderer.bounces: must be at least 0, got -1"},
      {"/renderer/seed", -1, "s.json: renderer.seed: must be at least 0, got -1"},
      {"/renderer/seed", 4294967296LL, "s.json: renderer.seed: must be at most 4294967295, got 4294967296"},
      {"/renderer/raymarch", {{"steps", 0}}, "s.json: renderer.raymarch.steps: must be at least 1, got 0"},
      {"/renderer/lobe", {{"lobePoints", 0}}, "s.json: renderer.lobe.lobePoints: must be at least 1, got 0"},
      {"/renderer/lobe", {{"lobeRadius", -1}}, "s.json: renderer.lobe.lobeRadius: must be non-negative, got -1"},
      {"/background", {0, -0.1, 0}, "s.json: background[1]: must be non-negative, got -0.1"},
      // cross references
      {"/primitives/0/materialName", "lamp", "s.json: primitives[0].materialName: no material named \"lamp\" (defined: \"light\", \"fog\")"},
      {"/materials/1/name", "light", "s.json: materials[1].name: duplicate material name \"light\" (first used by materials[0])"},
      {"/primitives/1/materialName", "light", "s.json: primitives[1].materialName: a volume primitive needs a volume material; \"light\" is an emitter"},
      {"/primitives/0/materialName", "fog", "s.json: primitives[0].materialName: a rectangle primitive needs an emitter material; \"fog\" is a volume"},
      {"/primitives/2", {{"type", "volume"}, {"materialName", "fog"}}, "s.json: primitives[2]: only one volume primitive is supported"},
      {"/primitives/2", {{"type", "point"}, {"materialName", "fog"}}, "s.json: primitives[2].materialName: a point primitive needs an emitter material; \"fog\" is a volume"},
  };
  for (const BadValue& c : cases) {
    json j = minimalScene();
    j[json::json_pointer(c.pointer)] = c.value;
    EXPECT_EQ(errorOf(j), c.message) << c.pointer << " = " << c.value;
  }
}

TEST(SceneErrors, ErrorsAreOneLine) {
  json j = minimalScene();
  j["materials"][1]["g"] = 2;
  const std::string message = errorOf(j);
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

// ---------------------------------------------------------------- warnings

TEST(SceneWarnings, UnknownKeysAreNamedAndIgnored) {
  json j = minimalScene();
  j["camera"]["fieldOfView"] = 30;
  j["comment"] = "made by hand";
  j["materials"][0]["scattering"] = {1, 1, 1};  // a volume key on an emitter
  j["primitives"][1]["transform"] = {{"translate", {1, 0, 0}}};
  j["renderer"]["lobe"] = {{"points", 3}};
  const Scene s = parseScene(j.dump(), "scenes/a.json");
  EXPECT_EQ(s.warnings, (std::vector<std::string>{
                            "scenes/a.json: unknown key materials[0].scattering (ignored)",
                            "scenes/a.json: unknown key primitives[1].transform.translate (ignored)",
                            "scenes/a.json: unknown key camera.fieldOfView (ignored)",
                            "scenes/a.json: unknown key renderer.lobe.points (ignored)",
                            "scenes/a.json: unknown key comment (ignored)",
                        }));
  EXPECT_EQ(s.camera.vfov, 45.0f);
}

// A key one slip away from a key its object takes is a typo whose default would run silently (a
// thousand samples for "sPP"): an error naming the key it probably meant. Case slips count at any
// length, one edit (a letter added, dropped, replaced, or two swapped) when the longer name has three
// letters or more, and other renderers' words for a key; anything further stays a warning.
TEST(SceneErrors, NearMissKeysNameTheKeyTheyProbablyMeant) {
  auto with = [](const std::string& object, int index, const std::string& key) {
    json j = minimalScene();
    json& o = index < 0 ? j[object] : j[object][index];
    o[key] = 4;
    return errorOf(j);
  };
  EXPECT_EQ(with("renderer", -1, "sPP"), "s.json: renderer.sPP: unknown key (did you mean renderer.spp?)");
  EXPECT_EQ(with("renderer", -1, "hdr"), "s.json: renderer.hdr: unknown key (did you mean renderer.HDR?)");
  EXPECT_EQ(with("camera", -1, "fov"), "s.json: camera.fov: unknown key (did you mean camera.vfov?)");
  EXPECT_EQ(with("camera", -1, "vofv"), "s.json: camera.vofv: unknown key (did you mean camera.vfov?)");
  EXPECT_EQ(with("camera", -1, "vfovv"), "s.json: camera.vfovv: unknown key (did you mean camera.vfov?)");
  EXPECT_EQ(with("materials", 1, "densty"), "s.json: materials[1].densty: unknown key (did you mean materials[1].density?)");
  EXPECT_EQ(with("materials", 1, "G"), "s.json: materials[1].G: unknown key (did you mean materials[1].g?)");
  EXPECT_EQ(with("materials", 1, "h"), "(no error)");  // one edit from "g", but one letter long
  EXPECT_EQ(with("renderer", -1, "sp"), "s.json: renderer.sp: unknown key (did you mean renderer.spp?)");
  EXPECT_EQ(with("renderer", -1, "samples"), "s.json: renderer.samples: unknown key (did you mean renderer.spp?)");
  EXPECT_EQ(with("renderer", -1, "maxDepth"), "s.json: renderer.maxDepth: unknown key (did you mean renderer.bounces?)");
  EXPECT_EQ(with("materials", 1, "sigma_s"),
            "s.json: materials[1].sigma_s: unknown key (did you mean materials[1].scattering?)");
  EXPECT_EQ(with("camera", -1, "fovy"), "(no error)");  // two edits from "vfov"
  // A required key misspelt: the missing key's message points at the one present.
  json j = minimalScene();
  j["materials"][1].erase("scattering");
  j["materials"][1]["Scattering"] = {1, 1, 1};
  EXPECT_EQ(errorOf(j), "s.json: materials[1].scattering: missing required key (is \"Scattering\" meant to be it?)");
}

// The multiple-scattering cache's settings without the cache are said to be ignored.
TEST(SceneWarnings, MsCacheSettingsWithoutTheCache) {
  json j = minimalScene();
  j["renderer"]["algorithm"] = "raymarch";
  j["renderer"]["raymarch"] = {{"multipleScattering", "none"}, {"msCache", {{"paths", 64}}}};
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{"s.json: renderer.raymarch.msCache: applies to multipleScattering \"cache\"; "
                                      "\"none\" ignores it"}));
  j["renderer"]["raymarch"]["multipleScattering"] = "cache";
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings, std::vector<std::string>{});
}

// A grid named or placed on a medium without a grid file has nothing to act on.
TEST(SceneWarnings, GridKeysOnAHomogeneousMedium) {
  json j = minimalScene();
  j["materials"][1]["grid"] = "smoke";
  j["materials"][1]["gridSpace"] = "file";
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{
                "s.json: materials[1].grid: ignored: the medium is homogeneous (no \"path\")",
                "s.json: materials[1].gridSpace: ignored: the medium is homogeneous (no \"path\")"}));
}

TEST(SceneWarnings, HenyeyGreensteinAtPlusMinusOneIsClamped) {
  json j = minimalScene();
  j["materials"][1]["phaseFunction"] = "hg";
  j["materials"][1]["g"] = 1;
  Scene s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.materials[1].phaseParameter, 0.9999f);
  EXPECT_EQ(s.warnings, (std::vector<std::string>{
                            "s.json: materials[1].g: g = 1 makes the hg phase function degenerate; "
                            "clamped to 0.9999"}));
  j["materials"][1]["g"] = -1.0;
  s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.materials[1].phaseParameter, -0.9999f);
  EXPECT_EQ(s.warnings, (std::vector<std::string>{
                            "s.json: materials[1].g: g = -1 makes the hg phase function degenerate; "
                            "clamped to -0.9999"}));
}

TEST(SceneWarnings, GWithIsotropicPhaseIsIgnored) {
  json j = minimalScene();
  j["materials"][1]["g"] = 0.5;
  const Scene s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.materials[1].phase, PHASE_ISOTROPIC);
  EXPECT_EQ(s.warnings, (std::vector<std::string>{
                            "s.json: materials[1].g: ignored by the isotropic phase function "
                            "(use \"phaseFunction\": \"hg\")"}));
}

// Mie: dropletDiameter (µm) defaults to 20, must lie in the fit's range [0.1, 50] (phase_kinds.h),
// and a "g" beside it is HG's key, ignored with the same warning as under isotropic.
TEST(SceneLoad, MiePhaseFunctionTakesADropletDiameter) {
  json j = minimalScene();
  j["materials"][1]["phaseFunction"] = "mie";
  Scene s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.materials[1].phase, PHASE_MIE);
  EXPECT_EQ(s.materials[1].phaseParameter, 20.0f);
  EXPECT_TRUE(s.warnings.empty());
  j["materials"][1]["dropletDiameter"] = 8;
  j["materials"][1]["g"] = 0.9;
  s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.materials[1].phaseParameter, 8.0f);
  EXPECT_EQ(s.warnings, (std::vector<std::string>{
                            "s.json: materials[1].g: ignored by the mie phase function (use \"phaseFunction\": \"hg\")"}));
  for (const auto& [d, message] : std::vector<std::pair<double, std::string>>{
           {60, "s.json: materials[1].dropletDiameter: must be in [0.1, 50], got 60"},
           {0.05, "s.json: materials[1].dropletDiameter: must be in [0.1, 50], got 0.05"}}) {
    j["materials"][1]["dropletDiameter"] = d;
    EXPECT_EQ(errorOf(j), message);
  }
  j = minimalScene();
  j["materials"][1]["dropletDiameter"] = 10;
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{"s.json: materials[1].dropletDiameter: ignored by the isotropic phase function "
                                      "(use \"phaseFunction\": \"mie\")"}));
}

// A distant light (light_distant.h): "direction" required and non-zero, "angularDiameter" in
// [0, 180] (default 0, a delta light); it takes no transform, and its keys on another primitive are
// named as ignored.
TEST(SceneLoad, DistantLightTakesADirectionAndAnAngularDiameter) {
  json j = minimalScene();
  j["primitives"][0] = {{"type", "distant"}, {"direction", {0, -1, 0}}, {"materialName", "light"}};
  Scene s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.primitives[0].type, PrimitiveType::Light);
  EXPECT_EQ(s.primitives[0].lightKind, LIGHT_DISTANT);
  EXPECT_EQ(s.primitives[0].lightVector, (Vec3f{0, -1, 0}));
  EXPECT_EQ(s.primitives[0].lightParameter, 0.0f);
  EXPECT_TRUE(s.warnings.empty());
  j["primitives"][0]["angularDiameter"] = 0.53;
  j["primitives"][0]["transform"] = {{"position", {1, 2, 3}}};
  s = parseScene(j.dump(), "s.json");
  EXPECT_EQ(s.primitives[0].lightParameter, 0.53f);
  EXPECT_EQ(s.warnings, (std::vector<std::string>{"s.json: primitives[0].transform: ignored by a distant light"}));
  j["primitives"][0]["angularDiameter"] = 181;
  EXPECT_EQ(errorOf(j), "s.json: primitives[0].angularDiameter: must be in [0, 180], got 181");
  j["primitives"][0]["angularDiameter"] = 1;
  j["primitives"][0]["direction"] = {0, 0, 0};
  EXPECT_EQ(errorOf(j), "s.json: primitives[0].direction: must be non-zero");
  j["primitives"][0].erase("direction");
  EXPECT_EQ(errorOf(j), "s.json: primitives[0].direction: missing required key");
  j = minimalScene();
  j["primitives"][0]["direction"] = {0, -1, 0};
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{"s.json: primitives[0].direction: ignored by a rectangle primitive"}));
}

TEST(SceneWarnings, NoLightAndBlackBackground) {
  json j = minimalScene();
  j["primitives"].erase(0);
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{"s.json: no light, no emission and a black background: the image will be black"}));
  j["background"] = {0.1, 0.1, 0.1};
  EXPECT_TRUE(parseScene(j.dump(), "s.json").warnings.empty());
}

// The corrected Lobe Estimator has no first-hit search and no fixed depth: those keys are named as
// ignored under it, and not under eq7 (where they count).
TEST(SceneWarnings, EqSevenKeysUnderTheCorrectedLobe) {
  json j = minimalScene();
  j["renderer"]["algorithm"] = "lobe";
  j["renderer"]["lobe"] = {{"variant", "corrected"}, {"depthFactor", 5}, {"firstHitSteps", 30}, {"lobeRadius", 2}};
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{
                "s.json: renderer.lobe.depthFactor: applies to variant \"eq7\"; \"corrected\" ignores it",
                "s.json: renderer.lobe.firstHitSteps: applies to variant \"eq7\"; \"corrected\" ignores it"}));
  // An emitting medium's light is marched with firstHitSteps in both variants.
  json fire = j;
  fire["materials"][1]["emission"] = {{"color", {1, 1, 1}}};
  EXPECT_EQ(parseScene(fire.dump(), "s.json").warnings,
            (std::vector<std::string>{
                "s.json: renderer.lobe.depthFactor: applies to variant \"eq7\"; \"corrected\" ignores it"}));
  j["renderer"]["lobe"]["variant"] = "eq7";
  EXPECT_TRUE(parseScene(j.dump(), "s.json").warnings.empty());
}

// A section set away from its defaults for an algorithm that does not read it is named; a section
// at its defaults (as a resolved scene writes every one) is not.
TEST(SceneWarnings, SectionsTheAlgorithmDoesNotRead) {
  json j = minimalScene();  // the path tracer
  j["renderer"]["raymarch"] = {{"steps", 45}};
  j["renderer"]["lobe"] = {{"lobePoints", 30}};  // its default
  j["renderer"]["lightCache"] = {{"resolution", 32}};
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{
                "s.json: renderer.raymarch: applies to algorithm \"raymarch\"; algorithm \"pathtrace\" ignores it",
                "s.json: renderer.lightCache: applies to the real-time algorithms; algorithm \"pathtrace\" ignores it"}));
  j["renderer"]["algorithm"] = "lobe";
  j["renderer"]["pathtrace"] = {{"shadowRoulette", 0.1}};
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{
                "s.json: renderer.pathtrace: applies to the path tracer and the ray marcher's multiple-scattering "
                "cache; algorithm \"lobe\" ignores it",
                "s.json: renderer.raymarch: applies to algorithm \"raymarch\"; algorithm \"lobe\" ignores it"}));
  // The ray marcher's cache traces paths with the path tracer's settings; the octaves' keys apply
  // only to the octaves.
  j["renderer"]["algorithm"] = "raymarch";
  j["renderer"]["raymarch"] = {{"multipleScattering", "cache"}, {"octavePhase", 0.7}};
  EXPECT_EQ(parseScene(j.dump(), "s.json").warnings,
            (std::vector<std::string>{"s.json: renderer.raymarch.octavePhase: applies to multipleScattering "
                                      "\"octaves\"; \"cache\" ignores it"}));
}

// ---------------------------------------------------------------- the resolved scene

// Scene::document writes out every default the loader took (narval scene --resolved): it names
// the values used, reads back to the same document without a warning, and so keys a render the
// same way; a key given at its default changes nothing.
TEST(SceneResolved, ReadsBackToTheSameDocumentAndRenderKey) {
  json j = minimalScene();
  j["renderer"]["algorithm"] = "lobe";
  j["renderer"]["lobe"] = {{"variant", "corrected"}};
  const Scene s = parseScene(j.dump(), "s.json");
  const json& r = s.document;
  EXPECT_EQ(r["renderer"]["spp"], 1000);
  EXPECT_EQ(r["renderer"]["lobe"]["viewSteps"], 16);  // the corrected variant's default
  EXPECT_EQ(r["renderer"]["lobe"]["shadowAreaSamples"], 4);
  EXPECT_EQ(r["renderer"]["raymarch"]["msCache"]["paths"], 100);  // the interactive quality's
  EXPECT_EQ(r["renderer"]["raymarch"]["msCache"]["tile"], "auto");
  EXPECT_EQ(r["renderer"]["lightCache"]["resolution"], "auto");
  EXPECT_EQ(r["renderer"]["toneMapping"], "aces");
  EXPECT_EQ(r["renderer"]["pathtrace"]["shadowRoulette"], 0.05);  // the float's shortest decimal
  EXPECT_EQ(r["materials"][1]["phaseFunction"], "isotropic");
  EXPECT_FALSE(r["materials"][1].contains("g"));  // another phase function's key is not written
  EXPECT_EQ(r["primitives"][1]["transform"]["scale"], json({1, 1, 1}));
  EXPECT_EQ(r["camera"]["vfov"], 45);
  EXPECT_EQ(r["background"], json({0, 0, 0}));

  const Scene again = parseScene(r.dump(), "s.json");
  EXPECT_TRUE(again.warnings.empty()) << again.warnings.front();
  EXPECT_EQ(again.document, r);
  EXPECT_EQ(renderKey(again), renderKey(s));
  EXPECT_EQ(lobeViewSteps(again.renderer.lobe), lobeViewSteps(s.renderer.lobe));

  EXPECT_EQ(renderKey(parseScene(j.dump(), "s.json", {"renderer.bounces=3"})), renderKey(s));
  EXPECT_NE(renderKey(parseScene(j.dump(), "s.json", {"renderer.bounces=4"})), renderKey(s));
}

// The loader's key table (narval scene --keys): every key typed; defaults that depend on another
// key listed as each one.
TEST(SceneKeyTable, EveryKeyTypedWithItsDefaultsAndRange) {
  const std::vector<SceneKey> table = sceneKeyTable();
  auto find = [&](const std::string& key) -> const SceneKey& {
    for (const SceneKey& k : table)
      if (k.key == key) return k;
    throw std::runtime_error("no key " + key);
  };
  for (const SceneKey& k : table) EXPECT_FALSE(k.type.empty()) << k.key;
  EXPECT_EQ(find("renderer.spp").defaults, std::vector<json>{1000});
  EXPECT_EQ(find("renderer.spp").range, ">= 1");
  EXPECT_EQ(find("renderer.lobe.viewSteps").defaults, (std::vector<json>{16, 24}));  // corrected's (the default), eq7's
  EXPECT_EQ(find("materials[].g").range, "[-1, 1]");
  EXPECT_EQ(find("materials[].phaseFunction").range, "isotropic, hg, mie");
  EXPECT_TRUE(find("camera.position").required);
  EXPECT_TRUE(find("primitives[].direction").required);  // the distant light's
  EXPECT_FALSE(find("renderer.seed").required);
}

// ---------------------------------------------------------------- --set overrides

TEST(SceneOverrides, ReplaceCreateAndParseValues) {
  json j = minimalScene();
  j["materials"][1]["phaseFunction"] = "hg";
  const Scene s = parseScene(j.dump(), "s.json",
                             {"renderer.spp=16", "materials.1.g=0.9", "background=[1,1,1]",
                              "renderer.seed=3", "renderer.lobe.lobePoints=10", "renderer.algorithm=lobe",
                              "materials[1].density=2.5", "renderer.toneMapping=false",
                              "camera.position.2=-9", "renderer.spp=32", "renderer.storage=buffer"});
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.renderer.spp, 32);  // later overrides win
  EXPECT_EQ(s.materials[1].phaseParameter, 0.9f);
  EXPECT_EQ(s.background, (Vec3f{1, 1, 1}));
  EXPECT_EQ(s.renderer.seed, 3u);
  EXPECT_EQ(s.renderer.lobe.lobePoints, 10);
  EXPECT_EQ(s.renderer.algorithm, Algorithm::Lobe);
  EXPECT_EQ(s.materials[1].density, 2.5f);
  EXPECT_EQ(s.renderer.toneMapping, ToneMapping::None);
  EXPECT_EQ(s.camera.position, (Vec3f{0, 0, -9}));
  EXPECT_EQ(s.renderer.storage, GridStorage::Buffer);
}

// renderer.storage takes every storage by its name, and gridStorageName spells it back.
TEST(SceneOverrides, EveryGridStorageParsesByName) {
  for (const char* name : {"auto", "image", "buffer", "bricks"}) {
    const Scene s = parseScene(minimalScene().dump(), "s.json", {std::string("renderer.storage=") + name});
    EXPECT_STREQ(gridStorageName(s.renderer.storage), name);
  }
  EXPECT_EQ(parseScene(minimalScene().dump(), "s.json", {"renderer.storage=bricks"}).renderer.storage,
            GridStorage::Bricks);
}

TEST(SceneOverrides, OverriddenValuesAreValidated) {
  EXPECT_EQ(errorOf(minimalScene(), {"renderer.spp=lots"}),
            "s.json: renderer.spp: expected an integer, got string");
  EXPECT_EQ(errorOf(minimalScene(), {"materials.1.density=-1"}),
            "s.json: materials[1].density: must be non-negative, got -1");
}

TEST(SceneOverrides, BadPaths) {
  EXPECT_EQ(errorOf(minimalScene(), {"renderer.spp"}),
            "s.json: --set renderer.spp: expected PATH=VALUE, e.g. renderer.spp=16");
  EXPECT_EQ(errorOf(minimalScene(), {"=3"}), "s.json: --set =3: expected PATH=VALUE, e.g. renderer.spp=16");
  EXPECT_EQ(errorOf(minimalScene(), {"renderer..spp=3"}),
            "s.json: --set renderer..spp=3: expected PATH=VALUE, e.g. renderer.spp=16");
  EXPECT_EQ(errorOf(minimalScene(), {"materials.5.g=1"}), "s.json: --set materials.5.g: no such key");
  EXPECT_EQ(errorOf(minimalScene(), {"materials.fog.g=1"}), "s.json: --set materials.fog.g: no such key");
  EXPECT_EQ(errorOf(minimalScene(), {"renderer.resolution.0.x=1"}),
            "s.json: --set renderer.resolution.0.x: no such key");
  EXPECT_EQ(errorOf(minimalScene(), {"camera.lookAt.x=1"}), "s.json: --set camera.lookAt.x: no such key");
  // Missing objects on the way are made; what they replace is then checked like any value.
  EXPECT_EQ(errorOf(minimalScene(), {"renderer.spp.x=1"}), "s.json: renderer.spp: expected an integer, got object");
  EXPECT_EQ(errorOf(minimalScene(), {"renderer.passes.0=1"}), "s.json: --set renderer.passes.0: no such key");
  // A key the loader does not know would only be a warning in a file; on the command line it is a typo.
  EXPECT_EQ(errorOf(minimalScene(), {"rendrer.spp=3"}),
            "s.json: --set rendrer.spp: not a scene setting (unknown key rendrer; did you mean renderer?)");
  EXPECT_EQ(errorOf(minimalScene(), {"camera.fov=30"}),
            "s.json: --set camera.fov: not a scene setting (unknown key camera.fov; did you mean camera.vfov?)");
  EXPECT_EQ(errorOf(minimalScene(), {"camera.fieldOfView=30"}),
            "s.json: --set camera.fieldOfView: not a scene setting (unknown key camera.fieldOfView)");
}

// ---------------------------------------------------------------- volume paths

TEST_F(SceneFiles, RelativePathsResolveAgainstTheSceneFolder) {
  const std::string vdb = touch("grids/a.vdb");
  const Scene s = parseScene(withPath(minimalScene(), "./sub/../grids/a.vdb"), scenePath());
  EXPECT_EQ(s.materials[1].path, vdb);
  // Absolute paths are kept (normalised).
  EXPECT_EQ(parseScene(withPath(minimalScene(), dir_.string() + "//grids/./a.vdb"), scenePath()).materials[1].path,
            vdb);
}

TEST_F(SceneFiles, DataDirFromTheEnvironment) {
  const std::string vdb = touch("data/a.vdb");
  const std::string fallback = touch("fallback/a.vdb");
  {
    ScopedEnv env("NARVAL_DATA_DIR", (dir_ / "data").string());
    EXPECT_EQ(parseScene(withPath(minimalScene(), "${NARVAL_DATA_DIR}/a.vdb"), scenePath()).materials[1].path, vdb);
    EXPECT_EQ(parseScene(withPath(minimalScene(), "${NARVAL_DATA_DIR:-fallback}/a.vdb"), scenePath())
                  .materials[1].path,
              vdb);
  }
  {
    ScopedEnv env("NARVAL_DATA_DIR", std::nullopt);
    // The default is itself relative to the scene file, like any other path.
    EXPECT_EQ(parseScene(withPath(minimalScene(), "${NARVAL_DATA_DIR:-fallback}/a.vdb"), scenePath())
                  .materials[1].path,
              fallback);
    EXPECT_EQ(errorOfText(withPath(minimalScene(), "${NARVAL_DATA_DIR}/a.vdb"), {}, scenePath()),
              scenePath() +
                  ": materials[1].path: environment variable NARVAL_DATA_DIR is not set "
                  "(write ${NARVAL_DATA_DIR:-default} to give a fallback)");
  }
  {
    // A grid that is not there says which variable placed the path, and whether it is set.
    ScopedEnv env("NARVAL_DATA_DIR", std::nullopt);
    EXPECT_EQ(errorOfText(withPath(minimalScene(), "${NARVAL_DATA_DIR:-fallback}/none.vdb"), {}, scenePath()),
              scenePath() + ": materials[1].path: volume file not found: " + (dir_ / "fallback/none.vdb").string() +
                  " (NARVAL_DATA_DIR is not set: set it to the folder that holds the file)");
    ScopedEnv set("NARVAL_DATA_DIR", (dir_ / "data").string());
    EXPECT_EQ(errorOfText(withPath(minimalScene(), "${NARVAL_DATA_DIR:-fallback}/none.vdb"), {}, scenePath()),
              scenePath() + ": materials[1].path: volume file not found: " + (dir_ / "data/none.vdb").string() +
                  " (from NARVAL_DATA_DIR=" + (dir_ / "data").string() + ")");
  }
  {
    ScopedEnv env("NARVAL_DATA_DIR", "");  // set but empty: the default applies, as in a shell
    ScopedEnv other("NARVAL_TEST_FALLBACK", (dir_ / "fallback").string());
    EXPECT_EQ(parseScene(withPath(minimalScene(), "${NARVAL_DATA_DIR:-${NARVAL_TEST_FALLBACK}}/a.vdb"),
                         scenePath())
                  .materials[1].path,
              fallback);
  }
}

// A key written twice in one object fails naming its path (JSON parsers keep one silently); the
// same key in two objects, or in two elements of an array, is not a duplicate.
TEST(SceneLoad, DuplicateKeysFailNamingThem) {
  const std::string scene = minimalScene().dump();
  auto withRenderer = [&](const std::string& renderer) {
    json j = minimalScene();
    j.erase("renderer");
    return j.dump().substr(0, j.dump().size() - 1) + ", \"renderer\": " + renderer + "}";
  };
  EXPECT_EQ(errorOfText(withRenderer(R"({"resolution": [4, 4], "spp": 1, "spp": 1000})")),
            "s.json: renderer.spp: written twice in one object (JSON would keep only the last silently)");
  EXPECT_EQ(errorOfText("{\"background\": [0, 0, 0], " + scene.substr(1, scene.size() - 2) +
                        ", \"background\": [1, 1, 1]}"),
            "s.json: background: written twice in one object (JSON would keep only the last silently)");
  std::string text = scene;
  const std::string fog = "\"name\":\"fog\"";
  ASSERT_NE(text.find(fog), std::string::npos);
  text.insert(text.find(fog), "\"g\":0.5,\"g\":0.6,");
  EXPECT_EQ(errorOfText(text), "s.json: materials[1].g: written twice in one object (JSON would keep only the last silently)");
  EXPECT_EQ(errorOfText(scene), "(no error)");  // "name" in every material, "position" in every transform
}

TEST_F(SceneFiles, BadVolumePaths) {
  touch("grids/a.vdb");
  const std::string prefix = scenePath() + ": materials[1].path: ";
  EXPECT_EQ(errorOfText(withPath(minimalScene(), "grids/b.vdb"), {}, scenePath()),
            prefix + "volume file not found: " + (dir_ / "grids/b.vdb").string());
  EXPECT_EQ(errorOfText(withPath(minimalScene(), "grids/b.VOL"), {}, scenePath()),
            prefix + "volume file not found: " + (dir_ / "grids/b.VOL").string());
  fs::create_directories(dir_ / "folder.vdb");
  EXPECT_EQ(errorOfText(withPath(minimalScene(), "folder.vdb"), {}, scenePath()),
            prefix + "volume path is not a file: " + (dir_ / "folder.vdb").string());
  EXPECT_EQ(errorOfText(withPath(minimalScene(), "grids/a.nvdb"), {}, scenePath()),
            prefix + "unsupported volume file type \".nvdb\" (allowed: .vdb, .vol): " +
                (dir_ / "grids/a.nvdb").string());
  EXPECT_EQ(errorOfText(withPath(minimalScene(), ""), {}, scenePath()),
            prefix + "must not be empty (leave it out for a homogeneous medium)");
  EXPECT_EQ(errorOfText(withPath(minimalScene(), "${NARVAL_DATA_DIR/a.vdb"), {}, scenePath()),
            prefix + "unterminated ${ in \"${NARVAL_DATA_DIR/a.vdb\"");
  EXPECT_EQ(errorOfText(withPath(minimalScene(), "${1X}/a.vdb"), {}, scenePath()),
            prefix + "bad variable reference ${1X} (expected ${NAME} or ${NAME:-default})");
  json j = minimalScene();
  j["materials"][1]["path"] = 7;
  EXPECT_EQ(errorOfText(j.dump(), {}, scenePath()), scenePath() + ": materials[1].path: expected a string, got number");
}

// ---------------------------------------------------------------- the scenes shipped in scenes/

TEST_F(SceneFiles, ShippedScenesParse) {
  const fs::path scenes = fs::path(NARVAL_SOURCE_DIR) / "scenes";
  // Their grids are generated at set-up or live outside the repository: stand-ins here.
  const std::string cloud128 = touch("data/cloud_128.vdb");
  const std::string disney = touch("volumes/wdas_cloud_sixteenth.vdb");
  ScopedEnv env("NARVAL_DATA_DIR", (dir_ / "volumes").string());

  const Scene cloud = parseScene(readFile(scenes / "cloud.json"), scenePath());
  EXPECT_TRUE(cloud.warnings.empty());
  EXPECT_EQ(cloud.materials[1].path, cloud128);
  EXPECT_EQ(cloud.materials[1].phaseParameter, 0.8f);
  EXPECT_EQ(cloud.materials[1].density, 5.0f);
  EXPECT_EQ(cloud.primitives[1].transform.scale, (Vec3f{10, 10, 10}));
  EXPECT_EQ(cloud.renderer.width, 640);
  EXPECT_EQ(cloud.renderer.height, 360);
  EXPECT_EQ(cloud.renderer.spp, 64);
  EXPECT_EQ(cloud.renderer.bounces, 8);
  EXPECT_EQ(cloud.background, (Vec3f{0.07f, 0.1f, 0.17f}));
  // A key light from the upper left front.
  EXPECT_EQ(cloud.primitives[2].materialName, "key");

  // cloud_sun.json: the same grid, droplets with the Mie phase function, under a sun 0.53° wide.
  const Scene sun = parseScene(readFile(scenes / "cloud_sun.json"), scenePath());
  EXPECT_TRUE(sun.warnings.empty());
  EXPECT_EQ(sun.materials[1].path, cloud128);
  EXPECT_EQ(sun.materials[1].phase, PHASE_MIE);
  EXPECT_EQ(sun.materials[1].phaseParameter, 20.0f);
  EXPECT_EQ(sun.primitives[0].type, PrimitiveType::Light);
  EXPECT_EQ(sun.primitives[0].lightKind, LIGHT_DISTANT);
  EXPECT_EQ(sun.primitives[0].lightParameter, 0.53f);

  // cloud_dawn.json and plume.json: scenes no real-time setting was tuned on (bench/RESULTS.md): the
  // cloud turned under a low sun, and the EmberGen file's temperature grid as a smoke's density.
  const Scene dawn = parseScene(readFile(scenes / "cloud_dawn.json"), scenePath());
  EXPECT_TRUE(dawn.warnings.empty());
  EXPECT_EQ(dawn.materials[1].path, cloud128);
  EXPECT_EQ(dawn.materials[1].phaseParameter, 0.6f);
  EXPECT_EQ(dawn.primitives[0].lightKind, LIGHT_DISTANT);
  const std::string fire = touch("volumes/embergen_fire_a_50.vdb");
  const Scene plume = parseScene(readFile(scenes / "plume.json"), scenePath());
  EXPECT_TRUE(plume.warnings.empty());
  EXPECT_EQ(plume.materials[1].path, fire);
  EXPECT_EQ(plume.materials[1].gridName, "temperature");
  EXPECT_EQ(plume.materials[1].phaseParameter, 0.4f);

  // listing_4_1.json is Listing 4.1 with only the grid's path changed.
  EXPECT_EQ(json::parse(readFile(scenes / "listing_4_1.json")), json::parse(listing41Json("data/cloud_128.vdb")));
  EXPECT_TRUE(parseScene(readFile(scenes / "listing_4_1.json"), scenePath()).warnings.empty());

  const Scene d = parseScene(readFile(scenes / "disney_cloud.json"), scenePath());
  EXPECT_TRUE(d.warnings.empty());
  EXPECT_EQ(d.materials[1].path, disney);
  EXPECT_EQ(d.renderer.spp, 64);
  // 126 x 86 x 154 voxels at 0.11 world units each.
  EXPECT_EQ(d.primitives[1].transform.scale, (Vec3f{13.86f, 9.46f, 16.94f}));
}

TEST(SceneShipped, DisneyCloudFindsTheSharedDataWithoutTheVariable) {
  ScopedEnv env("NARVAL_DATA_DIR", std::nullopt);
  const std::string grid = test::realDataPath("wdas_cloud_sixteenth.vdb");  // the build's default folder
  NARVAL_REQUIRE_REAL_DATA(grid);
  const Scene s = loadScene(std::string(NARVAL_SOURCE_DIR) + "/scenes/disney_cloud.json");
  EXPECT_EQ(fs::canonical(s.materials[1].path), fs::canonical(grid));
}

}  // namespace
}  // namespace narval
