// tracking_majorant_test.cpp: delta/spectral tracking and ratio tracking against the majorant grid
// (kernels/shared/tracking.h walking kernels/shared/majorant_dda.h's DDA), on the host — the very code
// the device compiles, here with -DCOUNTERS (defined below) so the counts can be checked too.
//   - the optical budget crosses segment boundaries exactly (hand-made cells, closed-form t),
//     including a start on a cell face, rays along an axis, rays with zero direction components;
//   - free flight: escape and scattering frequencies equal exp(-τ) and (σs/σt)(1 - exp(-τ)) from an
//     independent quadrature (binomial bounds), grey and chromatic, grid and global majorant;
//   - ratio tracking: the mean equals exp(-τ) per channel (standard-error bounds);
//   - cells whose majorant is 0 cost nothing: no tentative collision lands in one, a walk through
//     empty cells only makes no density lookup (the counters) and draws one random number.
// Statistical bounds are two-sided 4σ (false alarm 6.3e-5 each); the seeds are fixed.
#define COUNTERS 1

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "shared/medium.h"
#include "shared/phase.h"
#include "shared/tracking.h"
#include "unit/host_context.h"
#include "unit/stat_util.h"
#include "volume/dense_grid.h"
#include "volume/majorant_grid.h"

namespace {

using narval::test::MeanAccumulator;
using narval::test::MeanSe;

constexpr float kM = MAJORANT_MARGIN;

// ---- hand-made majorant cells: the budget across segments --------------------------------------

// A medium over [0, nx]×[0, ny]×[0, nz] index units (identity map, so t is in index units along a
// unit d) with σa = 0, σs = 1 (σ̄ per cell = cell value · MAJORANT_MARGIN) and unit cells.
medium_params handMedium(int nx, int ny, int nz) {
  medium_params m{};
  m.world_to_index.row[0] = {1, 0, 0, 0};
  m.world_to_index.row[1] = {0, 1, 0, 0};
  m.world_to_index.row[2] = {0, 0, 1, 0};
  m.dims = {float(nx), float(ny), float(nz), 0};
  m.sigma_a = {0, 0, 0, 0};
  m.sigma_s = {1, 1, 1, 0};
  m.majorant = 10.0f;
  m.grey = 1;
  m.phase = phase_make(PHASE_ISOTROPIC, 0.0f);
  m.majorant_grid.cell_size = {1, 1, 1, 0};
  m.majorant_grid.cells_x = nx;
  m.majorant_grid.cells_y = ny;
  m.majorant_grid.cells_z = nz;
  return m;
}

// The first tentative collision of a fresh walk over [t0, t1] that spends optical depth `tau` of
// the majorant; -1 when the walk leaves [t0, t1] first.
float firstCollision(const medium_params& m, const std::vector<float>& cells, vec3 o, vec3 d, float t0, float t1,
                     float tau) {
  tracking_walk w = tracking_walk_begin(&m, 1, o, d, t0, t1);
  uint status = 0u;
  const int hit = tracking_walk_step(&w, cells.data(), tau, &status);
  EXPECT_EQ(status, 0u);
  return hit ? w.t : -1.0f;
}

// Four cells along x, values 2, 0, 4, 1 (σ̄ = value·M). Along +x from x = 0 the majorant's optical
// depth is Λ(t)/M = 2t on [0, 1], 2 on [1, 2], 2 + 4(t − 2) on [2, 3], 6 + (t − 3) on [3, 4], 7 in all,
// so the collision for τ is Λ⁻¹(τ): τ = M → 0.5; 3M → 2.25 (crossing the empty cell with 1M left
// after the first); 6.5M → 3.5; 7.5M → none. τ = 2M is spent exactly at x = 1: what is left (0)
// crosses the empty cell, and the collision is at the start of cell 2, x = 2, never in cell 1.
TEST(TrackingMajorantBudget, AlongAnAxisAcrossAnEmptyCell) {
  const medium_params m = handMedium(4, 1, 1);
  const std::vector<float> cells = {2, 0, 4, 1};
  const vec3 o = vec3_make(0, 0.5f, 0.5f), d = vec3_make(1, 0, 0);
  EXPECT_NEAR(firstCollision(m, cells, o, d, 0, 4, 1 * kM), 0.5f, 1e-6);
  EXPECT_NEAR(firstCollision(m, cells, o, d, 0, 4, 3 * kM), 2.25f, 1e-6);
  EXPECT_NEAR(firstCollision(m, cells, o, d, 0, 4, 6.5f * kM), 3.5f, 1e-6);
  EXPECT_EQ(firstCollision(m, cells, o, d, 0, 4, 7.5f * kM), -1.0f);
  EXPECT_EQ(firstCollision(m, cells, o, d, 0, 4, 2 * kM), 2.0f);
  // Successive collisions carry on from the last one: τ = M (→ 0.5), then 2M more: 1M to the end
  // of cell 0, the empty cell for free, 1M in cell 2 at rate 4M → 2.25; then 4M: 3M to the end of
  // cell 2 (0.75 at 4M), 1M in cell 3 → 4.0 = t1: out.
  tracking_walk w = tracking_walk_begin(&m, 1, o, d, 0, 4);
  uint status = 0u;
  ASSERT_TRUE(tracking_walk_step(&w, cells.data(), 1 * kM, &status));
  EXPECT_NEAR(w.t, 0.5f, 1e-6);
  EXPECT_EQ(w.bar, 2 * kM);
  ASSERT_TRUE(tracking_walk_step(&w, cells.data(), 2 * kM, &status));
  EXPECT_NEAR(w.t, 2.25f, 1e-6);
  EXPECT_EQ(w.bar, 4 * kM);
  EXPECT_FALSE(tracking_walk_step(&w, cells.data(), 4 * kM, &status));
  EXPECT_EQ(status, 0u);
  // The same cells walked backwards from x = 4 along −x: Λ/M = t on [0, 1] (cell 3), 1 + 4(t − 1)
  // on [1, 2] (cell 2), 5 on [2, 3], 5 + 2(t − 3) on [3, 4]. τ = 5.5M → t = 3.25 (x = 0.75).
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(4, 0.5f, 0.5f), vec3_make(-1, 0, 0), 0, 4, 5.5f * kM), 3.25f, 1e-6);
}

