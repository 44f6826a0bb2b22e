// The status word on the host (the shared headers compile as C++): each STATUS_* bit at the
// function that raises it, including the cases a valid scene cannot reach on the device, and the
// derivation of the DDA's budget checked on many rays. The same bits through the real device path:
// tests/render/status_word_test.cpp. The tracking cap itself: tests/unit/tracking_test.cpp
// (TrackingDelta.ZeroMajorantEscapesAndIterationCapIsFlagged).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "shared/majorant_dda.h"
#include "shared/march.h"
#include "shared/tracking.h"
#include "unit/host_context.h"

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

medium_params unitMedium(float sa, float ss, float majorant, int grey) {
  medium_params m{};
  m.world_to_index.row[0] = {1, 0, 0, 0};
  m.world_to_index.row[1] = {0, 1, 0, 0};
  m.world_to_index.row[2] = {0, 0, 1, 0};
  m.dims = {1, 1, 1, 0};
  m.sigma_a = {sa, sa * (grey ? 1.0f : 0.5f), sa, 0};
  m.sigma_s = {ss, ss, ss * (grey ? 1.0f : 2.0f), 0};
  m.majorant = majorant;
  m.grey = grey;
  m.majorant_grid.cell_size = m.dims;
  m.majorant_grid.cells_x = m.majorant_grid.cells_y = m.majorant_grid.cells_z = 1;
  return m;
}

struct WalkResult {
  int event = -1;
  vec3 tr{};
  uint status = 0u;
};
WalkResult delta(const medium_params& m, const grid_view& g, uint seed = 1u) {
  rng_state rng = rng_init(seed, 2u, 3u);
  vec3 beta = vec3_splat(1.0f);
  float t = 0.0f;
  WalkResult r;
  r.event = tracking_delta(narval::test::hostContext(&m, &g, &r.status), vec3_make(0.5f, 0.5f, 0.0f),
                           vec3_make(0, 0, 1), 0.0f, 1.0f, &rng, &beta, &t);
  return r;
}
WalkResult ratio(const medium_params& m, const grid_view& g, uint seed = 1u) {
  rng_state rng = rng_init(seed, 2u, 3u);
  WalkResult r;
  r.tr = tracking_ratio(narval::test::hostContext(&m, &g, &r.status), vec3_make(0.5f, 0.5f, 0.0f),
                        vec3_make(0, 0, 1), 0.0f, 1.0f, 0.0f, &rng);
  return r;
}

// ---- tracking.h: STATUS_NAN -------------------------------------------------------------------

// A NaN or +inf majorant (σ·D overflowing float makes +inf; steps of 1/inf = 0 would never advance)
// is non-finite input: both walks flag STATUS_NAN at once and end (delta absorbed, ratio 0), for a
// homogeneous medium too (ratio would otherwise take the closed form and ignore the majorant).
TEST(StatusWordHost, NonFiniteMajorantIsNan) {
  const float one[1] = {1.0f};
  const grid_view grid = {one, 1, 1, 1, nullptr}, homogeneous = {nullptr, 1, 1, 1, nullptr};
  for (const float bar : {kNaN, kInf})
    for (const grid_view* g : {&grid, &homogeneous})
      for (const int grey : {1, 0}) {
        const medium_params m = unitMedium(0.5f, 0.5f, bar, grey);
        const WalkResult d = delta(m, *g), r = ratio(m, *g);
        EXPECT_EQ(d.event, TRACK_ABSORBED);
        EXPECT_EQ(d.status, STATUS_NAN);
        EXPECT_EQ(r.tr.x, 0.0f);
        EXPECT_EQ(r.status, STATUS_NAN);
      }
}

