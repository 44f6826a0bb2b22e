// The view-space layout of the multiple-scattering cache (kernels/shared/ms_cache_view.h): how a
// pixel finds its columns, how a column is read along the optical depth, and where its nodes are placed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/realtime_params.h"
#include "render/scene_upload.h"
#include "scene/scene.h"
#include "shared/ms_cache_view.h"
#include "unit/host_context.h"

namespace narval::test {
namespace {

// A cache of nx x ny columns and nz slices whose node (cx, cy, s) holds optical depth tau(cx, cy, s)
// and value value(cx, cy, s) in every channel.
template <typename Tau, typename Value>
std::vector<float> viewCache(const node_grid_params& c, Tau tau, Value value) {
  std::vector<float> cache(size_t(c.nx * c.ny * c.nz) * MS_CACHE_STRIDE, 0.0f);
  for (int s = 0; s < c.nz; ++s)
    for (int cy = 0; cy < c.ny; ++cy)
      for (int cx = 0; cx < c.nx; ++cx) {
        float* v = cache.data() + size_t(cx + c.nx * (cy + c.ny * s)) * MS_CACHE_STRIDE;
        v[0] = v[1] = v[2] = value(cx, cy, s);
        v[MS_VIEW_TAU] = tau(cx, cy, s);
      }
  return cache;
}

ms_cache_params viewParams(int nx, int ny, int nz, int tile) {
  ms_cache_params mc{};
  mc.grid.nx = nx;
  mc.grid.ny = ny;
  mc.grid.nz = nz;
  mc.layout = MS_CACHE_LAYOUT_VIEW;
  mc.tile = tile;
  return mc;
}

// msCache.tile "auto" (realtime_params.h): a column a pixel on a GPU; on a CPU the smallest side t
// with W·H/t² at most the quality's columns (draft 160·120 = 19,200, interactive 76,800, high
// 307,200); an explicit tile wins everywhere.
TEST(MsCacheView, AnAutomaticTileIsAPixelOnGpusAndBoundsTheColumnsOnCpus) {
  RaymarchSettings r;
  ASSERT_EQ(r.msCache.tile, kMsCacheTileAuto);
  const struct {
    RaymarchQuality quality;
    double width, height;
    int cpuTile;
  } cases[] = {
      {RaymarchQuality::Interactive, 320, 240, 1},    // 76,800 columns: the bound itself
      {RaymarchQuality::Interactive, 321, 240, 2},    // one column over: 77,040 / 4
      {RaymarchQuality::Interactive, 640, 360, 2},    // 57,600
      {RaymarchQuality::Interactive, 1280, 720, 4},   // 57,600
      {RaymarchQuality::Interactive, 1920, 1080, 6},  // 2,073,600 / 25 = 82,944 > 76,800; / 36 = 57,600
      {RaymarchQuality::Draft, 320, 240, 2},          // 19,200
      {RaymarchQuality::High, 640, 480, 1},
      {RaymarchQuality::High, 1280, 720, 2},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::to_string(int(c.width)) + "x" + std::to_string(int(c.height)));
    r.quality = c.quality;
    r.msCache.tile = kMsCacheTileAuto;
    EXPECT_EQ(msCacheTile(r, c.width * c.height, false), c.cpuTile);
    EXPECT_EQ(msCacheTile(r, c.width * c.height, true), 1);
    r.msCache.tile = 3;
    EXPECT_EQ(msCacheTile(r, c.width * c.height, false), 3);
    EXPECT_EQ(msCacheTile(r, c.width * c.height, true), 3);
  }
}

// A pixel at its column's centre reads that column alone; one between column centres reads them
// bilinearly; past the outer centres it reads the edge column (no extrapolation).
TEST(MsCacheView, PixelsFindTheirColumnsBilinearly) {
  const ms_cache_params rp = viewParams(3, 2, 2, 4);  // a 12x8 image in 4x4 tiles
  // Pixel px's centre is px + 0.5, column cx's (cx + 0.5)·4, so in column units u = (px + 0.5)/4 − 0.5.
  ms_view_columns cols = ms_view_locate(&rp, 5, 1);
  // x: u = 5.5/4 − 0.5 = 0.875 → columns 0 and 1 with weights 0.125 and 0.875; y: u = 1.5/4 − 0.5 <
  // 0 → row 0 alone.
  EXPECT_EQ(cols.column[0], 0);
  EXPECT_EQ(cols.column[1], 1);
  EXPECT_FLOAT_EQ(cols.w[0], 0.125f);
  EXPECT_FLOAT_EQ(cols.w[1], 0.875f);
  EXPECT_FLOAT_EQ(cols.w[2] + cols.w[3], 0.0f);
  // The last pixel column (11): u = 11.5/4 − 0.5 = 2.375 > 2: the last column alone.
  cols = ms_view_locate(&rp, 11, 7);
  float total = 0;
  for (int k = 0; k < 4; ++k) {
    total += cols.w[k];
    if (cols.w[k] > 0) EXPECT_EQ(cols.column[k], 2 + 3 * 1);
  }
  EXPECT_FLOAT_EQ(total, 1.0f);
  // One column across: every pixel reads it with weight 1 (no second column exists to read).
  const ms_cache_params one = viewParams(1, 1, 2, 64);
  cols = ms_view_locate(&one, 40, 3);
  EXPECT_EQ(cols.column[0], 0);
  EXPECT_FLOAT_EQ(cols.w[0], 1.0f);
  for (int k = 1; k < 4; ++k) EXPECT_EQ(cols.column[k] == 0 || cols.w[k] == 0.0f, true);
}

// Along a column each slice [τ_s, τ_{s+1}) gives its node's value (the slice's mean; ms_cache_view.h,
// "A node holds the slice's mean"): a sample before the first slice reads it, one past the last
// start reads the last; across columns the values mix bilinearly.
TEST(MsCacheView, ColumnsAreReadSliceBySliceInOpticalDepth) {
  const ms_cache_params rp = viewParams(2, 2, 4, 4);
  auto tau = [](int cx, int cy, int s) { return 0.5f * float(s * s) + 0.1f * float(cx + cy); };  // uneven spacing
  auto value = [](int cx, int cy, int s) { return 2.0f + 3.0f * float(s) + 10.0f * float(cx + 2 * cy); };
  const std::vector<float> cache = viewCache(rp.grid, tau, value);
  // Pixel (1, 1) of the 8x8 image: u = 1.5/4 − 0.5 < 0 → column (0, 0) alone, slice starts 0, 0.5, 2, 4.5.
  const ms_view_columns corner = ms_view_locate(&rp, 1, 1);
  const float expected[][2] = {{-1.0f, 2}, {0.0f, 2}, {0.49f, 2}, {0.5f, 5}, {1.99f, 5}, {2.0f, 8}, {4.49f, 8},
                               {4.5f, 11}, {9.0f, 11}};
  for (const auto& e : expected) EXPECT_EQ(ms_view_lookup(&rp.grid, cache.data(), &corner, e[0], 0.0f).y, e[1]) << e[0];
  // Pixel (3, 4): u = (0.375, 0.625), weights 0.625·0.375, 0.375·0.375, 0.625·0.625, 0.375·0.625 on
  // columns (0,0), (1,0), (0,1), (1,1). At τ = 1 column (0,0) is in slice 1 (starts 0, 0.5, 2), (1,0)
  // and (0,1) too (0.1, 0.6, 2.1), (1,1) too (0.2, 0.7, 2.2): 5 + 10·(0.375 + 2·0.625 … ) bilinear.
  const ms_view_columns mid = ms_view_locate(&rp, 3, 4);
  const float bilinear = 5.0f + 10.0f * (0.375f + 2.0f * 0.625f);
  EXPECT_NEAR(ms_view_lookup(&rp.grid, cache.data(), &mid, 1.0f, 0.0f).x, bilinear, 1e-5f);
  // At τ = 0.55 column (0,0) is in slice 1 (0.5 ≤ τ) and the others still in slice 0 (0.6, 0.6, 0.7).
  const float mixed = 0.625f * 0.375f * 5.0f + 0.375f * 0.375f * 12.0f + 0.625f * 0.625f * 22.0f +
                      0.375f * 0.625f * 32.0f;
  EXPECT_NEAR(ms_view_lookup(&rp.grid, cache.data(), &mid, 0.55f, 0.0f).x, mixed, 1e-5f);
}

// A march step from τ to τ + Δτ reads each column's piecewise-constant J weighted by e^{−(τ' − τ)}
// over the step, normalised by 1 − e^{−Δτ} (the weight the energy-conserving step gives it):
// column (0, 0) of the cache above has slices from 0, 0.5, 2, 4.5 holding 2, 5, 8, 11.
//  - [0.3, 0.8] crosses 0.5: (2·(1 − e^{−0.2}) + 5·e^{−0.2}(1 − e^{−0.3}))/(1 − e^{−0.5});
//  - [4, 6] crosses 4.5 into the last slice, which runs on: (8·(1 − e^{−0.5}) + 11·e^{−0.5}(1 − e^{−1.5}))/(1 − e^{−2});
//  - a step inside one slice reads its value, and a tiny step the slice it starts in.
TEST(MsCacheView, AStepReadsItsSlicesWeightedByItsOwnAttenuation) {
  const ms_cache_params rp = viewParams(2, 2, 4, 4);
  auto tau = [](int cx, int cy, int s) { return 0.5f * float(s * s) + 0.1f * float(cx + cy); };
  auto value = [](int cx, int cy, int s) { return 2.0f + 3.0f * float(s) + 10.0f * float(cx + 2 * cy); };
  const std::vector<float> cache = viewCache(rp.grid, tau, value);
  const ms_view_columns corner = ms_view_locate(&rp, 1, 1);
  auto read = [&](float t, float dt) { return double(ms_view_lookup(&rp.grid, cache.data(), &corner, t, dt).x); };
  const double e = std::exp(1.0);
  EXPECT_NEAR(read(0.3f, 0.5f), (2 * (1 - std::pow(e, -0.2)) + 5 * std::pow(e, -0.2) * (1 - std::pow(e, -0.3))) /
                                    (1 - std::pow(e, -0.5)), 1e-5);
  EXPECT_NEAR(read(4.0f, 2.0f), (8 * (1 - std::pow(e, -0.5)) + 11 * std::pow(e, -0.5) * (1 - std::pow(e, -1.5))) /
                                    (1 - std::pow(e, -2.0)), 1e-5);
  EXPECT_NEAR(read(0.6f, 1.0f), 5.0, 1e-5);
  EXPECT_NEAR(read(1.9f, 1e-7f), 5.0, 1e-4);
}

// A column whose ray meets no medium (τ = −1) drops out and the others' weights are renormalised;
// with none left the lookup is 0.
TEST(MsCacheView, ColumnsWithoutMediumDropOut) {
  const ms_cache_params rp = viewParams(2, 1, 2, 4);
  auto tau = [](int cx, int, int s) { return cx == 0 ? -1.0f : float(s); };
  auto value = [](int cx, int, int) { return cx == 0 ? 100.0f : 7.0f; };
  std::vector<float> cache = viewCache(rp.grid, tau, value);
  const ms_view_columns cols = ms_view_locate(&rp, 3, 0);  // between the two columns
  EXPECT_GT(cols.w[0], 0.0f);
  EXPECT_FLOAT_EQ(ms_view_lookup(&rp.grid, cache.data(), &cols, 0.5f, 0.0f).x, 7.0f);
  for (int s = 0; s < 2; ++s) cache[size_t(1 + 2 * s) * MS_CACHE_STRIDE + MS_VIEW_TAU] = -1.0f;
  EXPECT_EQ(ms_view_lookup(&rp.grid, cache.data(), &cols, 0.5f, 0.0f).x, 0.0f);
}

// Placement in a homogeneous cube [−½, ½]³ of σt = 6 (grey), seen from (0, 0, −4) at 30°: along a
// column's ray τ(t) = 6·(t − t0) exactly (the march's linear τ within a step is then exact), so
// level i lies at t_i = t0 + level_i/6, level_i = −ln(1 − (1 − T_end)·i/nz) with T_end =
// max(e^{−τ_end}, 0.01) ("Layout"), and node s spans levels s and s + 1; τ_end = 6·(t1 − t0) ≈ 6
// passes τ_max = ln 100 = 4.61, so the last slice ends at τ_max, inside the cube. In the 8x8 image
// at tile 2 the inner four columns' rays (pixel centres 3 and 5: 0.25 of the half-width, 0.23
// world units off the axis at the front face) cross the cube front to back; the outer twelve
// (0.75: 0.70 off it) miss it and hold τ = −1. Tolerance 1e-4 world units: 256 float steps of τ.
// A path's start drawn with u lies at τ_s − ln(1 − u·(1 − e^{−(τ_{s+1} − τ_s)})) (T uniform over
// the slice): at t0 + that/6, within the slice march's 16 steps' rounding (1e-4).
TEST(MsCacheView, SlicesEndAtEqualStepsOfTheCamerasTransmittance) {
  const Scene scene = parseScene(R"({
    "materials": [{"name": "m", "type": "volume", "scattering": [5, 5, 5], "absorption": [1, 1, 1]}],
    "primitives": [{"name": "v", "type": "volume", "transform": {"scale": [1, 1, 1]}, "materialName": "m"}],
    "camera": {"position": [0, 0, -4], "lookAt": [0, 0, 0], "vfov": 30},
    "renderer": {"resolution": [8, 8]}
  })", "cube.json");
  const DeviceScene ds = buildDeviceScene(scene, nullptr);
  const float global = 1.0f;  // the homogeneous medium's one majorant cell
  const grid_view homogeneous{nullptr, 1, 1, 1, &global};
  const ms_cache_params rp = viewParams(4, 4, 5, 2);
  std::vector<float> cache(size_t(4 * 4 * 5) * MS_CACHE_STRIDE, 0.0f);
  for (int column = 0; column < 16; ++column)
    ms_view_place_column(narval::test::sceneContext(&ds.params, ds.lights.data(), &homogeneous), &rp, column,
                         cache.data() + size_t(column) * MS_CACHE_STRIDE);
  int crossing = 0;
  for (int column = 0; column < 16; ++column) {
    const int cx = column % 4, cy = column / 4;
    const ray3 r = ms_view_column_ray(&ds.params.camera, 2, cx, cy);
    // The ray against the cube's slabs.
    double t0 = 0, t1 = 1e30;
    const double o[3] = {r.origin.x, r.origin.y, r.origin.z}, d[3] = {r.dir.x, r.dir.y, r.dir.z};
    for (int a = 0; a < 3; ++a) {
      const double ta = (-0.5 - o[a]) / d[a], tb = (0.5 - o[a]) / d[a];
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::min(t1, std::max(ta, tb));
    }
    const bool inner = (cx == 1 || cx == 2) && (cy == 1 || cy == 2);
    ASSERT_EQ(t0 < t1, inner) << "column " << column;
    crossing += inner;
    const double tEnd = std::max(std::exp(-6.0 * (t1 - t0)), 0.01);
    auto level = [&](int i) { return -std::log(1.0 - (1.0 - tEnd) * i / 5.0); };
    for (int s = 0; s < 5; ++s) {
      const int node = column + 16 * s;
      const float* v = cache.data() + size_t(node) * MS_CACHE_STRIDE;
      if (!inner) {
        EXPECT_EQ(v[MS_VIEW_TAU], -1.0f) << "column " << column << " slice " << s;
        continue;
      }
      EXPECT_NEAR(v[MS_VIEW_TAU], level(s), 1e-5) << "column " << column << " slice " << s;
      EXPECT_NEAR(v[MS_VIEW_TAU_END], level(s + 1), 1e-5) << "column " << column << " slice " << s;
      EXPECT_NEAR(v[MS_VIEW_T], t0 + level(s) / 6.0, 1e-4) << "column " << column << " slice " << s;
      EXPECT_NEAR(v[MS_VIEW_T_END], t0 + level(s + 1) / 6.0, 1e-4) << "column " << column << " slice " << s;
      for (float u : {0.0f, 0.3f, 0.8f}) {
        const double tau = level(s) - std::log(1.0 - u * (1.0 - std::exp(level(s) - level(s + 1))));
        const vec3 x = ms_view_sample_point(narval::test::sceneContext(&ds.params, ds.lights.data(), &homogeneous),
                                            &rp, node, v, u);
        EXPECT_NEAR(x.z, r.origin.z + r.dir.z * (t0 + tau / 6.0), 1e-4) << "column " << column << " slice " << s;
      }
    }
    if (inner) EXPECT_LT(t0 + std::log(100.0) / 6.0, t1);  // the last slice ends at τ_max, inside
  }
  EXPECT_EQ(crossing, 4);
}

}  // namespace
}  // namespace narval::test