// A start exactly on a face: at x = 1 going +x the walk starts in cell 1 (empty), so τ = 2M is
// spent in cell 2 at rate 4M: t = 1 + 0.5 = 1.5 (the point x = 2.5). At x = 2 going −x it starts in
// cell 1 too (the cell the ray enters, majorant_dda.h), then cell 0 at rate 2M: τ = M → t = 1 + 0.5 =
// 1.5 (x = 0.5); starting in cell 2 instead would have given t = 0.25.
TEST(TrackingMajorantBudget, StartOnACellFace) {
  const medium_params m = handMedium(4, 1, 1);
  const std::vector<float> cells = {2, 0, 4, 1};
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(1, 0.5f, 0.5f), vec3_make(1, 0, 0), 0, 3, 2 * kM), 1.5f, 1e-6);
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(2, 0.5f, 0.5f), vec3_make(-1, 0, 0), 0, 2, kM), 1.5f, 1e-6);
  // A walk beginning at t0 > 0 on a face (the box entry of a ray from outside): o at x = −1, t0 = 2.
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(-1, 0.5f, 0.5f), vec3_make(1, 0, 0), 2, 5, 2 * kM), 3.5f, 1e-6);
}

// Zero direction components. 2×2×1 cells, value(i, j) = {1, 3, 0, 2}[i + 2j].
// - d = (1, 0, 0) at y = 1 exactly, inside the face between rows j = 0 and j = 1: the walk follows
//   the upper row (majorant_dda.h), values 0 then 2: τ = M → t = 1 + 0.5 = 1.5. (The lower row, 1 then
//   3, would give t = 1.)
// - d = (0.6, 0.8, 0) from (0, 0, 0.5): x = 0.6t reaches 1 at t = 5/3, y = 0.8t reaches 1 at 1.25 and
//   2 at 2.5. Cells: (0,0) value 1 on [0, 1.25], (0,1) value 0 on [1.25, 5/3], (1,1) value 2 on
//   [5/3, 2.5]. τ = 1.75M: 1.25M in (0,0), nothing in (0,1), 0.5M at rate 2M → t = 5/3 + 0.25.
TEST(TrackingMajorantBudget, ZeroDirectionComponents) {
  const medium_params m = handMedium(2, 2, 1);
  const std::vector<float> cells = {1, 3, 0, 2};
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(0, 1, 0.5f), vec3_make(1, 0, 0), 0, 2, kM), 1.5f, 1e-6);
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(0, 0, 0.5f), vec3_make(0.6f, 0.8f, 0), 0, 2.5f, 1.75f * kM),
              5.0f / 3.0f + 0.25f, 2e-6);
  // The same along −z only (d = (0, 0, −1), x and y components zero) in cell (1, 1): value 2, so
  // τ = M → t = 0.5 from z = 1.
  EXPECT_NEAR(firstCollision(m, cells, vec3_make(1.5f, 1.5f, 1), vec3_make(0, 0, -1), 0, 1, kM), 0.5f, 1e-6);
}

