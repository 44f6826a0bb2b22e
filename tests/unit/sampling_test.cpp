// sampling_test.cpp: the warps of kernels/shared/sampling.h on the host (the very code the device
// compiles). Distributions are checked Mitsuba-style with χ² tests over equal-probability cells
// (whose expected counts are then N / cells, derived per test), geometry with exact identities.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "shared/sampling.h"
#include "unit/stat_util.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

// Statistics helpers (gammaQ, equalCellsChiSquarePValue): tests/unit/stat_util.h.
using namespace narval::test;

double angle01(double y, double x) {  // atan2 mapped to [0, 1)
  double a = std::atan2(y, x) / (2.0 * kPi);
  if (a < 0.0) a += 1.0;
  return a >= 1.0 ? 0.0 : a;
}

// The χ² tests of this file (sphere, disk, disk control) share a total significance of 1e-3:
// each runs at 1e-3 / 2 (the control must reject, so it does not count).
constexpr double kAlpha = 1e-3 / 2;

// Tabulated χ²₁₀ tail P(χ² > 18.307038) = 0.05: the helper is not an always-accept.
TEST(SamplingStatHelpers, ChiSquareTail) {
  EXPECT_NEAR(gammaQ(5.0, 18.307038 / 2.0), 0.05, 1e-6);
  EXPECT_NEAR(gammaQ(0.5, 3.841459 / 2.0), 0.05, 1e-6);
}

// Uniform sphere: |v| = 1 (r = √(1 − z²) is computed from z, so only rounding: < 2e-6); by symmetry
// E[v] = 0 with Var[v_i] = 1/3 (E[z²] = ∫_{-1}^{1} z²/2 dz = 1/3), so each mean component of N = 10⁶
// samples lies within 4σ = 4/√(3N) = 2.3e-3 (false alarm 6.3e-5 per component). Archimedes: the
// area of a band is proportional to its z extent, so 20 equal z bins × 40 equal φ bins are cells of
// equal probability 1/800, expected N/800 = 1250 each.
TEST(SamplingUniformSphere, IsUnitAndUniform) {
  const int n = 1000000, kz = 20, kphi = 40;
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  double sx = 0.0, sy = 0.0, sz = 0.0;
  std::vector<double> counts(kz * kphi, 0.0);
  for (int i = 0; i < n; ++i) {
    const vec3 v = sample_uniform_sphere(uni(gen), uni(gen));
    ASSERT_NEAR(vec3_length(v), 1.0f, 2e-6f);
    sx += v.x;
    sy += v.y;
    sz += v.z;
    const int iz = std::min(kz - 1, static_cast<int>((v.z + 1.0) * 0.5 * kz));
    const int ip = std::min(kphi - 1, static_cast<int>(angle01(v.y, v.x) * kphi));
    counts[iz * kphi + ip] += 1.0;
  }
  const double bound = 4.0 / std::sqrt(3.0 * n);
  EXPECT_NEAR(sx / n, 0.0, bound);
  EXPECT_NEAR(sy / n, 0.0, bound);
  EXPECT_NEAR(sz / n, 0.0, bound);
  double chi2 = 0.0;
  const double p = equalCellsChiSquarePValue(counts, &chi2);
  EXPECT_GE(p, kAlpha) << "chi2 = " << chi2;
  // End points: u1 = 0 -> z = +1 (north pole), u1 -> 1 -> z -> −1.
  EXPECT_EQ(sample_uniform_sphere(0.0f, 0.3f).z, 1.0f);
  EXPECT_NEAR(sample_uniform_sphere(0.99999994f, 0.3f).z, -1.0f, 1e-6f);
}

// The concentric map sends [0,1]² into the closed unit disk: checked on a 257 × 257 lattice that
// includes the square's edges (where |p| = 1: u1 = 1 gives a = 1 ≥ |b|, r = 1) and its centre
// (u = (1/2, 1/2) -> (0, 0)).
TEST(SamplingConcentricDisk, StaysInsideTheUnitDisk) {
  for (int i = 0; i <= 256; ++i) {
    for (int j = 0; j <= 256; ++j) {
      float x = 2.0f, y = 2.0f;
      sample_concentric_disk(i / 256.0f, j / 256.0f, &x, &y);
      ASSERT_LE(x * x + y * y, 1.0f + 2e-6f) << i << ", " << j;
      if (i == 0 || i == 256 || j == 0 || j == 256) {
        EXPECT_NEAR(x * x + y * y, 1.0f, 2e-6f) << i << ", " << j;
      }
    }
  }
  float x = 1.0f, y = 1.0f;
  sample_concentric_disk(0.5f, 0.5f, &x, &y);
  EXPECT_EQ(x, 0.0f);
  EXPECT_EQ(y, 0.0f);
}

// Uniform in area (pdf 1/π): with r² uniform on [0, 1] for a uniform disk, 10 rings of equal r²
// width × 16 equal sectors are cells of probability 1/160, expected 10⁶/160 = 6250 each.
double diskChiSquarePValue(bool squareTheRadius, double* chi2) {
  const int n = 1000000, kr = 10, ka = 16;
  std::mt19937 gen(12);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<double> counts(kr * ka, 0.0);
  for (int i = 0; i < n; ++i) {
    float x, y;
    sample_concentric_disk(uni(gen), uni(gen), &x, &y);
    double r2 = double(x) * x + double(y) * y;
    if (squareTheRadius) r2 *= r2;  // the control: a point at radius r² instead of r
    const int ir = std::min(kr - 1, static_cast<int>(r2 * kr));
    const int ia = std::min(ka - 1, static_cast<int>(angle01(y, x) * ka));
    counts[ir * ka + ia] += 1.0;
  }
  return equalCellsChiSquarePValue(counts, chi2);
}

