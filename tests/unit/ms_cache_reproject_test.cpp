// The view cache carried over a camera move (kernels/shared/ms_cache_reproject.h) on the host, the very
// code the device runs: a new node reads the old node whose slice holds its centre, and the prior fades
// out as the node's own paths come in.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shared/ms_cache_reproject.h"

namespace narval::test {
namespace {

// A 9x7 image looking along +z from `z` (tile 1: 9x7 columns of 4 slices); the centre column (4, 3) is
// the ray along the axis.
camera_params axisCamera(float z) {
  camera_params c{};
  c.position = {0.0f, 0.0f, z, 0.0f};
  c.forward = {0.0f, 0.0f, 1.0f, 0.0f};
  c.right = {1.0f, 0.0f, 0.0f, 0.0f};
  c.up = {0.0f, 1.0f, 0.0f, 0.0f};
  c.width = 9;
  c.height = 7;
  c.aspect = 9.0f / 7.0f;
  c.tan_half_vfov = 0.3f;
  return c;
}

ms_cache_params viewParams() {
  ms_cache_params mc{};
  mc.layout = MS_CACHE_LAYOUT_VIEW;
  mc.tile = 1;
  mc.grid.nx = 9;
  mc.grid.ny = 7;
  mc.grid.nz = 4;
  return mc;
}

// Every column's slices at optical depths {0, 0.5, 1.2, 2.5, 4} and distances t0 + {0, 0.5, 1.3, 2.5, 4};
// node (column, s) holds 10·column + s (grey) from 20 + s paths of relative variance 1.
std::vector<float> placedCache(const ms_cache_params& mc, float t0) {
  const float tau[5] = {0.0f, 0.5f, 1.2f, 2.5f, 4.0f}, t[5] = {0.0f, 0.5f, 1.3f, 2.5f, 4.0f};
  const int columns = mc.grid.nx * mc.grid.ny;
  std::vector<float> cache(size_t(columns * mc.grid.nz) * MS_CACHE_STRIDE, 0.0f);
  for (int s = 0; s < mc.grid.nz; ++s)
    for (int col = 0; col < columns; ++col) {
      float* v = cache.data() + size_t(col + columns * s) * MS_CACHE_STRIDE;
      v[0] = v[1] = v[2] = float(10 * col + s);
      v[3] = float(20 + s);
      v[MS_CACHE_SQUARE] = 2.0f * v[0] * v[0];  // a path's relative variance 1 (ms_cache_reproject.h, "Worth")
      v[MS_VIEW_TAU] = tau[s];
      v[MS_VIEW_TAU_END] = tau[s + 1];
      v[MS_VIEW_T] = t0 + t[s];
      v[MS_VIEW_T_END] = t0 + t[s + 1];
    }
  return cache;
}

std::vector<float> reproject(const camera_params& now, const camera_params& old, const std::vector<float>& previous,
                             const std::vector<float>& placed) {
  const ms_cache_params mc = viewParams();
  std::vector<float> prior(placed.size(), -1.0f);
  for (int node = 0; node < node_grid_count(&mc.grid); ++node)
    ms_view_reproject_node(&now, phase_make(PHASE_ISOTROPIC, 0.0f), &old, &mc, &mc, previous.data(), placed.data(), node,
                           prior.data() + size_t(node) * MS_CACHE_STRIDE);
  return prior;
}

// The same camera and placement: every node reads itself (its centre projects to its own column's
// centre, within float rounding of the bilinear weights, and lies inside its own slice).
TEST(MsCacheReproject, TheSameCameraReadsEveryNodeItself) {
  const ms_cache_params mc = viewParams();
  const camera_params cam = axisCamera(-10.0f);
  const std::vector<float> cache = placedCache(mc, 5.0f), prior = reproject(cam, cam, cache, cache);
  for (size_t n = 0; n < cache.size(); n += MS_CACHE_STRIDE) {
    ASSERT_NEAR(prior[n], cache[n], 1e-3f * (1.0f + cache[n])) << "node " << n / MS_CACHE_STRIDE;
    ASSERT_NEAR(prior[n + 3], cache[n + 3], 1e-3f) << "node " << n / MS_CACHE_STRIDE;
    ASSERT_EQ(prior[n + MS_VIEW_T], cache[n + MS_VIEW_T]);  // the placement's slots are the new cache's
  }
}

// The camera moved 0.6 forward along its axis, the new slices 1 nearer than the old (a placement of
// its own): the centre column's node centres (ms_view_node_depth: T midway across the slice, τ linear
// in distance) lie at 4 + {0.219, 0.831, 1.718, 2.992}, so 0.6 further from the old camera at
// {4.819, 5.431, 6.318, 7.592}: before the old medium (slice 0), in old slice 0 ([5, 5.5)), slice 2
// ([6.3, 7.5)) and slice 3. Centres: −ln(½(e^{−a} + e^{−b})) for (a, b) = (0, 0.5): 0.2191, f = 0.438;
// (0.5, 1.2): 0.7900, f = 0.414, ×0.8; (1.2, 2.5): 1.6522, f = 0.348, ×1.2; (2.5, 4): 2.9917, f = 0.328, ×1.5.
TEST(MsCacheReproject, ANodeReadsTheOldSliceHoldingItsCentre) {
  const ms_cache_params mc = viewParams();
  const camera_params old = axisCamera(-10.0f), now = axisCamera(-9.4f);
  const std::vector<float> previous = placedCache(mc, 5.0f), placed = placedCache(mc, 4.0f);
  const std::vector<float> prior = reproject(now, old, previous, placed);
  const int centre = 4 + 9 * 3, columns = 63, expected[4] = {0, 0, 2, 3};
  for (int s = 0; s < 4; ++s) {
    const float* p = prior.data() + size_t(centre + columns * s) * MS_CACHE_STRIDE;
    EXPECT_NEAR(p[0], float(10 * centre + expected[s]), 1e-3f) << "slice " << s;
    EXPECT_NEAR(p[3], float(20 + expected[s]), 1e-4f) << "slice " << s;
  }
}

// An old camera looking the other way sees none of the new nodes: each is left at 0, worth no paths.
TEST(MsCacheReproject, ANodeTheOldCameraDidNotSeeIsWorthNoPaths) {
  const ms_cache_params mc = viewParams();
  camera_params old = axisCamera(-10.0f);
  old.forward.z = -1.0f;
  old.right.x = -1.0f;
  const std::vector<float> previous = placedCache(mc, 5.0f), prior = reproject(axisCamera(-10.0f), old, previous, previous);
  for (size_t n = 0; n < prior.size(); n += MS_CACHE_STRIDE) {
    ASSERT_EQ(prior[n], 0.0f);
    ASSERT_EQ(prior[n + 3], 0.0f);
  }
}

// The blend ("Blend"): with n of N paths in, the prior's m paths count m·(1 − n/N). n = 0 draws the prior;
// m = 40, n = 20 of N = 40: weights 20 and 20, the mean; n = N: the fresh node, bit for bit; a node
// without medium is fresh's whatever the prior.
TEST(MsCacheReproject, ThePriorFadesAsTheNodesOwnPathsComeIn) {
  float prior[MS_CACHE_STRIDE] = {}, fresh[MS_CACHE_STRIDE] = {}, out[MS_CACHE_STRIDE];
  prior[0] = prior[1] = prior[2] = 3.0f;
  prior[3] = 40.0f;
  fresh[0] = 1.0f / 3.0f;
  fresh[1] = fresh[2] = 1.0f;
  fresh[MS_VIEW_TAU] = 0.25f;
  ms_view_blend_node(prior, fresh, 40, out);
  EXPECT_EQ(out[0], 3.0f);
  EXPECT_EQ(out[3], 40.0f);
  EXPECT_EQ(out[MS_VIEW_TAU], 0.25f);
  fresh[3] = 20.0f;
  ms_view_blend_node(prior, fresh, 40, out);
  EXPECT_FLOAT_EQ(out[0], 0.5f * (3.0f + 1.0f / 3.0f));
  EXPECT_FLOAT_EQ(out[1], 2.0f);
  EXPECT_FLOAT_EQ(out[3], 40.0f);
  fresh[3] = 40.0f;
  ms_view_blend_node(prior, fresh, 40, out);
  for (int i = 0; i < MS_CACHE_STRIDE; ++i) EXPECT_EQ(out[i], fresh[i]) << "slot " << i;
  fresh[3] = 10.0f;  // the prior's weight m = 40·(1 − 10/40) = 30
  ms_view_blend_node(prior, fresh, 40, out);
  EXPECT_FLOAT_EQ(out[0], (30.0f * 3.0f + 10.0f / 3.0f) / 40.0f);
  EXPECT_FLOAT_EQ(out[3], 40.0f);
  fresh[MS_VIEW_TAU] = -1.0f;
  ms_view_blend_node(prior, fresh, 40, out);
  for (int i = 0; i < MS_CACHE_STRIDE; ++i) EXPECT_EQ(out[i], fresh[i]) << "slot " << i;
}

}  // namespace
}  // namespace narval::test