// ---- a real grid with empty space: statistics --------------------------------------------------

// 16×8×8 voxels (index units = world units, identity map): density 0 for x < 6 and in the tube
// y < 4, z < 4; elsewhere uniform in [0.2, 2]. Majorant cells 8×4×4 (2 voxels each): by the
// support rule (majorant_grid.cpp) cells with x index 0 and 1 ([0, 4]) and the cells (·, 0, 0)
// ([0, 2]² in y, z: voxels 0..2) bound no nonzero voxel and are exactly 0.
struct EmptySpaceGrid {
  narval::DenseGrid grid;
  narval::MajorantGrid cells;
  grid_view withCells{}, withoutCells{};
  medium_params medium{};
};

EmptySpaceGrid makeEmptySpaceGrid(nv_float4 sigmaA, nv_float4 sigmaS, int grey) {
  EmptySpaceGrid g;
  narval::DenseGrid& d = g.grid;
  d.nx = 16;
  d.ny = d.nz = 8;
  d.data.assign(d.voxelCount(), 0.0f);
  std::mt19937 gen(2024);
  std::uniform_real_distribution<float> u(0.2f, 2.0f);
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x) {
        const float v = u(gen);
        if (x >= 6 && !(y < 4 && z < 4)) d.data[size_t(x + d.nx * (y + d.ny * z))] = v;
      }
  d.maxValue = *std::max_element(d.data.begin(), d.data.end());
  g.cells = narval::buildMajorantGrid(d, 8, 4, 4);
  g.withCells = {d.data.data(), d.nx, d.ny, d.nz, g.cells.maxDensity.data()};
  g.withoutCells = {d.data.data(), d.nx, d.ny, d.nz, nullptr};
  medium_params& m = g.medium;
  m.world_to_index.row[0] = {1, 0, 0, 0};
  m.world_to_index.row[1] = {0, 1, 0, 0};
  m.world_to_index.row[2] = {0, 0, 1, 0};
  m.dims = {16, 8, 8, 0};
  m.sigma_a = sigmaA;
  m.sigma_s = sigmaS;
  float stMax = 0;
  for (float s : {sigmaA.x + sigmaS.x, sigmaA.y + sigmaS.y, sigmaA.z + sigmaS.z}) stMax = std::max(stMax, s);
  m.majorant = stMax * d.maxValue * (1.0f + 1e-5f);  // as scene_upload.cpp
  m.grey = grey;
  m.phase = phase_make(PHASE_ISOTROPIC, 0.0f);
  m.majorant_grid = g.cells.params();
  return g;
}

struct TestRay {
  const char* name;
  vec3 o, d;
  float t0 = 0, t1 = 0;
};

