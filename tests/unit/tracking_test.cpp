// tracking_test.cpp: the medium box test (kernels/shared/intersect.h), the host grid reconstruction
// (kernels/shared/grid.h, host branch), the free-flight and transmittance estimators
// (kernels/shared/tracking.h), on the host —
// the very code the device compiles. Every statistical bound is stated with its false-alarm rate;
// every such test has a control showing the bound is tight enough to see a real error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "shared/medium.h"
#include "shared/phase.h"
#include "shared/tracking.h"
#include "unit/stat_util.h"
#include "unit/host_context.h"

namespace {

// ---- helpers ----

medium_params makeMedium(nv_float4 sigmaA, nv_float4 sigmaS, float majorant, int grey, nv_float4 dims) {
  medium_params m{};
  m.world_to_index.row[0] = {1.0f, 0.0f, 0.0f, 0.0f};
  m.world_to_index.row[1] = {0.0f, 1.0f, 0.0f, 0.0f};
  m.world_to_index.row[2] = {0.0f, 0.0f, 1.0f, 0.0f};
  m.dims = dims;
  m.sigma_a = sigmaA;
  m.sigma_s = sigmaS;
  m.majorant = majorant;
  m.phase = phase_make(PHASE_ISOTROPIC, 0.0f);
  m.grey = grey;
  return m;
}
nv_float4 grey4(float s) { return {s, s, s, 0.0f}; }
float channel(vec3 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }
float channel4(nv_float4 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }

// Mean and standard error of the mean of a sample: tests/unit/stat_util.h.
using narval::test::MeanAccumulator;
using narval::test::MeanSe;

// ---- intersect_box ----

// Axis-aligned hit from outside: o = (−1, 0.5, 0.5), d = +x against [0,2]×[0,3]×[0,4]: the x slab
// gives t ∈ [1, 3], y and z (d = 0, origin inside the slab) give (−∞, ∞): [1, 3] exactly.
TEST(IntersectBox, AxisParallelHitFromOutside) {
  float tn = 0.0f, tf = 0.0f;
  ASSERT_TRUE(intersect_box(vec3_make(-1.0f, 0.5f, 0.5f), vec3_make(1.0f, 0.0f, 0.0f), vec3_make(2.0f, 3.0f, 4.0f), &tn, &tf));
  EXPECT_EQ(tn, 1.0f);
  EXPECT_EQ(tf, 3.0f);
  // Along −y from above: y slab t ∈ [(3−5)/−1, (0−5)/−1] = [2, 5].
  ASSERT_TRUE(intersect_box(vec3_make(1.0f, 5.0f, 2.0f), vec3_make(0.0f, -1.0f, 0.0f), vec3_make(2.0f, 3.0f, 4.0f), &tn, &tf));
  EXPECT_EQ(tn, 2.0f);
  EXPECT_EQ(tf, 5.0f);
  // A negative zero component behaves like a zero one: 1/−0 = −∞, slab (−∞, ∞) for 0 < o.x < 2.
  ASSERT_TRUE(intersect_box(vec3_make(1.0f, 5.0f, 2.0f), vec3_make(-0.0f, -1.0f, 0.0f), vec3_make(2.0f, 3.0f, 4.0f), &tn, &tf));
  EXPECT_EQ(tn, 2.0f);
  EXPECT_EQ(tf, 5.0f);
}

// Oblique hit, unnormalised d = (2, 1, 0.5) from o = (−1, 0.5, 1) against [0, 4]³: slabs
// x: [(0+1)/2, (4+1)/2] = [0.5, 2.5], y: [−0.5/1, 3.5/1] = [−0.5, 3.5], z: [−1/0.5, 3/0.5] = [−2, 6];
// near = max = 0.5, far = min = 2.5. And the main diagonal of [0,2]³ from (−1,−1,−1) along
// (1,1,1)/√3: near = √3, far = 3√3.
TEST(IntersectBox, ObliqueHits) {
  float tn = 0.0f, tf = 0.0f;
  ASSERT_TRUE(intersect_box(vec3_make(-1.0f, 0.5f, 1.0f), vec3_make(2.0f, 1.0f, 0.5f), vec3_splat(4.0f), &tn, &tf));
  EXPECT_FLOAT_EQ(tn, 0.5f);
  EXPECT_FLOAT_EQ(tf, 2.5f);
  const float s = 1.0f / std::sqrt(3.0f);
  ASSERT_TRUE(intersect_box(vec3_splat(-1.0f), vec3_splat(s), vec3_splat(2.0f), &tn, &tf));
  EXPECT_NEAR(tn, std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(tf, 3.0 * std::sqrt(3.0), 1e-6);
}

// Misses: an axis-parallel ray outside the y slab (t_far = −∞); a ray passing beside a corner of
// [0,1]³ (o = (−1, 1.5, 0.5), d = (1, 1, 0): x needs t ∈ [1, 2], y needs t ∈ [−1.5, −0.5]: disjoint).
TEST(IntersectBox, Misses) {
  float tn = 0.0f, tf = 0.0f;
  EXPECT_FALSE(intersect_box(vec3_make(-1.0f, 5.0f, 0.5f), vec3_make(1.0f, 0.0f, 0.0f), vec3_make(2.0f, 3.0f, 4.0f), &tn, &tf));
  EXPECT_FALSE(intersect_box(vec3_make(-1.0f, 1.5f, 0.5f), vec3_make(1.0f, 1.0f, 0.0f), vec3_splat(1.0f), &tn, &tf));
  EXPECT_FALSE(intersect_box(vec3_make(-1.0f, -1.0f, 0.5f), vec3_make(1.0f, -1.0f, 0.0f), vec3_splat(1.0f), &tn, &tf));
}

// Origin inside: o = (0.5, 1, 2), d = +z in [0,2]×[0,3]×[0,4]: t ∈ [−2, 2], so t_near < 0 < t_far.
// The test is on the ray's line, so a box entirely behind the origin also "hits" with t_far < 0
// (o = (5, .5, .5), d = +x, box [0,1]³: [−5, −4]); medium_intersect clips to [t_min, t_max] and
// rejects it.
TEST(IntersectBox, OriginInsideAndBoxBehind) {
  float tn = 0.0f, tf = 0.0f;
  ASSERT_TRUE(intersect_box(vec3_make(0.5f, 1.0f, 2.0f), vec3_make(0.0f, 0.0f, 1.0f), vec3_make(2.0f, 3.0f, 4.0f), &tn, &tf));
  EXPECT_EQ(tn, -2.0f);
  EXPECT_EQ(tf, 2.0f);
  ASSERT_TRUE(intersect_box(vec3_make(5.0f, 0.5f, 0.5f), vec3_make(1.0f, 0.0f, 0.0f), vec3_splat(1.0f), &tn, &tf));
  EXPECT_EQ(tn, -5.0f);
  EXPECT_EQ(tf, -4.0f);

  const medium_params m = makeMedium(grey4(0.0f), grey4(1.0f), 1.0f, 1, {1.0f, 1.0f, 1.0f, 0.0f});
  medium_segment seg;
  EXPECT_FALSE(medium_intersect(&m, vec3_make(5.0f, 0.5f, 0.5f), vec3_make(1.0f, 0.0f, 0.0f), 0.0f, NV_INFINITY, &seg));
  ASSERT_TRUE(medium_intersect(&m, vec3_make(0.5f, 0.5f, 0.25f), vec3_make(0.0f, 0.0f, 1.0f), 0.0f, NV_INFINITY, &seg));
  EXPECT_EQ(seg.t0, 0.0f);  // clipped from −0.25 to t_min
  EXPECT_EQ(seg.t1, 0.75f);
}

// A ray lying in a face plane (o.x on the plane, d.x = 0) produces 0·∞ = NaN in that slab, which
// fmin/fmax discard. Whatever the answer, it must be NaN-free and the same for the two opposite
// faces x = 0 and x = hi (it is currently "miss" for both: such rays have measure zero).
TEST(IntersectBox, RayInAFacePlaneIsConsistentAndNaNFree) {
  float tn0 = 0.0f, tf0 = 0.0f, tn1 = 0.0f, tf1 = 0.0f;
  const int h0 = intersect_box(vec3_make(0.0f, -1.0f, 0.5f), vec3_make(0.0f, 1.0f, 0.0f), vec3_splat(1.0f), &tn0, &tf0);
  const int h1 = intersect_box(vec3_make(1.0f, -1.0f, 0.5f), vec3_make(0.0f, 1.0f, 0.0f), vec3_splat(1.0f), &tn1, &tf1);
  EXPECT_FALSE(std::isnan(tn0) || std::isnan(tf0) || std::isnan(tn1) || std::isnan(tf1));
  EXPECT_EQ(h0, h1);
}

// ---- grid_density (host branch) ----

// 2×2×2 grid, x fastest: c000 = 1, c100 = 2, c010 = 3, c110 = 5, c001 = 7, c101 = 11, c011 = 13,
// c111 = 17. Voxel centres are at i + 0.5, so p = (0.75, 1.0, 1.25) has weights ax = 0.25,
// ay = 0.5, az = 0.75:
//   along x: z0y0 = 1·0.75 + 2·0.25 = 1.25, z0y1 = 3·0.75 + 5·0.25 = 3.5,
//            z1y0 = 7·0.75 + 11·0.25 = 8,    z1y1 = 13·0.75 + 17·0.25 = 14;
//   along y: z0 = (1.25 + 3.5)/2 = 2.375, z1 = (8 + 14)/2 = 11;  along z: 2.375·0.25 + 11·0.75 = 8.84375
// (every step exact in binary floating point).
TEST(GridDensityHost, TrilinearByHand) {
  const float data[8] = {1, 2, 3, 5, 7, 11, 13, 17};
  const grid_view g = {data, 2, 2, 2};
  EXPECT_EQ(grid_view_density(&g, vec3_make(0.75f, 1.0f, 1.25f)), 8.84375f);
  // Voxel centres return the voxel exactly.
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x)
        EXPECT_EQ(grid_view_density(&g, vec3_make(x + 0.5f, y + 0.5f, z + 0.5f)), data[x + 2 * y + 4 * z]);
  // Midway between the centres of voxels (0,0,0) and (1,0,0): (1 + 2)/2.
  EXPECT_EQ(grid_view_density(&g, vec3_make(1.0f, 0.5f, 0.5f)), 1.5f);
}

// Trilinear interpolation reproduces a linear field exactly between voxel centres: with
// v(i, j, k) = 1 + i + 10 j + 100 k, density(p) = 1 + (px − 0.5) + 10(py − 0.5) + 100(pz − 0.5)
// for p inside the hull of the centres [0.5, n − 0.5]³ (up to float rounding: values ≤ 1000,
// tolerance 1e-3 ≈ 16 ulp).
TEST(GridDensityHost, ReproducesALinearField) {
  const int nx = 5, ny = 4, nz = 3;
  std::vector<float> data(nx * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) data[i + nx * (j + ny * k)] = 1.0f + i + 10.0f * j + 100.0f * k;
  const grid_view g = {data.data(), nx, ny, nz};
  std::mt19937 gen(21);
  std::uniform_real_distribution<float> ux(0.5f, nx - 0.5f), uy(0.5f, ny - 0.5f), uz(0.5f, nz - 0.5f);
  for (int n = 0; n < 2000; ++n) {
    const vec3 p = vec3_make(ux(gen), uy(gen), uz(gen));
    const double expected = 1.0 + (p.x - 0.5) + 10.0 * (p.y - 0.5) + 100.0 * (p.z - 0.5);
    ASSERT_NEAR(grid_view_density(&g, p), expected, 1e-3) << p.x << ", " << p.y << ", " << p.z;
  }
}

// Density outside the grid is 0: a point at least half a voxel beyond the grid has all eight taps
// outside (p.x = −0.5 gives taps −1 and 0 with weight 1 on −1; p.x = n + 0.5 gives taps n, n+1).
// Between the box face and the outermost centre the lookup blends with that zero border (as
// CLK_ADDRESS_CLAMP with a zero border colour does on the device): p.x = 0 is half voxel 0.
TEST(GridDensityHost, ZeroOutsideAndHalfAtTheFace) {
  const float data[8] = {1, 2, 3, 5, 7, 11, 13, 17};
  const grid_view g = {data, 2, 2, 2};
  for (const vec3& p : {vec3_make(-0.5f, 1.0f, 1.0f), vec3_make(2.5f, 1.0f, 1.0f), vec3_make(1.0f, -0.5f, 1.0f),
                        vec3_make(1.0f, 2.5f, 1.0f), vec3_make(1.0f, 1.0f, -0.5f), vec3_make(1.0f, 1.0f, 2.5f),
                        vec3_make(-3.0f, 7.0f, 0.5f), vec3_make(100.0f, -50.0f, 1000.0f)})
    EXPECT_EQ(grid_view_density(&g, p), 0.0f) << p.x << ", " << p.y << ", " << p.z;
  EXPECT_EQ(grid_view_density(&g, vec3_make(0.0f, 0.5f, 0.5f)), 0.5f);  // (0 + 1)/2
  EXPECT_EQ(grid_view_density(&g, vec3_make(2.0f, 0.5f, 0.5f)), 1.0f);  // (2 + 0)/2
  // A homogeneous view (data NULL) is density 1 everywhere.
  const grid_view h = {nullptr, 1, 1, 1};
  EXPECT_EQ(grid_view_density(&h, vec3_make(123.0f, -4.0f, 0.5f)), 1.0f);
}

// Far-away and non-finite coordinates must read 0, as on the device, where grid.h clamps the
// coordinates to [−1, 1e7] before the image lookup (DESIGN.md: clamp huge or infinite coordinates
// yourself). The host branch does not clamp: (int)floorf(1e10f) overflows int (undefined
// behaviour) and for p.x = ±inf the weight ax = inf − inf = NaN makes the density NaN.
TEST(GridDensityHost, HugeAndInfiniteCoordinatesReadZeroLikeTheDevice) {
  const float data[8] = {1, 2, 3, 5, 7, 11, 13, 17};
  const grid_view g = {data, 2, 2, 2};
  const float inf = std::numeric_limits<float>::infinity();
  for (const vec3& p : {vec3_make(1e10f, 0.5f, 0.5f), vec3_make(-1e10f, 0.5f, 0.5f), vec3_make(inf, 0.5f, 0.5f),
                        vec3_make(0.5f, -inf, 0.5f), vec3_make(0.5f, 0.5f, inf)})
    EXPECT_EQ(grid_view_density(&g, p), 0.0f) << p.x << ", " << p.y << ", " << p.z;
}

// ---- tracking_ratio ----

// Homogeneous medium (grid_view with data NULL, density 1): the closed form e^{−σt·(t_max − t)} per
// channel, bit for bit the float expression expf(−(σa + σs)·len), without consuming random numbers.
TEST(TrackingRatio, HomogeneousIsBeerLambert) {
  const medium_params m = makeMedium({0.1f, 0.5f, 2.0f, 0}, {0.3f, 0.25f, 1.0f, 0}, 3.0f, 0, {1, 1, 1, 0});
  const grid_view h = {nullptr, 1, 1, 1};
  rng_state rng = rng_init(1u, 2u, 3u);
  uint status = 0u;
  const float t0 = 0.25f, t1 = 2.0f;
  const vec3 tr = tracking_ratio(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f),
                                 vec3_make(0.0f, 0.0f, 1.0f), t0, t1, 0.0f, &rng);
  for (int c = 0; c < 3; ++c) {
    const float st = channel4(m.sigma_a, c) + channel4(m.sigma_s, c);
    EXPECT_EQ(channel(tr, c), expf(-(st * (t1 - t0)))) << "channel " << c;
    EXPECT_NEAR(channel(tr, c), std::exp(-double(st) * 1.75), 1e-6 * std::exp(-double(st) * 1.75));
  }
  EXPECT_EQ(rng.used, 4u);  // untouched: no Philox block drawn
  EXPECT_EQ(status, 0u);
  // An empty or reversed interval transmits everything.
  const vec3 one = tracking_ratio(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f),
                                  vec3_make(0.0f, 0.0f, 1.0f), 2.0f, 1.0f, 0.0f, &rng);
  EXPECT_EQ(one.x, 1.0f);
  EXPECT_EQ(one.z, 1.0f);
}

