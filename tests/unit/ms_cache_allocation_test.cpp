// The view cache's perceptual allocation of paths over its columns (render/ms_cache_allocation.h).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "render/ms_cache_allocation.h"
#include "shared/ms_cache.h"
#include "shared/ms_cache_view.h"

namespace narval {
namespace {

MsCacheAllocation perceptual(int meanPaths, ToneMapping tm = ToneMapping::None) {
  MsCacheAllocation a;
  a.perceptual = true;
  a.meanPaths = meanPaths;
  a.toneMapping = tm;
  return a;
}

// The pilot is a quarter of the mean, at least 1 path and below the mean where it can be.
TEST(MsCacheAllocation, PilotIsAQuarterOfTheMean) {
  EXPECT_EQ(msAllocationPilot(136), 34);
  EXPECT_EQ(msAllocationPilot(2048), 512);
  EXPECT_EQ(msAllocationPilot(4), 1);
  EXPECT_EQ(msAllocationPilot(1), 1);
}

// Without tone mapping and at exposure 0 the display shows Y itself, so above the CIE's linear
// segment L* = 116·Y^(1/3) − 16 and dL*/dY = (116/3)·Y^(−2/3): 154.67 at Y = 1/8 (the central
// difference over ±5% is within 0.1% of it: its error is Y²·f'''/6·0.05² relative ≈ 0.05%). ACES
// reaches 1 at x = 7.24 (tonemap.h), so at Y = 10 the display is saturated: slope 0.
TEST(MsCacheAllocation, TheDisplaySlopeIsLStarsThroughTheDisplayTransform) {
  EXPECT_NEAR(displayLightnessSlope(0.125, ToneMapping::None, 0.0f), 116.0 / 3.0 * 4.0, 0.15);
  // One stop of exposure doubles Y before the display: slope 2·L*'(2Y).
  EXPECT_NEAR(displayLightnessSlope(0.0625, ToneMapping::None, 1.0f), 2 * 116.0 / 3.0 * 4.0, 0.3);
  EXPECT_EQ(displayLightnessSlope(10.0, ToneMapping::Aces, 0.0f), 0.0);
  EXPECT_GT(displayLightnessSlope(0.01, ToneMapping::Aces, 0.0f), displayLightnessSlope(0.5, ToneMapping::Aces, 0.0f));
}

// Columns that all look alike share the paths evenly: every budget is the mean.
TEST(MsCacheAllocation, AlikeColumnsGetTheMean) {
  std::vector<MsColumnPilot> cols(4 * 3, MsColumnPilot{true, 0.2, 0.05});
  const std::vector<int> b = msPerceptualBudgets(cols, 4, 3, perceptual(100));
  for (int x : b) EXPECT_EQ(x, 100);
}

// A 6x5 image whose left half is noisy (spread 0.2) and right half quiet (0.02), the same value
// (0.2) everywhere, one column without medium. The budgets: 0 where no medium; within the floor
// (0.625 of the mean) and the cap (2.5x); averaging the mean within rounding; the noisy half's above
// the quiet half's. And a column's weight does not depend on its own pilot (which is what keeps its
// mean unbiased): changing column (1, 2)'s value and spread leaves its weight as it was, bit for
// bit, and changes its neighbour's.
TEST(MsCacheAllocation, BudgetsFollowTheNeighboursNoiseWithinTheirBoundsAndAverageTheMean) {
  const int nx = 6, ny = 5, mean = 80;
  std::vector<MsColumnPilot> cols(nx * ny);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) cols[size_t(x + nx * y)] = MsColumnPilot{true, 0.2, x < 3 ? 0.2 : 0.02};
  cols[size_t(5 + nx * 4)].medium = false;
  const std::vector<int> b = msPerceptualBudgets(cols, nx, ny, perceptual(mean, ToneMapping::Aces));
  double sum = 0;
  int n = 0;
  for (int i = 0; i < nx * ny; ++i) {
    if (!cols[size_t(i)].medium) {
      EXPECT_EQ(b[size_t(i)], 0);
      continue;
    }
    EXPECT_GE(b[size_t(i)], int(std::floor(kMsAllocationFloorShare * mean)));
    EXPECT_LE(b[size_t(i)], int(std::ceil(kMsAllocationCapShare * mean)));
    sum += b[size_t(i)];
    ++n;
  }
  EXPECT_NEAR(sum / n, mean, 0.5);
  EXPECT_GT(b[size_t(0 + nx * 2)], b[size_t(5 + nx * 2)]);  // noisy side above quiet side
  std::vector<MsColumnPilot> changed = cols;
  changed[size_t(1 + nx * 2)] = MsColumnPilot{true, 3.0, 1.5};
  const std::vector<double> w = msPerceptualWeights(cols, nx, ny, perceptual(mean, ToneMapping::Aces));
  const std::vector<double> c = msPerceptualWeights(changed, nx, ny, perceptual(mean, ToneMapping::Aces));
  EXPECT_EQ(c[size_t(1 + nx * 2)], w[size_t(1 + nx * 2)]);
  EXPECT_NE(c[size_t(2 + nx * 2)], w[size_t(2 + nx * 2)]);
}

// Noiseless pilots (every spread 0) give no weights to spread by: the even share.
TEST(MsCacheAllocation, NoiselessPilotsKeepTheEvenShare) {
  std::vector<MsColumnPilot> cols(9, MsColumnPilot{true, 0.3, 0.0});
  for (int x : msPerceptualBudgets(cols, 3, 3, perceptual(64))) EXPECT_EQ(x, 64);
}

// msColumnPilots reads a column's slices as ms_cache_view.h lays them: one column of two slices
// with levels τ 0, ln 2, ln 4 (transmittance 1, 1/2, 1/4), grey means J 0.4 and 0.8 (per-path mean
// squares 0.25 and 0.8), background seen 0.5, albedo 0.9:
//   Y = 0.5 + 0.9·(0.5·0.4 + 0.25·0.8) = 0.86,
//   σ² = (0.9·0.5)²·(0.25 − 0.16) + (0.9·0.25)²·(0.8 − 0.64) = 0.018225 + 0.0081 = 0.026325.
// The second column holds no medium (τ = −1).
TEST(MsCacheAllocation, ColumnPilotsReadTheSlicesTransmittanceMeansAndSpread) {
  node_grid_params c{};
  c.nx = 2;
  c.ny = 1;
  c.nz = 2;
  std::vector<float> cache(size_t(4) * MS_CACHE_STRIDE, 0.0f);
  auto node = [&](int column, int slice) { return &cache[(size_t(slice) * 2 + size_t(column)) * MS_CACHE_STRIDE]; };
  const float levels[3] = {0.0f, std::log(2.0f), std::log(4.0f)}, J[2] = {0.4f, 0.8f}, sq[2] = {0.25f, 0.8f};
  for (int s = 0; s < 2; ++s) {
    float* v = node(0, s);
    v[MS_VIEW_TAU] = levels[s];
    v[MS_VIEW_TAU_END] = levels[s + 1];
    v[0] = v[1] = v[2] = J[s];
    v[MS_CACHE_SQUARE] = sq[s];
    node(1, s)[MS_VIEW_TAU] = -1.0f;
  }
  node(0, 0)[MS_VIEW_SEEN] = 0.5f;
  const std::vector<MsColumnPilot> p = msColumnPilots(cache, c, 0.9);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_TRUE(p[0].medium);
  EXPECT_NEAR(p[0].value, 0.86, 1e-6);
  EXPECT_NEAR(p[0].spread, std::sqrt(0.026325), 1e-6);
  EXPECT_FALSE(p[1].medium);
}

}  // namespace
}  // namespace narval