// Rays of the kinds the DDA must get right, each clipped to the box (medium_intersect):
std::vector<TestRay> testRays(const medium_params& m) {
  std::vector<TestRay> rays = {
      {"along +x through the empty cells", vec3_make(-1.0f, 4.3f, 5.7f), vec3_make(1, 0, 0)},
      {"from a cell face (x = 4), oblique", vec3_make(4.0f, 5.1f, 5.2f), vec3_normalize(vec3_make(1, 0.3f, -0.2f))},
      {"from a cell face (x = 12) along -x", vec3_make(12.0f, 5.5f, 6.5f), vec3_make(-1, 0, 0)},
      {"zero y component, inside the face y = 4", vec3_make(-1.0f, 4.0f, 3.3f), vec3_normalize(vec3_make(1, 0, 0.25f))},
      {"oblique through the whole box", vec3_make(-2.0f, -1.0f, -1.0f), vec3_normalize(vec3_make(18, 10, 9.5f))},
  };
  for (TestRay& r : rays) {
    medium_segment seg;
    EXPECT_TRUE(medium_intersect(&m, r.o, r.d, 0.0f, NV_INFINITY, &seg)) << r.name;
    r.t0 = seg.t0;
    r.t1 = seg.t1;
  }
  return rays;
}

// ∫ρ along the ray over [t0, t1]: composite Simpson, 2·10⁵ panels, in double on grid_density (as
// tracking_test.cpp; error far below the Monte Carlo bounds).
double densityIntegral(const narval::DenseGrid& g, const TestRay& r) {
  const grid_view v{g.data.data(), g.nx, g.ny, g.nz, nullptr};
  const int n = 200000;
  const double h = (double(r.t1) - r.t0) / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double t = r.t0 + i * h;
    const vec3 p = vec3_make(float(r.o.x + t * r.d.x), float(r.o.y + t * r.d.y), float(r.o.z + t * r.d.z));
    sum += (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0)) * grid_view_density(&v, p);
  }
  return sum * h / 3.0;
}

float channelOf(vec3 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }
float channelOf4(nv_float4 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }

// Grey delta tracking, σa = 0.05, σs = 0.1 per unit density (optical depths 0.5–2 on these rays),
// N = 2·10⁵ walks per ray and majorant: escaped and scattered fractions against exp(−τ) and
// (σs/σt)(1 − exp(−τ)) within 4·sqrt(p(1 − p)/N). 5 rays × 2 majorants × 2 checks at 6.3e-5: 1.3e-3
// for the test. Control: exp(−1.03τ) (a 3% error in σt) is outside the escape bound on the thick rays.
// The grid walk makes fewer tentative collisions than the global one (counters), the same real ones
// in distribution.
TEST(TrackingMajorantStats, DeltaTrackingEscapesWithTheTransmittance) {
  const EmptySpaceGrid g = makeEmptySpaceGrid({0.05f, 0.05f, 0.05f, 0}, {0.1f, 0.1f, 0.1f, 0}, 1);
  const double st = 0.15, albedo = 0.1 / 0.15;
  const int n = 200000;
  int controlsSeen = 0;
  for (const TestRay& r : testRays(g.medium)) {
    const double tau = st * densityIntegral(g.grid, r), T = std::exp(-tau);
    unsigned long long tentative[2] = {0, 0};
    for (int mode = 0; mode < 2; ++mode) {
      const grid_view* view = mode == 0 ? &g.withCells : &g.withoutCells;
      int escaped = 0, scattered = 0;
      uint status = 0u;
      track_counters c = {0, 0, 0};
      for (int i = 0; i < n; ++i) {
        rng_state rng = rng_init(17u, uint(i), uint(mode));
        vec3 beta = vec3_splat(1.0f);
        float t = 0.0f;
        const int e = tracking_delta(narval::test::hostContext(&g.medium, view, &status, &c), r.o, r.d, r.t0, r.t1,
                                     &rng, &beta, &t);
        escaped += e == TRACK_ESCAPED;
        scattered += e == TRACK_SCATTERED;
      }
      EXPECT_EQ(status, 0u) << r.name;
      EXPECT_EQ(c.lookups, c.tentative) << r.name;  // delta tracking alone: one lookup per tentative collision
      EXPECT_EQ(c.real, (unsigned long long)(n - escaped)) << r.name;
      tentative[mode] = c.tentative;
      const char* name = mode == 0 ? "grid" : "global";
      const double pe = escaped / double(n), ps = scattered / double(n), Ps = albedo * (1 - T);
      EXPECT_NEAR(pe, T, 4 * std::sqrt(T * (1 - T) / n)) << r.name << ", " << name << ", tau " << tau;
      EXPECT_NEAR(ps, Ps, 4 * std::sqrt(Ps * (1 - Ps) / n)) << r.name << ", " << name;
      const double wrong = std::exp(-1.03 * tau);
      if (tau > 1.0) {
        EXPECT_GT(std::fabs(pe - wrong), 4 * std::sqrt(T * (1 - T) / n)) << r.name << ": control";
        ++controlsSeen;
      }
    }
    EXPECT_LT(tentative[0], tentative[1]) << r.name;
  }
  EXPECT_GE(controlsSeen, 4) << "the rays should include thick ones, or the control proves little";
}