// A small random grid (5×4×6 densities uniform in [0, 2]) and an oblique ray through the whole box.
struct RandomGridCase {
  std::vector<float> data;
  grid_view grid;
  medium_params medium;
  vec3 o, d;
  float t0, t1;
};
RandomGridCase makeRandomGridCase() {
  RandomGridCase c;
  const int nx = 5, ny = 4, nz = 6;
  std::mt19937 gen(77);
  std::uniform_real_distribution<float> uni(0.0f, 2.0f);
  c.data.resize(nx * ny * nz);
  for (float& v : c.data) v = uni(gen);
  c.grid = {c.data.data(), nx, ny, nz};
  // σt = (0.8, 0.8, 1.3) per unit density, ρ ≤ 2: σt·ρ ≤ 2.6 ≤ majorant 3.
  c.medium = makeMedium({0.2f, 0.5f, 0.1f, 0}, {0.6f, 0.3f, 1.2f, 0}, 3.0f, 0, {5, 4, 6, 0});
  c.o = vec3_make(-1.0f, 0.3f, 0.7f);
  c.d = vec3_normalize(vec3_make(1.0f, 0.6f, 0.9f));
  intersect_box(c.o, c.d, vec3_from4(c.medium.dims), &c.t0, &c.t1);
  return c;
}

