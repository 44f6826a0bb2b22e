// Emission's lookups on the host (kernels/shared/emission.h, compiled here with EMISSION as the
// kernels are with -DEMISSION), from a real .vdb through the loaders and the upload
// (cli_common.h loadSceneGrids, render/scene_upload.h buildDeviceScene):
// - an emission grid with another voxel size, offset and bounding box than the density grid is
//   placed where the file puts it (a field linear in world space, which trilinear filtering
//   reproduces exactly, read back at density-index points);
// - blackbody emission from a temperature grid is scale · B((v − offset) · temperatureScale), B the
//   host's blackbody colour (host/colour/blackbody.h, itself checked against the CIE tables in
//   blackbody_test.cpp) through the kernels' table;
// - nothing at or below 100 K; a constant temperature becomes a constant colour.
#define EMISSION 1
#include "shared/emission.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "colour/blackbody.h"
#include "render/scene_grids.h"
#include "render/scene_upload.h"
#include "scene/scene.h"
#include "test_support.h"
#include "unit/host_context.h"
#include "vdb_test_file.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

class EmissionLookup : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = tmp_.path();
    vdb_ = (dir_ / "fire.vdb").string();
    writeVdbTestFile(vdb_, "emission");
  }
  // A scene whose volume reads "smoke" from the test file and emits as `emission` (a JSON object),
  // its box rotated and scaled (the emission grid must follow the density grid, not the world).
  Scene scene(const std::string& emission, const std::string& gridSpace = "unit") const {
    return parseScene(R"({
      "materials": [{"name": "m", "type": "volume", "scattering": [1, 1, 1], "absorption": [2, 2, 2],
                     "path": ")" + vdb_ + R"(", "grid": "smoke", "gridSpace": ")" + gridSpace + R"(",
                     "emission": )" + emission + R"(}],
      "primitives": [{"type": "volume", "materialName": "m",
                      "transform": {"position": [1, 2, 3], "scale": [2, 3, 4], "rotation": [10, 20, 30]}}],
      "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
      "renderer": {"resolution": [4, 4]}
    })", (dir_ / "s.json").string());
  }
  test::TempDir tmp_{"narval_emission"};
  fs::path dir_;
  std::string vdb_;
};

// The host view of the uploaded grids, as the kernels get them.
grid_view viewOf(const DeviceScene& ds) {
  grid_view v{};
  v.data = ds.grid->data.data();
  v.nx = ds.grid->nx;
  v.ny = ds.grid->ny;
  v.nz = ds.grid->nz;
  if (ds.emissionGrid) {
    v.emission_data = ds.emissionGrid->data.data();
    v.emission_nx = ds.emissionGrid->nx;
    v.emission_ny = ds.emissionGrid->ny;
    v.emission_nz = ds.emissionGrid->nz;
  }
  v.emission_table = ds.emissionTable.data();
  return v;
}

// The file's world position of density-index point p (the loader's index-to-world map).
std::array<double, 3> fileWorld(const DenseGrid& g, const double p[3]) {
  std::array<double, 3> w{};
  for (int r = 0; r < 3; ++r)
    w[size_t(r)] = g.indexToWorld[size_t(4 * r)] * p[0] + g.indexToWorld[size_t(4 * r + 1)] * p[1] +
                   g.indexToWorld[size_t(4 * r + 2)] * p[2] + g.indexToWorld[size_t(4 * r + 3)];
  return w;
}

// The heat field of the test file at a world point (tests/vdb_test_file.h, writeVdbTestFile "emission").
double heatAt(const std::array<double, 3>& w) { return 100 + 10 * w[0] + 20 * w[1] + 30 * w[2]; }

