// phase_test.cpp: the phase functions of kernels/shared/phase.h on the host (the very code the
// device compiles). Henyey–Greenstein, DESIGN.md convention: μ = cos θ between the propagation
// directions before and after scattering,
//   p(μ) = (1 − g²) / (4π (1 + g² − 2gμ)^{3/2}),
// so ∫ p dω = 2π ∫_{-1}^{1} p(μ) dμ = 1 and the mean cosine 2π ∫ μ p(μ) dμ = g.
// Sampling is checked Mitsuba-style: a χ² goodness-of-fit test of sampled directions against the
// pdf integrated over each histogram cell, with a known-failing control to show the test bites.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "shared/phase.h"
#include "shared/structs.h"
#include "unit/stat_util.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

// χ² helpers (gammaQ, chiSquarePValue, sidak, chiSquare with pooling): tests/unit/stat_util.h.
using namespace narval::test;

// ---- helpers (double precision) ----

// Adaptive Simpson on [a, b] to absolute tolerance `tol`.
double adaptiveSimpsonRec(const std::function<double(double)>& f, double a, double b, double fa, double fm,
                          double fb, double whole, double tol, int depth) {
  const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(lm), frm = f(rm);
  const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  if (depth <= 0 || std::fabs(left + right - whole) <= 15.0 * tol)
    return left + right + (left + right - whole) / 15.0;
  return adaptiveSimpsonRec(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
         adaptiveSimpsonRec(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}
double adaptiveSimpson(const std::function<double(double)>& f, double a, double b, double tol) {
  const double fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
  return adaptiveSimpsonRec(f, a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), tol, 40);
}

// ∫_{-1}^{1} f(μ) dμ for a function peaked at μ = ±1 (HG with |g| → 1 has width ~(1−|g|)²):
// 5-point Gauss–Legendre on panels graded geometrically towards both ends, [1 − 2^-k, 1 − 2^-(k+1)]
// for k = 0..59 (and mirrored). Each panel spans a factor 2 in the distance to the end, over which
// (a + b(1 − μ))^{-3/2} varies by at most 2^{3/2}: the 5-point rule is then exact to ~1e-9.
double integrateGraded(const std::function<double(double)>& f) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                              0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                              0.4786286704993665, 0.2369268850561891};
  auto gl = [&](double a, double b) {
    double s = 0.0;
    for (int i = 0; i < 5; ++i) s += w[i] * f(0.5 * (a + b) + 0.5 * (b - a) * x[i]);
    return 0.5 * (b - a) * s;
  };
  double sum = 0.0;
  for (int k = 0; k < 60; ++k) {
    const double near = std::ldexp(1.0, -(k + 1)), far = std::ldexp(1.0, -k);
    sum += gl(1.0 - far, 1.0 - near);    // towards μ = +1
    sum += gl(-1.0 + near, -1.0 + far);  // towards μ = −1
  }
  // The two end panels of width 2^-60 are below float resolution: the integrand is its end value.
  sum += std::ldexp(1.0, -60) * (f(1.0) + f(-1.0));
  return sum;
}