// A NaN density (a one-voxel NaN grid: every lookup inside reads NaN). Grey delta tracking: pa, ps
// and the null probability 1 − pa − ps are NaN, so neither `u < pa` nor `u < pa + ps` holds and the
// walk used to take it for a null collision and walk on, silently; chromatic: the weights' sum c is
// NaN and `!(c > 0)` used to end the walk as "zero throughput", silently. Ratio: the weight 1 − σt·ρ/σ̄
// is NaN. Expected: STATUS_NAN and the walk ends (absorbed / transmittance 0). Control: density 1
// under a true majorant gives status 0.
TEST(StatusWordHost, NanDensityIsNanInEveryWalk) {
  const float nan[1] = {kNaN}, one[1] = {1.0f};
  const grid_view poisoned = {nan, 1, 1, 1, nullptr}, clean = {one, 1, 1, 1, nullptr};
  for (const int grey : {1, 0}) {
    // σt ≤ 1.5 per channel, majorant 2: a true bound.
    const medium_params m = unitMedium(0.25f, 0.5f, 2.0f, grey);
    EXPECT_EQ(delta(m, clean).status, 0u) << "grey " << grey;
    EXPECT_EQ(ratio(m, clean).status, 0u) << "grey " << grey;
    const WalkResult d = delta(m, poisoned), r = ratio(m, poisoned);
    EXPECT_EQ(d.event, TRACK_ABSORBED) << "grey " << grey;
    EXPECT_EQ(d.status, STATUS_NAN) << "grey " << grey;
    EXPECT_EQ(r.tr.x, 0.0f) << "grey " << grey;
    EXPECT_EQ(r.status, STATUS_NAN) << "grey " << grey;
  }
}

// ---- tracking.h: STATUS_NEGATIVE_PDF ----------------------------------------------------------

// A majorant below σt(x): σt = 1 (σa = σs = 0.5, grey) under σ̄ = 0.5, density 1. The null-collision
// probability 1 − σt/σ̄ = −1 at every tentative collision (delta) and the ratio weight too: flagged
// STATUS_NEGATIVE_PDF, and nothing else (the walks still end normally: the grey walk collides at once
// since u < pa + ps = 2 always; ratio's weights −1 multiply to ±1 until it leaves the segment). The
// chromatic walk likewise (σn < 0 in some channel). Boundary control: σ̄ exactly σt (a null
// probability of exactly 0 is legal) gives status 0, as does any σ̄ above.
TEST(StatusWordHost, MajorantBelowExtinctionIsANegativePdf) {
  const float one[1] = {1.0f};
  const grid_view g = {one, 1, 1, 1, nullptr};
  for (const int grey : {1, 0}) {
    const medium_params low = unitMedium(0.5f, 0.5f, 0.5f, grey);
    // σt per channel: grey (1, 1, 1); chromatic (1, 0.75, 1.5): its max is the exact bound.
    const medium_params exact = unitMedium(0.5f, 0.5f, grey ? 1.0f : 1.5f, grey);
    for (uint seed = 1u; seed <= 20u; ++seed) {
      EXPECT_EQ(delta(exact, g, seed).status, 0u) << "grey " << grey;
      EXPECT_EQ(ratio(exact, g, seed).status, 0u) << "grey " << grey;
    }
    const WalkResult d = delta(low, g), r = ratio(low, g);
    EXPECT_EQ(d.status, STATUS_NEGATIVE_PDF) << "grey " << grey;
    EXPECT_EQ(r.status, STATUS_NEGATIVE_PDF) << "grey " << grey;
    EXPECT_TRUE(vec3_is_finite(r.tr));
  }
}

// ---- majorant_dda.h: the DDA's budget and its two bits --------------------------------------------

majorant_grid_params gridParams(int cx, int cy, int cz, float sx, float sy, float sz) {
  majorant_grid_params p{};
  p.cell_size = {sx, sy, sz, 0};
  p.cells_x = cx;
  p.cells_y = cy;
  p.cells_z = cz;
  return p;
}

