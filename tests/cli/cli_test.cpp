// The narval binary as a user runs it: exit codes, the one-line errors (file and key named), and
// that a failed run writes nothing and overwrites nothing (DESIGN.md, command line).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "image/image.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

using test::listing41Json;
using test::readFile;
using test::realDataPath;

using test::RunResult;

// Each test runs narval in a fresh folder of its own.
class Cli : public test::CliFixture {};

TEST_F(Cli, Listing41RendersWithOverrides) {
  writeVdb((dir_ / "cloud.vdb").string(), makeCloud(16, 1));
  write("scene.json", listing41Json("cloud.vdb"));
  const RunResult r = run("render scene.json -o out/listing.exr --resolution 24x12 --spp 2 --stats-json stats.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out/listing.exr"));
  EXPECT_TRUE(fs::exists(dir_ / "out/listing.png"));
  const ImageRGB img = readExr((dir_ / "out/listing.exr").string());
  EXPECT_EQ(img.width, 24);
  EXPECT_EQ(img.height, 12);
  const nlohmann::json stats = nlohmann::json::parse(readFile(dir_ / "stats.json"));
  for (const char* key : {"algorithm", "device", "width", "height", "spp", "bounces", "seconds", "kernel_seconds",
                          "samples_per_second", "nan_pixels"})
    EXPECT_TRUE(stats.contains(key)) << key;
  EXPECT_EQ(stats["algorithm"], "pathtrace");
  EXPECT_EQ(stats["spp"], 2);
  EXPECT_EQ(stats["bounces"], 3);
  EXPECT_EQ(stats["width"], 24);
  EXPECT_EQ(stats["nan_pixels"], 0);
  // The light behind the cloud faces the camera: the image is not black.
  double sum = 0;
  for (float v : img.rgb) sum += v;
  EXPECT_GT(sum, 0.0);
}

// Each bad input: exit 2, exactly one line on stderr that names the file and the key, no output
// written, and an existing output left as it was.
void expectBadInput(Cli& t, const RunResult& r, const std::string& expectedLine) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err, expectedLine + "\n");
}

TEST_F(Cli, MalformedJson) {
  write("scene.json", "{\"materials\": [\n  {\"name\": }\n");
  write("keep.exr", "precious");
  const RunResult r = run("render scene.json -o keep.exr");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("narval: scene.json: ", 0), 0u) << r.err;
  EXPECT_EQ(readFile(dir_ / "keep.exr"), "precious");
  EXPECT_EQ(outputs({"scene.json", "keep.exr"}), std::vector<std::string>{});
}

TEST_F(Cli, WrongType) {
  writeVdb((dir_ / "cloud.vdb").string(), makeCloud(8, 1));
  std::string s = listing41Json("cloud.vdb");
  s.replace(s.find("\"spp\": 1000"), 11, "\"spp\": \"many\"");
  write("scene.json", s);
  expectBadInput(*this, run("render scene.json"), "narval: scene.json: renderer.spp: expected an integer, got string");
  EXPECT_EQ(outputs({"scene.json", "cloud.vdb"}), std::vector<std::string>{});
}

TEST_F(Cli, MissingKey) {
  writeVdb((dir_ / "cloud.vdb").string(), makeCloud(8, 1));
  std::string s = listing41Json("cloud.vdb");
  s.replace(s.find("\"lookAt\": [0, 0, 0],"), 20, "");
  write("scene.json", s);
  expectBadInput(*this, run("render scene.json"), "narval: scene.json: camera.lookAt: missing required key");
  EXPECT_EQ(outputs({"scene.json", "cloud.vdb"}), std::vector<std::string>{});
}

TEST_F(Cli, MissingVolumeFile) {
  write("scene.json", listing41Json("vdb/wdas_cloud_quarter.vdb"));
  const RunResult r = run("render scene.json");
  expectBadInput(*this, r,
                 "narval: scene.json: materials[1].path: volume file not found: " +
                     (dir_ / "vdb/wdas_cloud_quarter.vdb").lexically_normal().string());
  EXPECT_EQ(outputs({"scene.json"}), std::vector<std::string>{});
}