TEST_F(EmissionLookup, AnEmissionGridIsPlacedByItsOwnTransformAndBox) {
  const Scene s = scene(R"({"grid": "heat", "color": [1, 0.5, 0.25], "scale": 0.5})");
  SceneGridStorage storage;
  const SceneGrids grids = loadSceneGrids(s, storage);
  ASSERT_NE(grids.emission, nullptr);
  // The two grids differ in size (8³ against 22³ voxels) and in placement.
  EXPECT_EQ(grids.density->nx, 8);
  EXPECT_EQ(grids.emission->nx, 22);
  const DeviceScene ds = buildDeviceScene(s, grids);
  ASSERT_EQ(ds.params.medium.emission.kind, EMISSION_COLOR);
  const grid_view view = viewOf(ds);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 8.0);  // the whole density box [0, 8]³
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    const vec3 Le = emission_radiance(narval::test::hostContext(&ds.params.medium, &view),
                                      vec3_make(float(p[0]), float(p[1]), float(p[2])));
    // Le = colour · scale · heat(world(p)); the heat grid is linear in world space, so trilinear
    // filtering at any point between its voxel centres gives it exactly (up to float rounding,
    // relative 1e-5 of values 10-640).
    const double h = heatAt(fileWorld(*grids.density, p));
    EXPECT_NEAR(Le.x, 0.5 * h, 1e-5 * 0.5 * h) << p[0] << " " << p[1] << " " << p[2];
    EXPECT_NEAR(Le.y, 0.25 * h, 1e-5 * 0.25 * h);
    EXPECT_NEAR(Le.z, 0.125 * h, 1e-5 * 0.125 * h);
    worst = std::max(worst, std::fabs(Le.x - 0.5 * h) / (0.5 * h));
  }
  std::printf("largest relative error of the placed emission grid: %.2e\n", worst);
  // The same in "file" grid space: placement goes through the file, whatever the box's world map.
  const Scene f = scene(R"({"grid": "heat"})", "file");
  const DeviceScene dsf = buildDeviceScene(f, loadSceneGrids(f, storage));
  const grid_view vf = viewOf(dsf);
  const double p[3] = {3.3, 4.1, 5.7};
  EXPECT_NEAR(emission_radiance(narval::test::hostContext(&dsf.params.medium, &vf), vec3_make(3.3f, 4.1f, 5.7f)).y,
              heatAt(fileWorld(storage.density, p)), 1e-5 * heatAt(fileWorld(storage.density, p)));
}

TEST_F(EmissionLookup, BlackbodyFromATemperatureGrid) {
  // T = (v − 200)·20 over the smoke's box, where v runs from 70 to 550: below 0 K (nothing at or
  // below 100 K) up to 7000 K.
  const Scene s = scene(R"({"temperature": "heat", "temperatureOffset": 200, "temperatureScale": 20, "scale": 3})");
  SceneGridStorage storage;
  const SceneGrids grids = loadSceneGrids(s, storage);
  const DeviceScene ds = buildDeviceScene(s, grids);
  const emission_params& e = ds.params.medium.emission;
  ASSERT_EQ(e.kind, EMISSION_BLACKBODY);
  // The table reaches past the hottest temperature the grid can give.
  EXPECT_GE(e.table_max, (grids.emission->maxValue - 200) * 20);
  EXPECT_EQ(e.table_size, kBlackbodyTableSize);
  const grid_view view = viewOf(ds);
  const float red1000 = blackbodyLinearSrgb(1000)[0];
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 8.0);
  int hot = 0, cold = 0;
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    const vec3 Le = emission_radiance(narval::test::hostContext(&ds.params.medium, &view),
                                      vec3_make(float(p[0]), float(p[1]), float(p[2])));
    const double T = (heatAt(fileWorld(*grids.density, p)) - 200) * 20;
    if (T <= 100) {
      // Nothing at or below 100 K, exactly (emission_blackbody's rule, not the table's).
      EXPECT_EQ(Le.x, 0.0f);
      EXPECT_EQ(Le.y, 0.0f);
      EXPECT_EQ(Le.z, 0.0f);
      ++cold;
      continue;
    }
    ++hot;
    const std::array<float, 3> B = blackbodyLinearSrgb(T);
    // Against the largest channel: the table's step (2.2 K here) and the temperature's float
    // rounding move B by well under 1e-3 of it from 1000 K up (TheTableFollowsTheBlackbody...);
    // below, where the step is long against B's change, against that of 1000 K, which is itself a
    // dim glow (linear sRGB channels may be negative or tiny).
    const double peak = 3 * std::max({std::fabs(B[0]), std::fabs(B[1]), std::fabs(B[2]), red1000});
    for (int c = 0; c < 3; ++c) {
      const double got = c == 0 ? Le.x : c == 1 ? Le.y : Le.z;
      EXPECT_NEAR(got, 3 * B[size_t(c)], 1e-3 * peak) << "T = " << T << " channel " << c;
      worst = std::max(worst, std::fabs(got - 3 * B[size_t(c)]) / peak);
    }
  }
  EXPECT_GT(hot, 1000);
  EXPECT_GT(cold, 0);
  std::printf("largest error of blackbody emission, relative to its largest channel: %.2e\n", worst);
}