// The budget's derivation (majorant_dda.h, MAJORANT_DDA_BUDGET): a walk uses at most
// nx + ny + nz − 1 iterations of majorant_iter_next's loop (counted as budget spent), 4 below the
// budget. Checked on 20000 random rays per grid (origins inside and outside the box, lines through
// it, directions with some components exactly 0, segments ending inside or beyond it) over grids
// from 1³ to 64³ and unequal cell sizes: the bound holds, the walk always ends at t_end (no
// STATUS_ITERATION_CAP) and status stays 0. The worst ray seen is printed.
TEST(StatusWordHost, DdaBudgetBoundHoldsOnRandomRays) {
  struct Case {
    int cx, cy, cz;
    float sx, sy, sz;
  };
  const Case cases[] = {{1, 1, 1, 1, 1, 1}, {3, 5, 7, 2, 1, 0.5f}, {16, 16, 16, 1, 1, 1}, {64, 64, 64, 2, 2, 2},
                        {13, 9, 16, 9.6875f, 9.5556f, 9.625f}};
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> uni(-0.5f, 1.5f), dir(-1, 1);
  std::vector<float> cells(64 * 64 * 64, 1.0f);
  for (const Case& c : cases) {
    const majorant_grid_params p = gridParams(c.cx, c.cy, c.cz, c.sx, c.sy, c.sz);
    const float ext[3] = {c.cx * c.sx, c.cy * c.sy, c.cz * c.sz};
    const int bound = c.cx + c.cy + c.cz - 1;
    int worst = 0;
    for (int i = 0; i < 20000; ++i) {
      const vec3 o = vec3_make(uni(gen) * ext[0], uni(gen) * ext[1], uni(gen) * ext[2]);
      vec3 d = vec3_make(dir(gen), dir(gen), dir(gen));
      if (i % 5 == 1) d.x = 0.0f;
      if (i % 7 == 2) d.y = 0.0f;
      if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) d.z = 1.0f;
      d = vec3_normalize(d);
      float t0 = 0.0f, t1 = 0.0f;
      if (!intersect_box(o, d, vec3_make(ext[0], ext[1], ext[2]), &t0, &t1)) continue;
      // Sometimes only part of the chord, sometimes a little beyond it (the boundary cells take it).
      const float a = i % 3 == 0 ? t0 + 0.3f * (t1 - t0) : t0, b = i % 4 == 0 ? t1 + 0.1f * (t1 - t0) : t1;
      majorant_iter it = majorant_iter_begin(p, o, d, a, b);
      const int budget = it.budget;
      float s0, s1, mx;
      while (majorant_iter_next(&it, cells.data(), &s0, &s1, &mx)) {
      }
      const int used = budget - it.budget;
      worst = std::max(worst, used);
      ASSERT_LE(used, bound) << "cells " << c.cx << "x" << c.cy << "x" << c.cz << ", ray " << i;
      ASSERT_EQ(it.status, 0u) << "ray " << i;
      ASSERT_FALSE(it.t < it.t_end) << "ray " << i;
    }
    EXPECT_EQ(MAJORANT_DDA_BUDGET(c.cx, c.cy, c.cz), bound + 4);
    std::printf("[ status ] DDA %dx%dx%d: at most %d iterations used of budget %d (bound %d)\n", c.cx, c.cy, c.cz,
                worst, bound + 4, bound);
  }
}