// Spectral tracking (chromatic σ) with the majorant grid: σa = (0.02, 0.1, 0.05), σs = (0.05, 0.05,
// 0.2) per unit density, so σt = (0.07, 0.15, 0.25) and σ̄ follows max σt = 0.25. Unbiased per
// channel: E[β_c·1(escaped)] = exp(−σt_c ∫ρ) and E[β_c·1(scattered)] = (σs_c/σt_c)(1 − exp(−σt_c ∫ρ)),
// within 4 standard errors of the sample (N = 2·10⁵ per ray; 5 rays × 6 checks: 1.9e-3 in all).
TEST(TrackingMajorantStats, SpectralTrackingIsUnbiasedPerChannelOnTheGrid) {
  const nv_float4 sa = {0.02f, 0.1f, 0.05f, 0}, ss = {0.05f, 0.05f, 0.2f, 0};
  const EmptySpaceGrid g = makeEmptySpaceGrid(sa, ss, 0);
  const int n = 200000;
  for (const TestRay& r : testRays(g.medium)) {
    const double rho = densityIntegral(g.grid, r);
    MeanAccumulator esc[3], sca[3];
    uint status = 0u;
    track_counters c = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      rng_state rng = rng_init(23u, uint(i), 0u);
      vec3 beta = vec3_splat(1.0f);
      float t = 0.0f;
      const int e = tracking_delta(narval::test::hostContext(&g.medium, &g.withCells, &status, &c), r.o, r.d, r.t0,
                                   r.t1, &rng, &beta, &t);
      for (int ch = 0; ch < 3; ++ch) {
        esc[ch].add(e == TRACK_ESCAPED ? channelOf(beta, ch) : 0.0);
        sca[ch].add(e == TRACK_SCATTERED ? channelOf(beta, ch) : 0.0);
      }
    }
    EXPECT_EQ(status, 0u) << r.name;
    for (int ch = 0; ch < 3; ++ch) {
      const double st = double(channelOf4(sa, ch)) + channelOf4(ss, ch), T = std::exp(-st * rho);
      const MeanSe e = esc[ch].result(), s = sca[ch].result();
      EXPECT_NEAR(e.mean, T, 4 * e.se) << r.name << ", channel " << ch;
      EXPECT_NEAR(s.mean, channelOf4(ss, ch) / st * (1 - T), 4 * s.se) << r.name << ", channel " << ch;
    }
  }
}