double hgReference(double g, double mu) {
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

vec3 normalized(double x, double y, double z) {
  const double n = std::sqrt(x * x + y * y + z * z);
  return vec3_make(static_cast<float>(x / n), static_cast<float>(y / n), static_cast<float>(z / n));
}

// Histogram of N directions drawn by phase_sample(sampled, w_in) in (cos θ, φ) cells about w_in (μ
// edges at edge(i/20), increasing from −1 to 1), tested against pdfMu (per steradian, a function of
// μ) integrated over each cell. φ is measured in a frame built here (not vec3_basis), so the test
// does not share the sampler's frame.
ChiSquareResult phaseChiSquareOf(phase_params sampled, const std::function<double(double)>& pdfMu,
                                 const std::function<double(double)>& edge, int n, uint32_t seed) {
  const int kMu = 20, kPhi = 40;
  const vec3 win = normalized(0.3, -0.5, 0.8);
  const double wx = win.x, wy = win.y, wz = win.z;
  // t = normalize(w × x̂) (w is far from x̂), b = w × t.
  double tx = 0.0, ty = wz, tz = -wy;
  const double tn = std::sqrt(ty * ty + tz * tz);
  ty /= tn;
  tz /= tn;
  const double bx = wy * tz - wz * ty, by = wz * tx - wx * tz, bz = wx * ty - wy * tx;

  std::vector<double> observed(kMu * kPhi, 0.0), expected(kMu * kPhi, 0.0);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (int i = 0; i < n; ++i) {
    float pdf = 0.0f;
    const vec3 v = phase_sample(sampled, win, uni(gen), uni(gen), &pdf);
    const double mu = std::clamp(v.x * wx + v.y * wy + v.z * wz, -1.0, 1.0);
    double phi = std::atan2(v.x * bx + v.y * by + v.z * bz, v.x * tx + v.y * ty + v.z * tz);
    if (phi < 0.0) phi += 2.0 * kPi;
    int im = 0;
    while (im < kMu - 1 && mu >= edge(double(im + 1) / kMu)) ++im;
    const int ip = std::min(kPhi - 1, static_cast<int>(phi / (2.0 * kPi) * kPhi));
    observed[im * kPhi + ip] += 1.0;
  }
  // Expected count of cell (μ-bin, φ-bin) = N · Δφ · ∫_bin p(μ) dμ (the pdf is per steradian and
  // dω = dμ dφ). The integral is of the device's own eval, to 1e-9 of the bin mass.
  const double dphi = 2.0 * kPi / kPhi;
  for (int im = 0; im < kMu; ++im) {
    const double a = edge(double(im) / kMu), b = edge(double(im + 1) / kMu);
    const double mass = adaptiveSimpson(pdfMu, a, b, 1e-10);
    for (int ip = 0; ip < kPhi; ++ip) expected[im * kPhi + ip] = n * dphi * mass;
  }
  return chiSquare(observed, expected);
}

// HG: samples of gSample against the pdf of gPdf, in cells even in μ.
ChiSquareResult phaseChiSquare(float gSample, float gPdf, int n, uint32_t seed) {
  return phaseChiSquareOf(
      phase_make(PHASE_HG, gSample), [&](double mu) { return double(phase_hg_eval(gPdf, float(mu))); },
      [](double t) { return -1.0 + 2.0 * t; }, n, seed);
}

// ---- tests ----

// The χ² helper itself, against tabulated quantiles: P(χ²₁ > 3.841459) = 0.05,
// P(χ²₁₀ > 18.307038) = 0.05, P(χ²₁₀₀ > 149.449252) = 0.001 (Abramowitz & Stegun Table 26.8 /
// any χ² table). Guards against a helper that always accepts.
TEST(PhaseStatHelpers, ChiSquareTailMatchesTables) {
  EXPECT_NEAR(chiSquarePValue(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(chiSquarePValue(18.307038, 10), 0.05, 1e-6);
  EXPECT_NEAR(chiSquarePValue(149.449252, 100), 0.001, 1e-6);
  // Q(a, 0) = 1 and Q(k/2, x) decreases in x.
  EXPECT_DOUBLE_EQ(chiSquarePValue(0.0, 7), 1.0);
  EXPECT_GT(chiSquarePValue(5.0, 7), chiSquarePValue(6.0, 7));
}

// Pooling: expected counts {1, 2, 3, 10, 10, 10} pool the three small cells (1 + 2 = 3 < 5, + 3 = 6)
// into one, leaving 4 cells and dof = 3. Observed {3, 0, 3, 10, 10, 10} matches the pooled
// expectation exactly (χ² = 0); {0, 0, 0, 10, 10, 16} gives (0 − 6)²/6 + (16 − 10)²/10 = 9.6.
// A sample in a zero-probability cell is counted, never pooled away.
TEST(PhaseStatHelpers, PoolsSmallCells) {
  const std::vector<double> expected = {1, 2, 3, 10, 10, 10};
  ChiSquareResult r = chiSquare({3, 0, 3, 10, 10, 10}, expected);
  EXPECT_EQ(r.dof, 3);
  EXPECT_DOUBLE_EQ(r.chi2, 0.0);
  r = chiSquare({0, 0, 0, 10, 10, 16}, expected);
  EXPECT_EQ(r.dof, 3);
  EXPECT_DOUBLE_EQ(r.chi2, 9.6);
  r = chiSquare({1, 2, 3, 10, 10, 10, 4}, {1, 2, 3, 10, 10, 10, 0});
  EXPECT_EQ(r.samplesInZeroCells, 4);
}

// Normalisation: 2π ∫ p dμ = 1. The quadrature error is ~1e-9 and float evaluation adds ~1e-7
// relative, so 1e-3 leaves the test sensitive to any wrong constant or exponent (the dissertation's
// printed form, without the 3/2 exponent, integrates to (1 − g²)/(2g)·ln((1+g)/(1−g)) ≠ 1, e.g.
// 0.053 for g = 0.99 and 0.82 for g = 0.5).
TEST(PhaseHG, IntegratesToOne) {
  for (float g : {-0.99f, -0.5f, 0.0f, 0.5f, 0.99f}) {
    const double integral =
        2.0 * kPi * integrateGraded([&](double mu) { return phase_hg_eval(g, static_cast<float>(mu)); });
    EXPECT_NEAR(integral, 1.0, 1e-3) << "g = " << g;
  }
}

// The first moment of HG is g: 2π ∫ μ p(μ) dμ = g. This pins the sign convention (g > 0 forward).
TEST(PhaseHG, MeanCosineIsG) {
  for (float g : {-0.99f, -0.5f, 0.0f, 0.5f, 0.99f}) {
    const double mean = 2.0 * kPi * integrateGraded([&](double mu) {
                          return mu * phase_hg_eval(g, static_cast<float>(mu));
                        });
    EXPECT_NEAR(mean, g, 1e-3) << "g = " << g;
  }
}

// Point values against the closed form evaluated in double. The cancellation-free denominator
// leaves only float rounding: a few ulp, far inside 1e-5 relative. Also checks forward peaking:
// p(+1) = (1+g)/(4π(1−g)²) > p(−1) = (1−g)/(4π(1+g)²) for g > 0.
TEST(PhaseHG, MatchesClosedForm) {
  for (float g : {-0.999f, -0.9f, -0.3f, 0.001f, 0.3f, 0.9f, 0.999f}) {
    for (float mu : {-1.0f, -0.7f, -0.1f, 0.0f, 0.25f, 0.8f, 0.99f, 1.0f}) {
      const double ref = hgReference(g, mu);
      EXPECT_NEAR(phase_hg_eval(g, mu), ref, 1e-5 * ref) << "g = " << g << ", mu = " << mu;
    }
  }
  EXPECT_GT(phase_hg_eval(0.5f, 1.0f), phase_hg_eval(0.5f, -1.0f));
  EXPECT_NEAR(phase_hg_eval(0.5f, 1.0f), 1.5 / (4.0 * kPi * 0.25), 1e-6);
}

// Isotropic: 1/(4π) = 0.0795774715..., i.e. exactly the float nearest to it (NV_INV_4PI), everywhere,
// both as PHASE_ISOTROPIC and as HG with g = 0; its sampler reports the same pdf.
TEST(PhaseIsotropic, EvalIsOneOverFourPi) {
  const float inv4pi = static_cast<float>(1.0 / (4.0 * kPi));
  const vec3 a = normalized(1, 2, 3), b = normalized(-3, 0.5, 1);
  EXPECT_EQ(phase_eval(phase_make(PHASE_ISOTROPIC, 0.7f), a, b), inv4pi);
  EXPECT_EQ(phase_pdf(phase_make(PHASE_ISOTROPIC, -0.7f), a, a), inv4pi);
  for (float mu : {-1.0f, -0.3f, 0.0f, 0.6f, 1.0f}) EXPECT_EQ(phase_hg_eval(0.0f, mu), inv4pi);
  float pdf = -1.0f;
  const vec3 v = phase_sample(phase_make(PHASE_ISOTROPIC, 0.9f), a, 0.3f, 0.6f, &pdf);
  EXPECT_EQ(pdf, inv4pi);
  EXPECT_NEAR(vec3_length(v), 1.0f, 1e-6f);
}

// Inverse-CDF sampling: u = 0 → μ = −1, u → 1 → μ = +1, and μ(u) increasing (derived from
// s = (1−g²)/(1−g+2gu): s(0) = 1+g gives μ = (1+g²−(1+g)²)/(2g) = −1; s(1) = 1−g gives +1).
// The sampled μ's CDF must equal u: F(μ) = (1−g²)/(2g)·(1/√(1+g²−2gμ) − 1/(1+g)), evaluated in
// double (tolerance derived in the loop).
TEST(PhaseHG, SampleCosInvertsTheCdf) {
  for (float g : {-0.9f, -0.3f, 0.3f, 0.9f}) {
    EXPECT_NEAR(phase_hg_sample_cos(g, 0.0f), -1.0f, 1e-5f) << g;
    EXPECT_NEAR(phase_hg_sample_cos(g, 0.99999994f), 1.0f, 1e-5f) << g;
    float prev = -2.0f;
    for (int i = 0; i < 1000; ++i) {
      const float u = (i + 0.5f) / 1000.0f;
      const float mu = phase_hg_sample_cos(g, u);
      EXPECT_GE(mu, prev) << "g = " << g << ", u = " << u;
      prev = mu;
      const double d = 1.0 + double(g) * g - 2.0 * g * mu;
      const double cdf = (1.0 - double(g) * g) / (2.0 * g) * (1.0 / std::sqrt(d) - 1.0 / (1.0 + g));
      // dF/dμ = 2π p(μ) ≤ 2π p_max = (1+|g|)/(2(1−|g|)²) = 95 for |g| = 0.9; μ carries ~1e-7 of
      // rounding, so |F(μ) − u| ≤ 95 · 2e-7 ≈ 2e-5 at worst.
      EXPECT_NEAR(cdf, u, 3e-5) << "g = " << g << ", u = " << u;
    }
  }
}

// χ² goodness of fit of phase_sample(PHASE_HG) in 20 (cos θ) × 40 (φ) cells about a non-axis w_in,
// 10⁶ samples per g. Total significance 1e-3, Šidák-corrected over the 5 g values (each test at
// 2.0e-4): a correct sampler fails this with probability 1e-3 (seeds are fixed, so in practice never
// or always).
TEST(PhaseHG, SamplingPassesChiSquare) {
  const std::vector<float> gs = {-0.9f, -0.3f, 0.0f, 0.3f, 0.9f};
  const double alpha = sidak(1e-3, static_cast<int>(gs.size()));
  uint32_t seed = 1234;
  for (float g : gs) {
    const ChiSquareResult r = phaseChiSquare(g, g, 1000000, seed++);
    EXPECT_EQ(r.samplesInZeroCells, 0) << "g = " << g;
    EXPECT_GT(r.dof, 700) << "g = " << g;  // most of the 800 cells keep an expected count >= 5
    EXPECT_GE(r.pValue, alpha) << "g = " << g << ": chi2 = " << r.chi2 << ", dof = " << r.dof;
    RecordProperty("p_value_g" + std::to_string(g), std::to_string(r.pValue));
  }
}

// Control: the same test must reject a sampler that is slightly off. Samples of g = 0.3 against the
// pdf of g = 0.33 differ in cell mass by several percent near μ = ±1, i.e. a χ² excess of thousands
// over ~800 dof with 10⁶ samples: the p-value is essentially 0.
TEST(PhaseHG, ChiSquareRejectsAWrongG) {
  const ChiSquareResult r = phaseChiSquare(0.3f, 0.33f, 1000000, 99);
  EXPECT_LT(r.pValue, 1e-9) << "chi2 = " << r.chi2 << ", dof = " << r.dof;
}

// Sampled directions are unit length, and the pdf phase_sample returns equals phase_eval and
// phase_pdf of the returned direction. The returned pdf is p(μ) of the sampled μ while eval
// recomputes μ' = dot(w_in, w_out) with ~2e-7 rounding; |d ln p/dμ| = 3|g|/(1+g²−2gμ) ≤
// 3·0.9/0.01 = 270 for |g| = 0.9, so the relative mismatch stays below 270·2e-7 ≈ 6e-5 < 1e-4
// (measured: 3.2e-5). Not tested beyond |g| = 0.9 because the bound grows as 1/(1−|g|)²: measured
// 7e-3 at g = 0.99 and 0.7 at g = 0.999, where the peak (width ~(1−g)²/2 = 5e-7 in μ) is only a
// few float ulps of μ wide. Delta-tracking throughput is unaffected (eval/pdf is taken as 1); the
// MIS weights, which use the sampled pdf on one side and phase_eval on the other, are then slightly
// inconsistent for very forward media.
TEST(PhaseHG, SamplePdfMatchesEval) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const vec3 axes[3] = {normalized(0.3, -0.5, 0.8), normalized(0, 0, -1), normalized(-1, 1e-3, 0)};
  double worst = 0.0;
  for (float g : {-0.9f, -0.3f, 0.0f, 0.3f, 0.9f}) {
    for (const vec3& win : axes) {
      for (int i = 0; i < 20000; ++i) {
        float pdf = -1.0f;
        const vec3 v = phase_sample(phase_make(PHASE_HG, g), win, uni(gen), uni(gen), &pdf);
        ASSERT_NEAR(vec3_length(v), 1.0f, 2e-6f);
        const float eval = phase_eval(phase_make(PHASE_HG, g), win, v);
        const float pp = phase_pdf(phase_make(PHASE_HG, g), win, v);
        ASSERT_GT(pdf, 0.0f);
        const double rel = std::fabs(double(pdf) - eval) / eval;
        worst = std::max(worst, rel);
        ASSERT_LE(rel, 1e-4) << "g = " << g << ", pdf = " << pdf << ", eval = " << eval;
        ASSERT_EQ(pp, eval);
      }
    }
  }
  RecordProperty("max_relative_pdf_eval_mismatch", std::to_string(worst));
}

// Extreme asymmetry: g = ±0.999999 (peak p(±1) = (1+|g|)/(4π(1−|g|)²) ≈ 1.6e11, still finite in
// float) and |g| = 1e-7 (below PHASE_HG_ISOTROPIC_EPS: treated as isotropic, no division by g) give
// finite cosines in [−1, 1], finite unit directions and finite positive pdfs over the whole u range,
// u = 0 and the largest u below 1 included.
TEST(PhaseHG, ExtremeGStaysFinite) {
  const vec3 win = normalized(0.3, -0.5, 0.8);
  std::vector<float> us = {0.0f, 1e-7f, 1e-3f, 0.25f, 0.5f, 0.75f, 0.999f, 0.99999994f};
  for (int i = 0; i < 1000; ++i) us.push_back((i + 0.5f) / 1000.0f);
  for (float g : {0.999999f, -0.999999f, 1e-7f, -1e-7f}) {
    for (float u : us) {
      const float mu = phase_hg_sample_cos(g, u);
      ASSERT_TRUE(std::isfinite(mu)) << "g = " << g << ", u = " << u;
      ASSERT_GE(mu, -1.0f);
      ASSERT_LE(mu, 1.0f);
      float pdf = -1.0f;
      const vec3 v = phase_sample(phase_make(PHASE_HG, g), win, u, 0.37f, &pdf);
      ASSERT_TRUE(vec3_is_finite(v)) << "g = " << g << ", u = " << u;
      ASSERT_NEAR(vec3_length(v), 1.0f, 2e-6f);
      ASSERT_TRUE(std::isfinite(pdf)) << "g = " << g << ", u = " << u;
      ASSERT_GT(pdf, 0.0f) << "g = " << g << ", u = " << u;
      ASSERT_TRUE(std::isfinite(phase_eval(phase_make(PHASE_HG, g), win, v)));
    }
  }
  // For g = 0.999999 the median sample is essentially straight ahead: μ(0.5) = 1 − O(1e-12).
  EXPECT_GT(phase_hg_sample_cos(0.999999f, 0.5f), 0.9999f);
  EXPECT_LT(phase_hg_sample_cos(-0.999999f, 0.5f), -0.9999f);
}

// ---- Mie (phase_mie.h) ----

// Diameters across the fit's three ranges (0.1 ≤ d < 1.5, 1.5 ≤ d < 5, 5 ≤ d ≤ 50), their ends included.
const float kDiameters[] = {0.1f, 0.4f, 1.0f, 1.5f, 3.0f, 4.99f, 5.0f, 10.0f, 20.0f, 50.0f};

double mieEval(phase_params p, double mu) { return double(phase_eval_mu(p, float(mu))); }

// The fitted constants stay where the blend is a phase function: |g_HG|, |g_D| < 1, α ≥ 0 and the
// weight w_D in [0, 1]. A transcription slip in one of the paper's fits would show where two ranges
// meet: the constants themselves jump there (α is 250 below 1.5 µm and 9.3 above: the fits are
// separate curves), but the function they describe barely moves. Across d = 1.5 and d = 5 (±0.1%)
// the mean cosine changes by under 0.005 and p(μ) by under 10% away from the forward peak
// (μ ≤ 0.99; measured: 0.0021 and 7.5%, at μ = 0.9 across 1.5 µm).
TEST(PhaseMie, FittedConstantsAreValidAndContinuousAcrossRanges) {
  for (float d : kDiameters) {
    const phase_params p = phase_make(PHASE_MIE, d);
    EXPECT_EQ(p.kind, PHASE_MIE);
    EXPECT_GT(p.coef.x, 0.0f) << d;
    EXPECT_LT(p.coef.x, 1.0f) << d;
    EXPECT_GT(p.coef.y, -1.0f) << d;
    EXPECT_LT(p.coef.y, 1.0f) << d;
    EXPECT_GE(p.coef.z, 0.0f) << d;
    EXPECT_GE(p.coef.w, 0.0f) << d;
    EXPECT_LE(p.coef.w, 1.0f) << d;
  }
  for (float edge : {1.5f, 5.0f}) {
    const phase_params a = phase_make(PHASE_MIE, edge * 0.999f), b = phase_make(PHASE_MIE, edge * 1.001f);
    EXPECT_NEAR(phase_mean_cosine(a), phase_mean_cosine(b), 0.005f) << edge;
    for (float mu : {-1.0f, -0.5f, 0.0f, 0.5f, 0.9f, 0.99f})
      EXPECT_NEAR(phase_eval_mu(a, mu), phase_eval_mu(b, mu), 0.1f * phase_eval_mu(b, mu)) << edge << " " << mu;
  }
  // Larger droplets scatter more forward: the mean cosine grows from 1 to 50 µm.
  EXPECT_LT(phase_mean_cosine(phase_make(PHASE_MIE, 1.0f)), phase_mean_cosine(phase_make(PHASE_MIE, 20.0f)));
}

// Normalised over the sphere (2π∫p dμ = 1, both lobes are) and the mean cosine phase_mean_cosine
// reports (Draine's g(1 + α(3 + 2g²)/5)/N, blended) equals 2π∫μ p dμ, by quadrature graded towards
// the forward peak (width ~(1 − g_HG)², 4e-6 at 50 µm).
TEST(PhaseMie, IntegratesToOneWithItsMeanCosine) {
  for (float d : kDiameters) {
    const phase_params p = phase_make(PHASE_MIE, d);
    const double integral = 2.0 * kPi * integrateGraded([&](double mu) { return mieEval(p, mu); });
    const double mean = 2.0 * kPi * integrateGraded([&](double mu) { return mu * mieEval(p, mu); });
    EXPECT_NEAR(integral, 1.0, 1e-3) << "d = " << d;
    EXPECT_NEAR(mean, phase_mean_cosine(p), 1e-3) << "d = " << d;
  }
}

// The cap integral (phase_polygon.h's closed form per edge): phase_cap_over_sin2·(1 − μ²) equals
// ∫_μ^1 p dμ' by quadrature, for caps from a sliver around the peak to almost the whole sphere.
// Float rounding of the cancellation-free form keeps it within 1e-4 relative (plus 1e-9 absolute).
TEST(PhaseMie, CapIntegralMatchesQuadrature) {
  for (float d : {0.4f, 3.0f, 20.0f, 50.0f}) {
    const phase_params p = phase_make(PHASE_MIE, d);
    for (float muf : {-0.999f, -0.5f, 0.0f, 0.5f, 0.9f, 0.99f, 0.9999f}) {
      const double mu = muf;  // the float the kernel sees, not the decimal
      const double ref = adaptiveSimpson([&](double m) { return mieEval(p, m); }, mu, 1.0, 1e-9);
      const double got = double(phase_cap_over_sin2(p, muf)) * (1.0 - mu * mu);
      EXPECT_NEAR(got, ref, 1e-4 * ref + 1e-9) << "d = " << d << ", mu = " << mu;
    }
  }
}

// Draine's sampler inverts S_D(μ) = 2π∫_μ^1 p_D: the returned μ has S_D(μ) = 1 − u, checked against
// the quadrature of the eval (not the closed form the sampler iterates on) for α = 250 (the small
// droplets') and α = 27 (20 µm), g_D of either sign. |dS/dμ| = 2π p_D; μ's float rounding (6e-8)
// times its largest value here (about 5) leaves 1e-6: the bound 2e-5 leaves room for the quadrature.
TEST(PhaseMie, DraineSamplerInvertsItsCdf) {
  for (float g : {-0.3f, 0.2f, 0.6f}) {
    for (float alpha : {27.0f, 250.0f}) {
      for (int i = 0; i < 24; ++i) {
        const float u = (i + 0.5f) / 24.0f;
        const float mu = phase_mie_draine_sample(g, alpha, u);
        ASSERT_GE(mu, -1.0f);
        ASSERT_LE(mu, 1.0f);
        const double above = 2.0 * kPi *
                             adaptiveSimpson([&](double m) { return double(phase_mie_draine_eval(g, alpha, float(m))); },
                                             mu, 1.0, 1e-9);
        EXPECT_NEAR(above, 1.0 - u, 2e-5) << "g = " << g << ", alpha = " << alpha << ", u = " << u;
      }
    }
  }
}

// χ² goodness of fit of phase_sample(Mie) as for HG, in cells even in ν with μ = 1 − 2ν⁴ (graded
// towards the forward peak, the first cell 1.3e-5 wide in μ), 10⁶ samples per diameter, one per
// range and a large one; total significance 1e-3, Šidák-corrected over the 4 diameters.
TEST(PhaseMie, SamplingPassesChiSquare) {
  const auto edge = [](double t) { return 1.0 - 2.0 * std::pow(1.0 - t, 4.0); };
  const std::vector<float> ds = {0.5f, 2.0f, 10.0f, 30.0f};
  const double alpha = sidak(1e-3, static_cast<int>(ds.size()));
  uint32_t seed = 4321;
  for (float d : ds) {
    const phase_params p = phase_make(PHASE_MIE, d);
    const ChiSquareResult r = phaseChiSquareOf(p, [&](double mu) { return mieEval(p, mu); }, edge, 1000000, seed++);
    EXPECT_EQ(r.samplesInZeroCells, 0) << "d = " << d;
    EXPECT_GT(r.dof, 700) << "d = " << d;
    EXPECT_GE(r.pValue, alpha) << "d = " << d << ": chi2 = " << r.chi2 << ", dof = " << r.dof;
  }
}

// Control: samples of 10 µm droplets against the pdf of 12 µm ones must fail the same test.
TEST(PhaseMie, ChiSquareRejectsAnotherDiameter) {
  const auto edge = [](double t) { return 1.0 - 2.0 * std::pow(1.0 - t, 4.0); };
  const phase_params wrong = phase_make(PHASE_MIE, 12.0f);
  const ChiSquareResult r = phaseChiSquareOf(phase_make(PHASE_MIE, 10.0f), [&](double mu) { return mieEval(wrong, mu); },
                                             edge, 1000000, 77);
  EXPECT_LT(r.pValue, 1e-9) << "chi2 = " << r.chi2 << ", dof = " << r.dof;
}

// With w_D = 0 the blend is HG bit for bit (its eval adds 0·p_D, its sampler passes u through
// unchanged). No diameter in the fit's range gives w_D = 0, so this is set on the constants.
TEST(PhaseMie, WithoutDraineItIsHgBitForBit) {
  for (float g : {-0.4f, 0.3f, 0.95f}) {
    phase_params mie = phase_make(PHASE_MIE, 10.0f);
    mie.coef.x = g;
    mie.coef.w = 0.0f;
    const phase_params hg = phase_make(PHASE_HG, g);
    for (int i = 0; i < 257; ++i) {
      const float t = i / 256.0f, mu = -1.0f + 2.0f * t;
      ASSERT_EQ(phase_eval_mu(mie, mu), phase_eval_mu(hg, mu)) << g << " " << mu;
      ASSERT_EQ(phase_sample_mu(mie, std::min(t, 0.99999994f)), phase_sample_mu(hg, std::min(t, 0.99999994f)));
    }
  }
}

}  // namespace
