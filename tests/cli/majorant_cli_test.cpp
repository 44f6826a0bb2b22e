// --majorant, --majorant-resolution and --counters as a user meets them: the stats JSON keys
// (majorant, majorant_cells, and with --counters collisions_tentative, collisions_real,
// density_lookups), usage errors with exit code 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "image/image.h"
#include "test_support.h"

namespace narval {
namespace {

using test::readFile;
using test::RunResult;

// A 12³ .vol grid (a ball of density 1 in the middle, empty around it) in a unit box, a point light
// beside it, 8×8 px, 4 spp.
class MajorantCli : public test::CliFixture {
 protected:
  void writeScene() {
    std::string vol = "12 12 12\n";
    for (int z = 0; z < 12; ++z)
      for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 12; ++x) {
          const double dx = x - 5.5, dy = y - 5.5, dz = z - 5.5;
          vol += (dx * dx + dy * dy + dz * dz < 9 ? "1 " : "0 ");
        }
    write("ball.vol", vol + "\n");
    write("scene.json", R"({
      "materials": [
        {"name": "light", "type": "emitter", "albedo": [5, 5, 5]},
        {"name": "m", "type": "volume", "scattering": [4, 4, 4], "absorption": [0.5, 0.5, 0.5],
         "phaseFunction": "isotropic", "path": "ball.vol", "density": 1}
      ],
      "primitives": [
        {"name": "pl", "type": "point", "transform": {"position": [1, 1, -1]}, "materialName": "light"},
        {"name": "box", "type": "volume", "transform": {"scale": [1, 1, 1]}, "materialName": "m"}
      ],
      "camera": {"position": [0, 0, -3], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 30},
      "renderer": {"resolution": [8, 8], "spp": 4, "bounces": 3}
    })");
  }
};

// Default (auto): the grid on CPUs, the global majorant on GPUs, as resolved; automatic cells (12³
// grid: min(12, 32) on CPUs, min(12, 16) elsewhere = 12 per axis); no counter keys.
// --majorant grid|global --counters: the three counts as integers, tentative >= real > 0, lookups >
// tentative (shadow rays); the grid's tentative count is below the global one's on the same scene.
TEST_F(MajorantCli, StatsJsonReportsMajorantAndCounters) {
  writeScene();
  RunResult r = run("render scene.json -o a.exr --stats-json a.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json a = nlohmann::json::parse(readFile(dir_ / "a.json"));
  // The default device is the first GPU, else the first CPU (narval devices): auto picks for it.
  const RunResult d = run("devices --json");
  ASSERT_EQ(d.code, 0) << d.err;
  bool gpu = false;
  for (const nlohmann::json& dev : nlohmann::json::parse(d.out)) gpu = gpu || dev["type"] == "GPU";
  EXPECT_EQ(a["majorant"], gpu ? "global" : "grid");
  EXPECT_EQ(a["majorant_cells"], nlohmann::json({12, 12, 12}));
  EXPECT_FALSE(a.contains("collisions_tentative"));
  r = run("render scene.json -o a.exr --majorant auto --stats-json a2.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(readFile(dir_ / "a2.json"))["majorant"], a["majorant"]);

  unsigned long long tentative[2] = {0, 0};
  const char* modes[2] = {"grid", "global"};
  for (int i = 0; i < 2; ++i) {
    r = run(std::string("render scene.json -o b.exr --counters --majorant ") + modes[i] + " --stats-json b.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json b = nlohmann::json::parse(readFile(dir_ / "b.json"));
    EXPECT_EQ(b["majorant"], modes[i]);
    ASSERT_TRUE(b["collisions_tentative"].is_number_unsigned()) << b.dump();
    ASSERT_TRUE(b["collisions_real"].is_number_unsigned());
    ASSERT_TRUE(b["density_lookups"].is_number_unsigned());
    tentative[i] = b["collisions_tentative"].get<unsigned long long>();
    const auto real = b["collisions_real"].get<unsigned long long>();
    EXPECT_GT(real, 0u);
    EXPECT_GE(tentative[i], real);
    EXPECT_GT(b["density_lookups"].get<unsigned long long>(), tentative[i]);
  }
  EXPECT_LT(tentative[0], tentative[1]);
}

// --majorant-resolution 4: 4 cells per axis; 0 is automatic.
TEST_F(MajorantCli, ResolutionOverride) {
  writeScene();
  RunResult r = run("render scene.json -o a.exr --majorant-resolution 4 --stats-json a.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(readFile(dir_ / "a.json"))["majorant_cells"], nlohmann::json({4, 4, 4}));
  r = run("render scene.json -o a.exr --majorant-resolution 0 --stats-json a.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(readFile(dir_ / "a.json"))["majorant_cells"], nlohmann::json({12, 12, 12}));
}

// Usage errors, exit 2 with one line naming the option: an unknown majorant, a negative resolution,
// --counters with a real-time algorithm (only the path tracer counts).
TEST_F(MajorantCli, BadUsageExitsWithTwo) {
  writeScene();
  RunResult r = run("render scene.json -o a.exr --majorant octree");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--majorant"), std::string::npos) << r.err;
  r = run("render scene.json -o a.exr --majorant-resolution -3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--majorant-resolution"), std::string::npos) << r.err;
  r = run("render scene.json -o a.exr --algorithm raymarch --counters");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--counters"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// --resume keeps the majorant (and the grid's resolution) the file was rendered with: its samples
// depend on them. A render of 2 spp with --majorant global (or the grid at 4 cells), resumed to 4 spp
// without naming the majorant, has the bits of one 4-spp render with it; naming another is exit 2.
TEST_F(MajorantCli, ResumeKeepsTheFilesMajorant) {
  writeScene();
  struct Case {
    std::string options, other;
  };
  for (const Case& c : {Case{"--majorant global", "--majorant grid"},
                        Case{"--majorant grid --majorant-resolution 4", "--majorant-resolution 6"}}) {
    SCOPED_TRACE(c.options);
    RunResult r = run("render scene.json -o part.exr --spp 2 " + c.options);
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("render scene.json -o part.exr --spp 4 --resume --stats-json p.json");
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("render scene.json -o full.exr --spp 4 " + c.options + " --stats-json f.json");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(readExr((dir_ / "part.exr").string()).rgb, readExr((dir_ / "full.exr").string()).rgb);
    const nlohmann::json p = nlohmann::json::parse(readFile(dir_ / "p.json")),
                         f = nlohmann::json::parse(readFile(dir_ / "f.json"));
    EXPECT_EQ(p["majorant"], f["majorant"]);
    EXPECT_EQ(p["majorant_cells"], f["majorant_cells"]);
    r = run("render scene.json -o full.exr --spp 8 --resume " + c.other);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(c.other.substr(0, c.other.find(' '))), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace narval