TEST_F(Cli, MissingSceneFile) {
  expectBadInput(*this, run("render nowhere.json"), "narval: nowhere.json: cannot open scene file");
}

TEST_F(Cli, MissingGridListsTheGridsPresent) {
  DenseGrid g = makeCloud(8, 1);
  writeVdb((dir_ / "smoke.vdb").string(), g, "smoke");
  write("scene.json", listing41Json("smoke.vdb"));
  const RunResult r = run("render scene.json");
  expectBadInput(*this, r,
                 "narval: " + (dir_ / "smoke.vdb").string() + ": grid: no grid named 'density' (the file has: smoke)");
  EXPECT_EQ(outputs({"scene.json", "smoke.vdb"}), std::vector<std::string>{});
}

TEST_F(Cli, RealFireHasNoDensityGrid) {
  const std::string fire = realDataPath("embergen_fire_a_50.vdb");
  NARVAL_REQUIRE_REAL_DATA(fire);
  write("scene.json", listing41Json(fire));
  const RunResult r = run("render scene.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no grid named 'density' (the file has: flames, temperature)"), std::string::npos) << r.err;
}

TEST_F(Cli, UnknownAlgorithmAndBadOptions) {
  writeVdb((dir_ / "cloud.vdb").string(), makeCloud(8, 1));
  write("scene.json", listing41Json("cloud.vdb"));
  expectBadInput(*this, run("render scene.json --algorithm photons"),
                 "narval: scene.json: renderer.algorithm: unknown value \"photons\" (allowed: pathtrace, raymarch, lobe)");
  expectBadInput(*this, run("render scene.json --resolution 10by3"),
                 "narval: --resolution: expected WIDTHxHEIGHT with positive integers, got '10by3'");
  EXPECT_EQ(run("render scene.json --spp -3").code, 2);
  EXPECT_EQ(run("render").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(outputs({"scene.json", "cloud.vdb"}), std::vector<std::string>{});
}

// narval scene --resolved prints the scene with its defaults written out (--set applied), which
// renders as the scene does; --keys prints the loader's key table; misuse is one line, exit 2.
TEST_F(Cli, SceneResolvedAndKeys) {
  writeVdb((dir_ / "cloud.vdb").string(), makeCloud(8, 1));
  write("scene.json", listing41Json("cloud.vdb"));
  const RunResult r = run("scene scene.json --set renderer.spp=7 --resolved");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc["renderer"]["spp"], 7);
  EXPECT_EQ(doc["renderer"]["raymarch"]["steps"], 30);  // with the cache, at the interactive quality
  write("resolved.json", r.out);
  EXPECT_EQ(run("scene resolved.json --resolved").out, r.out);

  const RunResult keys = run("scene --keys");
  ASSERT_EQ(keys.code, 0) << keys.err;
  bool found = false;
  for (const auto& k : nlohmann::json::parse(keys.out))
    if (k["key"] == "renderer.bounces") {
      found = true;
      EXPECT_EQ(k["defaults"], nlohmann::json::array({3}));
      EXPECT_EQ(k["type"], "integer");
    }
  EXPECT_TRUE(found);

  expectBadInput(*this, run("scene scene.json"), "narval: narval scene: give --resolved (with a SCENE.json) or --keys");
  expectBadInput(*this, run("scene --resolved"), "narval: --resolved: needs a SCENE.json");
  expectBadInput(*this, run("scene scene.json --keys"),
                 "narval: --keys: takes no scene, --set or --resolved (it lists the format's keys)");
  expectBadInput(*this, run("scene scene.json --resolved --set renderer.sp=3"),
                 "narval: scene.json: --set renderer.sp: not a scene setting (unknown key renderer.sp; did you mean "
                 "renderer.spp?)");
  EXPECT_EQ(outputs({"scene.json", "cloud.vdb", "resolved.json"}), std::vector<std::string>{});
}