// ∫ ρ(o + t·d) dt over [t0, t1], composite Simpson with 2·10⁵ panels in double on grid_density. ρ
// is piecewise cubic along the ray with kinks where it crosses voxel-centre planes: the error is
// O(h²·jumps) ≈ 1e-9, far below the Monte Carlo error compared with below.
double opticalDepthOfDensity(const RandomGridCase& c, float shift) {
  const int n = 200000;
  const double h = (double(c.t1) - c.t0) / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double t = c.t0 + i * h;
    const vec3 p = vec3_make(static_cast<float>(c.o.x + t * c.d.x) + shift, static_cast<float>(c.o.y + t * c.d.y) + shift,
                             static_cast<float>(c.o.z + t * c.d.z) + shift);
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * grid_view_density(&c.grid, p);
  }
  return sum * h / 3.0;
}

// Ratio tracking is unbiased: the mean of N = 2·10⁵ estimates (independent streams) equals
// T_c = exp(−σt_c ∫ρ) within 4 standard errors per channel (false alarm 6.3e-5 each, 1.9e-4 for the
// three). Control: the reference computed with voxel centres at integers instead of i + 0.5 (the
// field shifted by half a voxel) is far outside that band, so the test sees a half-voxel error.
// The same with Russian roulette below Tr = 0.5 (far above pbrt-v4's 0.05, so that most walks play
// it: at least a quarter of them end at 0, which plain ratio tracking never returns here): still
// unbiased, at a larger standard error.
TEST(TrackingRatio, UnbiasedOnARandomGridWithAndWithoutRoulette) {
  const RandomGridCase c = makeRandomGridCase();
  ASSERT_LT(c.t0, c.t1);
  const double tau = opticalDepthOfDensity(c, 0.0f), tauShifted = opticalDepthOfDensity(c, 0.5f);
  const int n = 200000;
  for (const float roulette : {0.0f, 0.5f}) {
    MeanAccumulator acc[3];
    uint status = 0u;
    int zeros = 0;
    for (int i = 0; i < n; ++i) {
      rng_state rng = rng_init(9u, static_cast<uint>(i), 0u);
      const vec3 tr =
          tracking_ratio(narval::test::hostContext(&c.medium, &c.grid, &status), c.o, c.d, c.t0, c.t1, roulette, &rng);
      for (int ch = 0; ch < 3; ++ch) acc[ch].add(channel(tr, ch));
      zeros += vec3_is_zero(tr);
    }
    EXPECT_EQ(status, 0u);
    if (roulette > 0)
      EXPECT_GT(zeros, n / 4) << "roulette hardly played";
    else
      EXPECT_EQ(zeros, 0);
    for (int ch = 0; ch < 3; ++ch) {
      const double st = double(channel4(c.medium.sigma_a, ch)) + channel4(c.medium.sigma_s, ch);
      const double expected = std::exp(-st * tau), wrong = std::exp(-st * tauShifted);
      const MeanSe r = acc[ch].result();
      EXPECT_NEAR(r.mean, expected, 4.0 * r.se) << "channel " << ch << " (tau = " << tau << ", roulette " << roulette << ")";
      EXPECT_GT(std::fabs(r.mean - wrong), 10.0 * r.se) << "channel " << ch << ": control too close";
    }
  }
}

