// The view-space layout of the multiple-scattering cache (kernels/shared/ms_cache_view.h): how a
// pixel finds its columns and how a column is read along the optical depth.
#include <gtest/gtest.h>

#include <vector>

#include "shared/ms_cache_view.h"

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

realtime_params viewParams(int nx, int ny, int nz, int tile) {
  realtime_params rp{};
  rp.ms_cache.nx = nx;
  rp.ms_cache.ny = ny;
  rp.ms_cache.nz = nz;
  rp.ms_cache_layout = MS_CACHE_LAYOUT_VIEW;
  rp.ms_cache_tile = tile;
  return rp;
}

// A pixel at its column's centre reads that column alone; one between column centres reads them
// bilinearly; past the outer centres it reads the edge column (no extrapolation).
TEST(MsCacheView, PixelsFindTheirColumnsBilinearly) {
  const realtime_params rp = viewParams(3, 2, 2, 4);  // a 12x8 image in 4x4 tiles
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
  const realtime_params one = viewParams(1, 1, 2, 64);
  cols = ms_view_locate(&one, 40, 3);
  EXPECT_EQ(cols.column[0], 0);
  EXPECT_FLOAT_EQ(cols.w[0], 1.0f);
  for (int k = 1; k < 4; ++k) EXPECT_EQ(cols.column[k] == 0 || cols.w[k] == 0.0f, true);
}

// Along a column the value is linear in τ between slices: a field linear in τ (and bilinear across
// columns) is read exactly at any τ inside the nodes' range, clamped at the ends outside it.
TEST(MsCacheView, ColumnsAreReadLinearlyInOpticalDepth) {
  const realtime_params rp = viewParams(2, 2, 4, 4);
  auto tau = [](int cx, int cy, int s) { return 0.5f * float(s * s) + 0.1f * float(cx + cy); };  // uneven spacing
  auto value = [](int cx, int cy, int s) { return 2.0f + 3.0f * (0.5f * float(s * s) + 0.1f * float(cx + cy)); };
  const std::vector<float> cache = viewCache(rp.ms_cache, tau, value);
  // Pixel (1, 1) of the 8x8 image: u = 1.5/4 − 0.5 < 0 → column (0, 0) alone; f(τ) = 2 + 3τ.
  const ms_view_columns corner = ms_view_locate(&rp, 1, 1);
  for (float t : {0.0f, 0.2f, 0.5f, 1.3f, 2.0f, 3.7f, 4.5f})
    EXPECT_NEAR(ms_view_lookup(&rp.ms_cache, cache.data(), &corner, t).y, 2.0f + 3.0f * t, 1e-5f) << t;
  EXPECT_NEAR(ms_view_lookup(&rp.ms_cache, cache.data(), &corner, -1.0f).x, 2.0f, 1e-6f);  // before node 0
  EXPECT_NEAR(ms_view_lookup(&rp.ms_cache, cache.data(), &corner, 9.0f).z, 2.0f + 3.0f * 4.5f, 1e-5f);  // past 3
  // Pixel (3, 4): between all four columns; each reads 2 + 3τ at the same τ (in range for all).
  const ms_view_columns mid = ms_view_locate(&rp, 3, 4);
  EXPECT_NEAR(ms_view_lookup(&rp.ms_cache, cache.data(), &mid, 1.0f).x, 5.0f, 1e-5f);
}

// A column whose ray meets no medium (τ = −1) drops out and the others' weights are renormalised;
// with none left the lookup is 0.
TEST(MsCacheView, ColumnsWithoutMediumDropOut) {
  const realtime_params rp = viewParams(2, 1, 2, 4);
  auto tau = [](int cx, int, int s) { return cx == 0 ? -1.0f : float(s); };
  auto value = [](int cx, int, int) { return cx == 0 ? 100.0f : 7.0f; };
  std::vector<float> cache = viewCache(rp.ms_cache, tau, value);
  const ms_view_columns cols = ms_view_locate(&rp, 3, 0);  // between the two columns
  EXPECT_GT(cols.w[0], 0.0f);
  EXPECT_FLOAT_EQ(ms_view_lookup(&rp.ms_cache, cache.data(), &cols, 0.5f).x, 7.0f);
  for (int s = 0; s < 2; ++s) cache[size_t(1 + 2 * s) * MS_CACHE_STRIDE + MS_VIEW_TAU] = -1.0f;
  EXPECT_EQ(ms_view_lookup(&rp.ms_cache, cache.data(), &cols, 0.5f).x, 0.0f);
}

}  // namespace
}  // namespace narval::test