TEST_F(Cli, DevicesJsonListsAtLeastOneDevice) {
  const RunResult r = run("devices --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_array());
  ASSERT_GE(j.size(), 1u);
  EXPECT_TRUE(j[0].contains("name"));
  EXPECT_TRUE(j[0].contains("max_alloc_bytes"));
}

TEST_F(Cli, MakeCloudWritesTheGeneratedGrid) {
  const RunResult r = run("make-cloud c.vdb --resolution 20 --seed 9");
  ASSERT_EQ(r.code, 0) << r.err;
  const DenseGrid fromFile = loadGrid((dir_ / "c.vdb").string(), "density");
  const DenseGrid direct = makeCloud(20, 9);
  // The file holds the active bounding box only: compare the maxima and the total mass.
  EXPECT_EQ(fromFile.maxValue, direct.maxValue);
  double a = 0, b = 0;
  for (float v : fromFile.data) a += v;
  for (float v : direct.data) b += v;
  EXPECT_NEAR(a, b, 1e-9 * b);
}

// The output's folder is made as the other commands make theirs; a folder in the way is one line,
// exit 2, before any work.
TEST_F(Cli, MakeCloudMakesItsFolderAndRefusesAFolderAsOutput) {
  const RunResult r = run("make-cloud new/deeper/c.vdb --resolution 8");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "new" / "deeper" / "c.vdb"));
  fs::create_directories(dir_ / "taken.vdb");
  const RunResult refused = run("make-cloud taken.vdb --resolution 8");
  EXPECT_EQ(refused.code, 2);
  EXPECT_EQ(refused.err, "narval: OUT.vdb: cannot write taken.vdb: it is a folder\n");
  EXPECT_EQ(refused.out, "");
}

}  // namespace
}  // namespace narval

namespace narval {
namespace {

// The dragon's file transform rotates and shears: in the default "unit" grid space that part is
// dropped, and the user is told so (DESIGN.md, physics conventions); "file" keeps it, silently.
TEST_F(Cli, DragonTransformWarningInUnitGridSpaceOnly) {
  const std::string dragon = realDataPath("vpt_dragon_with_xform.vdb");
  NARVAL_REQUIRE_REAL_DATA(dragon);
  write("scene.json", listing41Json(dragon));
  RunResult r = run("render scene.json --resolution 8x4 --spp 1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err,
            "narval: warning: scene.json: materials[1].gridSpace: the grid's file transform rotates or shears; "
            "\"unit\" grid space drops it (set \"gridSpace\": \"file\" to keep it)\n");
  r = run("render scene.json --resolution 8x4 --spp 1 --set materials.1.gridSpace=file");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

}  // namespace
}  // namespace narval

namespace narval {
namespace {

// --frames K: K timed launches; the first (program build on first launch, warm-up) reported apart,
// median/min/max over the other K-1, so min <= median <= max. Every algorithm accepts it; the
// path tracer's frame is one pass of 1 spp, so its image holds K spp.
TEST_F(Cli, FramesReportMillisecondsPerFrameForEveryAlgorithm) {
  writeVdb((dir_ / "cloud.vdb").string(), makeCloud(16, 1));
  write("scene.json", test::listing41Json("cloud.vdb"));
  for (const std::string algorithm : {"raymarch", "lobe", "pathtrace"}) {
    const RunResult r = run("render scene.json -o " + algorithm + ".exr --resolution 16x8 --frames 3 --algorithm " +
                            algorithm + " --stats-json " + algorithm + ".json");
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json s = nlohmann::json::parse(test::readFile((dir_ / (algorithm + ".json")).string()));
    EXPECT_EQ(s["algorithm"], algorithm);
    const nlohmann::json& f = s["ms_per_frame"];
    EXPECT_EQ(f["frames"], 3);
    EXPECT_GT(f["first_frame_ms"]["kernel"].get<double>(), 0.0);
    EXPECT_LE(f["min"].get<double>(), f["median"].get<double>());
    EXPECT_LE(f["median"].get<double>(), f["max"].get<double>());
    EXPECT_GT(f["min"].get<double>(), 0.0);
    if (algorithm == "pathtrace") EXPECT_EQ(s["spp"], 3);
    EXPECT_TRUE(fs::exists(dir_ / (algorithm + ".png")));
  }
}

}  // namespace
}  // namespace narval