TEST(SamplingConcentricDisk, IsUniformInArea) {
  double chi2 = 0.0;
  const double p = diskChiSquarePValue(false, &chi2);
  EXPECT_GE(p, kAlpha) << "chi2 = " << chi2;
}

// Control: a warp that puts the point at radius r² instead of r (density ∝ 1/√r², concentrated at
// the centre: 31.6% of the mass in the inner ring instead of 10%) must be rejected.
TEST(SamplingConcentricDisk, ChiSquareRejectsANonUniformDisk) {
  double chi2 = 0.0;
  EXPECT_LT(diskChiSquarePValue(true, &chi2), 1e-9) << "chi2 = " << chi2;
}

// sample_direction_around(w, μ, u): unit length, cosine μ to the axis (both to float rounding,
// < 2e-6), for random axes including the poles where Duff's basis switches sign (w = ±z), and
// azimuths half a turn apart are mirror images about the axis: v(u) + v(u + 1/2) = 2μ·w.
TEST(SamplingDirectionAround, HasTheRequestedCosine) {
  std::mt19937 gen(13);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<vec3> axes = {vec3_make(0, 0, 1), vec3_make(0, 0, -1), vec3_make(1, 0, 0), vec3_make(0, -1, 0),
                            vec3_normalize(vec3_make(1e-4f, 0.0f, -1.0f))};
  for (int i = 0; i < 200; ++i) axes.push_back(sample_uniform_sphere(uni(gen), uni(gen)));
  for (const vec3& w : axes) {
    for (float mu : {-1.0f, -0.99f, -0.5f, 0.0f, 0.3f, 0.999f, 1.0f}) {
      for (int k = 0; k < 8; ++k) {
        const float u = uni(gen) * 0.5f;
        const vec3 v = sample_direction_around(w, mu, u);
        ASSERT_NEAR(vec3_length(v), 1.0f, 2e-6f);
        ASSERT_NEAR(vec3_dot(v, w), mu, 2e-6f) << "w = (" << w.x << ", " << w.y << ", " << w.z << ")";
        const vec3 opposite = sample_direction_around(w, mu, u + 0.5f);
        const vec3 sum = vec3_add(v, opposite);
        ASSERT_NEAR(sum.x, 2.0f * mu * w.x, 1e-5f);
        ASSERT_NEAR(sum.y, 2.0f * mu * w.y, 1e-5f);
        ASSERT_NEAR(sum.z, 2.0f * mu * w.z, 1e-5f);
      }
    }
  }
}

// The azimuth is uniform about the axis: for μ = 0 the directions are a great circle ⊥ w, and
// successive quarter turns u, u + 1/4 are orthogonal: dot = cos(π/2) = 0.
TEST(SamplingDirectionAround, QuarterTurnsAreOrthogonal) {
  const vec3 w = vec3_normalize(vec3_make(0.3f, -0.5f, 0.8f));
  for (float u : {0.0f, 0.1f, 0.37f, 0.6f}) {
    const vec3 a = sample_direction_around(w, 0.0f, u), b = sample_direction_around(w, 0.0f, u + 0.25f);
    EXPECT_NEAR(vec3_dot(a, b), 0.0f, 2e-6f);
    EXPECT_NEAR(vec3_dot(a, w), 0.0f, 2e-6f);
  }
}

// Exponential free flight: t = −ln(1 − u)/σ inverts the CDF 1 − e^{−σt}; u = 0 gives t = 0 and the
// median u = 1/2 gives ln 2/σ.
TEST(SamplingExponential, InvertsTheCdf) {
  EXPECT_EQ(sample_exponential(0.0f, 3.0f), 0.0f);
  EXPECT_NEAR(sample_exponential(0.5f, 2.0f), std::log(2.0) / 2.0, 1e-7);
  for (float u : {0.01f, 0.3f, 0.9f, 0.99999994f}) {
    const float t = sample_exponential(u, 0.7f);
    ASSERT_TRUE(std::isfinite(t));
    EXPECT_NEAR(1.0 - std::exp(-0.7 * t), u, 1e-6);
  }
}

// Power heuristic (β = 2): w(a, b) = a²/(a² + b²); w(a, b) + w(b, a) = 1; w(3, 1) = 9/10.
TEST(SamplingMis, PowerHeuristic) {
  EXPECT_FLOAT_EQ(mis_power_heuristic(3.0f, 1.0f), 0.9f);
  EXPECT_FLOAT_EQ(mis_power_heuristic(1.0f, 0.0f), 1.0f);
  EXPECT_FLOAT_EQ(mis_power_heuristic(0.2f, 5.0f) + mis_power_heuristic(5.0f, 0.2f), 1.0f);
  EXPECT_EQ(mis_power_heuristic(0.0f, 0.0f), 0.0f);  // drawable by neither: no weight, not 0/0
}

}  // namespace