// The cap is live: the same walk with its budget cut to 1 (what -D NARVAL_DDA_BUDGET=1 does on the
// device) yields its first segment and then returns 0 short of t_end, raising
// STATUS_ITERATION_CAP. The ray runs along x through 4 cells of a 4 × 1 × 1 grid: segments [0, 1],
// [1, 2], ... normally; with the budget cut, only [0, 1].
TEST(StatusWordHost, DdaBudgetSpentRaisesIterationCap) {
  const majorant_grid_params p = gridParams(4, 1, 1, 1, 1, 1);
  const float cells[4] = {1, 1, 1, 1};
  float s0, s1, mx;
  majorant_iter full = majorant_iter_begin(p, vec3_make(0, 0.5f, 0.5f), vec3_make(1, 0, 0), 0.0f, 4.0f);
  int n = 0;
  while (majorant_iter_next(&full, cells, &s0, &s1, &mx)) ++n;
  EXPECT_EQ(n, 4);
  EXPECT_EQ(full.status, 0u);

  majorant_iter cut = majorant_iter_begin(p, vec3_make(0, 0.5f, 0.5f), vec3_make(1, 0, 0), 0.0f, 4.0f);
  cut.budget = 1;
  ASSERT_TRUE(majorant_iter_next(&cut, cells, &s0, &s1, &mx));
  EXPECT_EQ(s0, 0.0f);
  EXPECT_EQ(s1, 1.0f);
  EXPECT_FALSE(majorant_iter_next(&cut, cells, &s0, &s1, &mx));
  EXPECT_EQ(cut.status, STATUS_ITERATION_CAP);
}

// Non-finite input (a NaN from upstream) yields nothing, as the contract says, and is no longer
// mistaken for an empty segment: STATUS_NAN. A finite empty segment (t0 >= t1) yields nothing with
// status 0. march_optical_depth passes both on: a NaN ray origin would miss the box and read as
// optical depth 0 (clear air), so it flags STATUS_NAN; a finite ray that misses gives 0, status 0.
TEST(StatusWordHost, NonFiniteRayIsNanInTheDdaAndTheMarch) {
  const majorant_grid_params p = gridParams(2, 2, 2, 1, 1, 1);
  const float cells[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  float s0, s1, mx;
  majorant_iter empty = majorant_iter_begin(p, vec3_make(0.5f, 0.5f, 0.5f), vec3_make(1, 0, 0), 1.0f, 1.0f);
  EXPECT_FALSE(majorant_iter_next(&empty, cells, &s0, &s1, &mx));
  EXPECT_EQ(empty.status, 0u);
  const vec3 o = vec3_make(0.5f, 0.5f, 0.5f), d = vec3_make(1, 0, 0);
  const vec3 nan3 = vec3_make(kNaN, 0.5f, 0.5f);
  const majorant_iter bad[] = {majorant_iter_begin(p, nan3, d, 0.0f, 1.0f), majorant_iter_begin(p, o, nan3, 0.0f, 1.0f),
                               majorant_iter_begin(p, o, d, kNaN, 1.0f), majorant_iter_begin(p, o, d, 0.0f, kInf)};
  for (majorant_iter it : bad) {
    EXPECT_FALSE(majorant_iter_next(&it, cells, &s0, &s1, &mx));
    EXPECT_EQ(it.status, STATUS_NAN);
  }

  medium_params m = unitMedium(0.5f, 0.5f, 1.0f, 1);
  m.majorant_grid = gridParams(1, 1, 1, 1, 1, 1);
  const float one[1] = {1.0f};
  const grid_view g = {nullptr, 1, 1, 1, one};
  uint status = 0u;
  const vec3 tau = march_optical_depth(narval::test::hostContext(&m, &g, &status), vec3_make(-1, 0.5f, 0.5f), d,
                                       3.0f, 10);
  EXPECT_NEAR(tau.x, 1.0f, 1e-6f);  // σt = 1 across the unit box
  EXPECT_EQ(status, 0u);
  EXPECT_EQ(march_optical_depth(narval::test::hostContext(&m, &g, &status), vec3_make(-1, 5, 0.5f), d, 3.0f, 10).x,
            0.0f);  // misses
  EXPECT_EQ(status, 0u);
  EXPECT_EQ(march_optical_depth(narval::test::hostContext(&m, &g, &status), nan3, d, 3.0f, 10).x, 0.0f);
  EXPECT_EQ(status, STATUS_NAN);
}

}  // namespace