// Ratio tracking with the majorant grid and with the global majorant: the mean of N = 10⁵ estimates
// per ray equals exp(−σt_c ∫ρ) per channel within 4 standard errors (5 rays × 2 × 3 channels at
// 6.3e-5: 1.9e-3). σt = (0.07, 0.15, 0.25) as above.
TEST(TrackingMajorantStats, RatioTrackingMatchesQuadrature) {
  const nv_float4 sa = {0.02f, 0.1f, 0.05f, 0}, ss = {0.05f, 0.05f, 0.2f, 0};
  const EmptySpaceGrid g = makeEmptySpaceGrid(sa, ss, 0);
  const int n = 100000;
  for (const TestRay& r : testRays(g.medium)) {
    const double rho = densityIntegral(g.grid, r);
    for (int mode = 0; mode < 2; ++mode) {
      const grid_view* view = mode == 0 ? &g.withCells : &g.withoutCells;
      MeanAccumulator acc[3];
      uint status = 0u;
      track_counters c = {0, 0, 0};
      for (int i = 0; i < n; ++i) {
        rng_state rng = rng_init(29u, uint(i), uint(mode));
        const vec3 tr = tracking_ratio(narval::test::hostContext(&g.medium, view, &status, &c), r.o, r.d, r.t0, r.t1, 0.0f,
                                       &rng);
        for (int ch = 0; ch < 3; ++ch) acc[ch].add(channelOf(tr, ch));
      }
      EXPECT_EQ(status, 0u);
      EXPECT_EQ(c.tentative, 0u);  // ratio tracking counts lookups only
      EXPECT_EQ(c.real, 0u);
      for (int ch = 0; ch < 3; ++ch) {
        const double st = double(channelOf4(sa, ch)) + channelOf4(ss, ch);
        const MeanSe s = acc[ch].result();
        EXPECT_NEAR(s.mean, std::exp(-st * rho), 4 * s.se)
            << r.name << ", " << (mode == 0 ? "grid" : "global") << ", channel " << ch;
      }
    }
  }
}

// ---- empty cells cost nothing ------------------------------------------------------------------

// The majorant cell(s) containing index point p (a closed cell: on a face, both sides), largest value.
float cellValueAt(const narval::MajorantGrid& mg, vec3 p) {
  float best = 0.0f;
  const float eps = 1e-4f;
  for (int dx = -1; dx <= 1; dx += 2)
    for (int dy = -1; dy <= 1; dy += 2)
      for (int dz = -1; dz <= 1; dz += 2) {
        const int i = std::clamp(int(std::floor((p.x + dx * eps) / mg.cellSize[0])), 0, mg.cellsX - 1);
        const int j = std::clamp(int(std::floor((p.y + dy * eps) / mg.cellSize[1])), 0, mg.cellsY - 1);
        const int k = std::clamp(int(std::floor((p.z + dz * eps) / mg.cellSize[2])), 0, mg.cellsZ - 1);
        best = std::max(best, mg.at(i, j, k));
      }
  return best;
}

// Every tentative collision of the grid walk (so every density lookup of both estimators, which
// look up exactly there) lies in a cell whose majorant is positive: 2·10⁴ walks per ray, each to
// the end of its segment with fresh τ ~ Exp(1) after every collision; a collision is attributed to
// the closed cell(s) around it. Control: the global walk's collisions do land in empty cells.
TEST(TrackingMajorantEmptyCells, NoTentativeCollisionInAnEmptyCell) {
  const EmptySpaceGrid g = makeEmptySpaceGrid({0.05f, 0.05f, 0.05f, 0}, {0.1f, 0.1f, 0.1f, 0}, 1);
  long long inEmpty[2] = {0, 0}, total[2] = {0, 0};
  for (const TestRay& r : testRays(g.medium))
    for (int mode = 0; mode < 2; ++mode)
      for (int i = 0; i < 20000; ++i) {
        rng_state rng = rng_init(31u, uint(i), uint(mode));
        tracking_walk w = tracking_walk_begin(&g.medium, mode == 0, r.o, r.d, r.t0, r.t1);
        uint status = 0u;
        while (tracking_walk_step(&w, g.cells.maxDensity.data(), sample_exponential(rng_uniform(&rng), 1.0f), &status)) {
          ++total[mode];
          inEmpty[mode] += cellValueAt(g.cells, vec3_madd(r.o, r.d, w.t)) == 0.0f;
        }
        ASSERT_EQ(status, 0u);
      }
  EXPECT_GT(total[0], 10000);
  EXPECT_EQ(inEmpty[0], 0) << "of " << total[0] << " collisions of the grid walk";
  EXPECT_GT(inEmpty[1], total[1] / 10) << "control: the global walk's collisions spread over the empty cells too";
}