// ---- tracking_delta ----

// Grey homogeneous medium σa = 0.3, σs = 0.7 (σt = 1) with majorant 1.6 (so 37.5% of tentative
// collisions are null), walking [0.25, 1.75] (L = 1.5), N = 10⁶ walks: P(escape) = e^{−σt L} =
// 0.2231, P(scatter) = (σs/σt)(1 − e^{−σt L}) = 0.5438, P(absorb) = (σa/σt)(1 − e^{−σt L}) = 0.2331,
// each within a binomial 4σ = 4√(p(1−p)/N) (false alarm 6.3e-5 each). The scattering distance
// s = t − 0.25 follows σt e^{−σt s} truncated to [0, L]: E[s] = 1/σt − L e^{−σt L}/(1 − e^{−σt L})
// = 0.5692, within 4 standard errors. β stays 1 (analogue walk).
TEST(TrackingDelta, GreyHomogeneousEventProbabilities) {
  const float sa = 0.3f, ss = 0.7f, L = 1.5f, t0 = 0.25f;
  const medium_params m = makeMedium(grey4(sa), grey4(ss), 1.6f, 1, {1, 1, 1, 0});
  const grid_view h = {nullptr, 1, 1, 1};
  const int n = 1000000;
  int counts[3] = {0, 0, 0};
  MeanAccumulator dist;
  uint status = 0u;
  for (int i = 0; i < n; ++i) {
    rng_state rng = rng_init(3u, static_cast<uint>(i), 7u);
    vec3 beta = vec3_splat(1.0f);
    float t = -1.0f;
    const int e = tracking_delta(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f), vec3_make(1, 0, 0),
                                 t0, t0 + L, &rng, &beta, &t);
    ASSERT_GE(e, 0);
    ASSERT_LE(e, 2);
    ++counts[e];
    ASSERT_EQ(beta.x, 1.0f);
    if (e == TRACK_SCATTERED) {
      ASSERT_GE(t, t0);
      ASSERT_LT(t, t0 + L);
      dist.add(t - t0);
    }
  }
  EXPECT_EQ(status, 0u);
  const double st = sa + ss, T = std::exp(-st * L);
  const double p[3] = {T, ss / st * (1.0 - T), sa / st * (1.0 - T)};
  const char* names[3] = {"escaped", "scattered", "absorbed"};
  for (int e = 0; e < 3; ++e) {
    const double sigma = std::sqrt(p[e] * (1.0 - p[e]) / n);
    EXPECT_NEAR(counts[e] / double(n), p[e], 4.0 * sigma) << names[e];
  }
  const MeanSe r = dist.result();
  EXPECT_NEAR(r.mean, 1.0 / st - L * T / (1.0 - T), 4.0 * r.se);
}

