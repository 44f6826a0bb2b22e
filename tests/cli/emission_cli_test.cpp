// Emission keys as a user meets them: every mistake in a volume's `emission` object is one line
// naming the scene file and the key, exit code 2, before anything is rendered, and no output
// written. The grids come from a test .vdb (writeVdbTestFile "emission": float grids "smoke" and
// "heat", a Vec3 grid "velocity").
#include <gtest/gtest.h>

#include <string>

#include "cli/cli_fixture.h"
#include "vdb_test_file.h"
#include "volume/dense_grid.h"

namespace narval {
namespace {

class EmissionCli : public test::CliFixture {
 protected:
  void SetUp() override { writeVdbTestFile((dir_ / "fire.vdb").string(), "emission"); }
  // The scene with the volume's extra fields `material` (JSON members after the required ones).
  void scene(const std::string& material) {
    write("s.json", R"({
      "materials": [{"name": "m", "type": "volume", "scattering": [1, 1, 1], "absorption": [1, 1, 1)" +
                        material + R"(}],
      "primitives": [{"type": "volume", "materialName": "m"}],
      "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
      "renderer": {"resolution": [8, 8], "spp": 2}, "background": [0.1, 0.1, 0.1]
    })");
  }
  void expectRefused(const std::string& material, const std::string& line) {
    scene(material);
    const test::RunResult r = run("render s.json -o out.exr --stats-json stats.json");
    EXPECT_EQ(r.code, 2) << material;
    EXPECT_EQ(r.err, "narval: " + line + "\n") << material;
    EXPECT_EQ(outputs({"s.json", "fire.vdb"}), std::vector<std::string>{}) << material;
  }
};

TEST_F(EmissionCli, MistakesAreOneLineNamingTheKey) {
  const std::string vdb = R"(], "path": "fire.vdb", "grid": "smoke")";
  const std::string file = (dir_ / "fire.vdb").string();
  expectRefused(vdb + R"(, "emission": {"temperature": "flame"})",
                "s.json: materials[0].emission.temperature: " + file +
                    ": no grid named 'flame' (the file has: heat, smoke, velocity (vec3s))");
  expectRefused(vdb + R"(, "emission": {"grid": "velocity"})",
                "s.json: materials[0].emission.grid: " + file +
                    ": 'velocity' is a vec3s grid; narval needs a float grid (float grids in the file: heat, smoke)");
  expectRefused(vdb + R"(, "emission": {"grid": "heat", "scale": -1})",
                "s.json: materials[0].emission.scale: must be non-negative, got -1");
  expectRefused(vdb + R"(, "emission": {"grid": "heat", "temperature": "heat"})",
                "s.json: materials[0].emission.temperature: give either \"grid\" (Le = color · scale · grid) or "
                "\"temperature\" (blackbody), not both");
  expectRefused(vdb + R"(, "emission": {"temperature": "heat", "color": [1, 0, 0]})",
                "s.json: materials[0].emission.color: does not apply to blackbody emission (\"temperature\")");
  expectRefused(vdb + R"(, "emission": {"grid": "heat", "temperatureScale": 2})",
                "s.json: materials[0].emission.temperatureScale: applies to blackbody emission only (give "
                "\"temperature\")");
  expectRefused(R"(], "emission": {"temperature": "heat"})",
                "s.json: materials[0].emission.temperature: names a grid, but the volume has no grid file (\"path\")");
  expectRefused(R"(], "emission": {"temperature": -5})", "s.json: materials[0].emission.temperature: must be non-negative, got -5");
  expectRefused(R"(], "emission": [1, 2])", "s.json: materials[0].emission: expected an object, got array");
}

TEST_F(EmissionCli, AFileWithoutDensityNeedsTheMaterialToNameItsGrid) {
  expectRefused(R"(], "path": "fire.vdb")",
                (dir_ / "fire.vdb").string() +
                    ": grid: no grid named 'density' (the file has: heat, smoke, velocity (vec3s))");
  // Naming one renders, and an emission grid with another transform and box than the density's.
  scene(R"(], "path": "fire.vdb", "grid": "smoke", "emission": {"temperature": "heat", "temperatureScale": 10})");
  const test::RunResult r = run("render s.json -o out.exr");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

}  // namespace
}  // namespace narval