// A ray through empty cells only (along x inside the empty tube, y = z = 1: the cells (·, 0, 0)):
// the grid walk of either estimator makes no tentative collision and no density lookup, draws one
// random number (its first τ, spent in no cell), delta escapes and ratio returns exactly 1. The
// global majorant on the same ray (control) makes lookups: Poisson(σ̄·16), σ̄ = 0.15·max ρ ≈ 0.3, so
// over 100 walks P(none) = e^{−480}.
TEST(TrackingMajorantEmptyCells, AWalkThroughEmptyCellsMakesNoLookup) {
  const EmptySpaceGrid g = makeEmptySpaceGrid({0.05f, 0.05f, 0.05f, 0}, {0.1f, 0.1f, 0.1f, 0}, 1);
  const vec3 o = vec3_make(-1.0f, 1.0f, 1.0f), d = vec3_make(1, 0, 0);
  medium_segment seg;
  ASSERT_TRUE(medium_intersect(&g.medium, o, d, 0.0f, NV_INFINITY, &seg));
  for (int i = 0; i < g.cells.cellsX; ++i) ASSERT_EQ(g.cells.at(i, 0, 0), 0.0f) << "the tube's cells must be empty";
  track_counters grid = {0, 0, 0}, global = {0, 0, 0};
  uint status = 0u;
  for (int i = 0; i < 100; ++i) {
    rng_state rng = rng_init(37u, uint(i), 0u);
    vec3 beta = vec3_splat(1.0f);
    float t = 0.0f;
    EXPECT_EQ(tracking_delta(narval::test::hostContext(&g.medium, &g.withCells, &status, &grid), seg.o, seg.d,
                             seg.t0, seg.t1, &rng, &beta, &t),
              TRACK_ESCAPED);
    EXPECT_EQ(rng.used, 1u);  // one draw of the first Philox block
    const vec3 tr = tracking_ratio(narval::test::hostContext(&g.medium, &g.withCells, &status, &grid), seg.o, seg.d,
                                   seg.t0, seg.t1, 0.0f, &rng);
    EXPECT_EQ(tr.x, 1.0f);
    EXPECT_EQ(tr.z, 1.0f);
    EXPECT_EQ(rng.used, 2u);
    rng_state rng2 = rng_init(37u, uint(i), 1u);
    tracking_delta(narval::test::hostContext(&g.medium, &g.withoutCells, &status, &global), seg.o, seg.d, seg.t0,
                   seg.t1, &rng2, &beta, &t);
    tracking_ratio(narval::test::hostContext(&g.medium, &g.withoutCells, &status, &global), seg.o, seg.d, seg.t0,
                   seg.t1, 0.0f, &rng2);
  }
  EXPECT_EQ(status, 0u);
  EXPECT_EQ(grid.tentative, 0u);
  EXPECT_EQ(grid.lookups, 0u);
  EXPECT_EQ(grid.real, 0u);
  EXPECT_GT(global.lookups, 0u);
  EXPECT_EQ(global.real, 0u);  // the tube is empty: every collision is null
}

// The global walk through tracking_walk is the previous code's arithmetic bit for bit: with one
// segment, t + (−ln(1 − u))/σ̄ compared with t_max as before (tracking.h), so --majorant global renders
// the pixels it always did. Checked against a copy of the old loop's free-flight arithmetic.
TEST(TrackingMajorantBudget, GlobalWalkIsTheOldArithmetic) {
  const EmptySpaceGrid g = makeEmptySpaceGrid({0.05f, 0.05f, 0.05f, 0}, {0.1f, 0.1f, 0.1f, 0}, 1);
  const TestRay r = testRays(g.medium)[4];
  for (int i = 0; i < 1000; ++i) {
    rng_state a = rng_init(41u, uint(i), 0u), b = a;
    tracking_walk w = tracking_walk_begin(&g.medium, 0, r.o, r.d, r.t0, r.t1);
    float t = r.t0;
    uint status = 0u;
    for (;;) {
      t += sample_exponential(rng_uniform(&a), g.medium.majorant);  // the old loop
      const int old_in = t < r.t1;
      const int in = tracking_walk_step(&w, nullptr, sample_exponential(rng_uniform(&b), 1.0f), &status);
      ASSERT_EQ(in, old_in);
      if (!in) break;
      ASSERT_EQ(w.t, t);
    }
  }
}

}  // namespace