// Control for the binomial bound: with N = 10⁶ the escape fraction separates e^{−1.5} = 0.2231
// from e^{−1.5·1.01} = 0.2198 (a 1% error in σt) by 0.0033 = 8σ: the analogue walk on σt = 1.01
// must be rejected by the bound used above.
TEST(TrackingDelta, BinomialBoundSeesAOnePercentError) {
  const medium_params m = makeMedium(grey4(0.3f), grey4(0.71f), 1.6f, 1, {1, 1, 1, 0});
  const grid_view h = {nullptr, 1, 1, 1};
  const int n = 1000000;
  int escaped = 0;
  uint status = 0u;
  for (int i = 0; i < n; ++i) {
    rng_state rng = rng_init(3u, static_cast<uint>(i), 7u);
    vec3 beta = vec3_splat(1.0f);
    float t = 0.0f;
    escaped += tracking_delta(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f), vec3_make(1, 0, 0),
                              0.25f, 1.75f, &rng, &beta, &t) ==
               TRACK_ESCAPED;
  }
  const double T = std::exp(-1.5), sigma = std::sqrt(T * (1.0 - T) / n);
  EXPECT_GT(std::fabs(escaped / double(n) - T), 4.0 * sigma);
}

// Chromatic homogeneous medium σa = (0.1, 0.4, 0.05), σs = (0.3, 0.5, 1.6), so σt = (0.4, 0.9, 1.65),
// majorant 2, L = 1.2, N = 10⁶: spectral tracking is unbiased per channel, i.e.
//   E[β_c · 1(escaped)]   = e^{−σt_c L}                        (0.6188, 0.3396, 0.1381),
//   E[β_c · 1(scattered)] = (σs_c/σt_c)(1 − e^{−σt_c L})       (0.2859, 0.3669, 0.8359),
// each within 4 standard errors of the sample (false alarm 6.3e-5 each, 3.8e-4 for the six).
TEST(TrackingDelta, ChromaticSpectralTrackingIsUnbiasedPerChannel) {
  const nv_float4 sa = {0.1f, 0.4f, 0.05f, 0}, ss = {0.3f, 0.5f, 1.6f, 0};
  const float L = 1.2f;
  const medium_params m = makeMedium(sa, ss, 2.0f, 0, {1, 1, 1, 0});
  const grid_view h = {nullptr, 1, 1, 1};
  const int n = 1000000;
  MeanAccumulator esc[3], sca[3];
  uint status = 0u;
  for (int i = 0; i < n; ++i) {
    rng_state rng = rng_init(4u, static_cast<uint>(i), 0u);
    vec3 beta = vec3_splat(1.0f);
    float t = 0.0f;
    const int e = tracking_delta(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f), vec3_make(0, 1, 0),
                                 0.0f, L, &rng, &beta, &t);
    ASSERT_TRUE(vec3_is_finite(beta));
    for (int c = 0; c < 3; ++c) {
      esc[c].add(e == TRACK_ESCAPED ? channel(beta, c) : 0.0);
      sca[c].add(e == TRACK_SCATTERED ? channel(beta, c) : 0.0);
    }
  }
  EXPECT_EQ(status, 0u);
  for (int c = 0; c < 3; ++c) {
    const double st = double(channel4(sa, c)) + channel4(ss, c), T = std::exp(-st * L);
    const MeanSe re = esc[c].result(), rs = sca[c].result();
    EXPECT_NEAR(re.mean, T, 4.0 * re.se) << "escaped, channel " << c;
    EXPECT_NEAR(rs.mean, channel4(ss, c) / st * (1.0 - T), 4.0 * rs.se) << "scattered, channel " << c;
  }
}