TEST_F(EmissionLookup, TheTableFollowsTheBlackbodyBetweenItsEntries) {
  const Scene s = scene(R"({"temperature": "heat", "temperatureScale": 5})");  // up to 3200 K, a fire's range
  SceneGridStorage storage;
  const DeviceScene ds = buildDeviceScene(s, loadSceneGrids(s, storage));
  const emission_params& e = ds.params.medium.emission;
  // Halfway between entries, where linear interpolation is furthest off, from 500 K to the top. The
  // error is that of a linear fit to e^{−hc/λkT} over a step ΔT: about (hc/λkT² · ΔT)²/8 relative,
  // largest at low T and short λ; 500 K glows 1e-7 as brightly as 3000 K, so the visible range
  // from 1000 K up is reported apart.
  const double step = double(e.table_max) / (e.table_size - 1);
  double worst = 0, worstVisible = 0;
  for (double T = 500 + 0.5 * step; T < e.table_max; T += 7 * step) {
    const vec3 b = emission_blackbody(&e, ds.emissionTable.data(), float(T));
    const std::array<float, 3> B = blackbodyLinearSrgb(T);
    const double peak = std::max({std::fabs(B[0]), std::fabs(B[1]), std::fabs(B[2])});
    const double err = std::max({std::fabs(b.x - B[0]), std::fabs(b.y - B[1]), std::fabs(b.z - B[2])}) / peak;
    worst = std::max(worst, err);
    if (T >= 1000) worstVisible = std::max(worstVisible, err);
  }
  std::printf("largest table interpolation error, relative to the largest channel: %.2e from 500 K, %.2e from "
              "1000 K (step %.3f K)\n", worst, worstVisible, step);
  EXPECT_LT(worst, 1e-3);
  EXPECT_LT(worstVisible, 1e-4);
  // Exactly 0 at and below 100 K, and for a NaN temperature.
  for (float T : {-5.0f, 0.0f, 50.0f, 100.0f, NAN}) {
    const vec3 b = emission_blackbody(&e, ds.emissionTable.data(), T);
    EXPECT_TRUE(b.x == 0.0f && b.y == 0.0f && b.z == 0.0f) << T;
  }
  // Above the table (no grid value gets there): its last entry.
  const vec3 top = emission_blackbody(&e, ds.emissionTable.data(), 2 * e.table_max);
  EXPECT_EQ(top.x, ds.emissionTable[ds.emissionTable.size() - 3]);
}

TEST_F(EmissionLookup, AConstantTemperatureIsAConstantColour) {
  const Scene s = parseScene(R"({
      "materials": [{"name": "m", "type": "volume", "scattering": [0, 0, 0], "absorption": [1, 1, 1],
                     "emission": {"temperature": 1500, "scale": 2}}],
      "primitives": [{"type": "volume", "materialName": "m"}],
      "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
      "renderer": {"resolution": [4, 4]}
    })", "s.json");
  const DeviceScene ds = buildDeviceScene(s, SceneGrids{});
  const emission_params& e = ds.params.medium.emission;
  ASSERT_EQ(e.kind, EMISSION_COLOR);
  EXPECT_EQ(e.grid_dims.x, 0.0f);  // no grid: v = 1
  const std::array<float, 3> B = blackbodyLinearSrgb(1500);
  EXPECT_EQ(e.color.x, 2 * B[0]);
  EXPECT_EQ(e.color.y, 2 * B[1]);
  EXPECT_EQ(e.color.z, 2 * B[2]);
  // A medium that does not emit has kind none and no table to speak of.
  const Scene dark = parseScene(R"({
      "materials": [{"name": "m", "type": "volume", "scattering": [1, 1, 1], "absorption": [1, 1, 1]}],
      "primitives": [{"type": "volume", "materialName": "m"}],
      "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
      "renderer": {"resolution": [4, 4]}, "background": [1, 1, 1]
    })", "s.json");
  const DeviceScene dd = buildDeviceScene(dark, SceneGrids{});
  EXPECT_EQ(dd.params.medium.emission.kind, EMISSION_NONE);
  EXPECT_EQ(dd.emissionTable.size(), 3u);
}

}  // namespace
}  // namespace narval