// A majorant of 0 means no medium: the walk escapes at once; an all-null medium with an absurd
// majorant (10⁹ collisions per unit, more steps than TRACKING_MAX_STEPS = 10⁷, and steps of ~1e-9
// that cannot even advance t = 0.25 in float) stops at the cap, flags STATUS_ITERATION_CAP and
// returns absorbed (delta) or 0 (ratio): no endless loop.
TEST(TrackingDelta, ZeroMajorantEscapesAndIterationCapIsFlagged) {
  const grid_view h = {nullptr, 1, 1, 1};
  const float data[1] = {1.0f};
  const grid_view g = {data, 1, 1, 1};
  rng_state rng = rng_init(1u, 1u, 1u);
  vec3 beta = vec3_splat(1.0f);
  float t = 0.0f;
  uint status = 0u;
  const medium_params empty = makeMedium(grey4(0.5f), grey4(0.5f), 0.0f, 1, {1, 1, 1, 0});
  EXPECT_EQ(tracking_delta(narval::test::hostContext(&empty, &h, &status), vec3_splat(0.0f), vec3_make(1, 0, 0),
                           0.0f, 1.0f, &rng, &beta, &t),
            TRACK_ESCAPED);
  EXPECT_EQ(status, 0u);
  const medium_params nullOnly = makeMedium(grey4(0.0f), grey4(0.0f), 1e9f, 1, {1, 1, 1, 0});
  EXPECT_EQ(tracking_delta(narval::test::hostContext(&nullOnly, &h, &status), vec3_splat(0.0f), vec3_make(1, 0, 0),
                           0.25f, 1.0f, &rng, &beta, &t),
            TRACK_ABSORBED);
  EXPECT_EQ(status, static_cast<uint>(STATUS_ITERATION_CAP));
  status = 0u;
  const vec3 tr = tracking_ratio(narval::test::hostContext(&nullOnly, &g, &status), vec3_make(0.5f, 0.5f, 0.0f),
                                 vec3_make(0, 0, 1), 0.25f, 0.75f, 0.0f, &rng);
  EXPECT_EQ(tr.x, 0.0f);
  EXPECT_EQ(status, static_cast<uint>(STATUS_ITERATION_CAP));
}

}  // namespace
