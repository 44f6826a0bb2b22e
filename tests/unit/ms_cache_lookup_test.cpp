// The multiple-scattering cache's lookup on the host (kernels/shared/ms_cache.h, the code the ray
// marcher runs): its geometric interpolation of R and linear interpolation of b/R, on node values
// written as the build writes them (ms_cache_build.h: the running means, then ln R and b/R).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include "shared/ms_cache.h"

namespace narval::test {
namespace {

// A 3x3x3 node grid over the index box [0, 2]³ (node spacing 1).
node_grid_params grid3() {
  node_grid_params c{};
  c.nx = c.ny = c.nz = 3;
  return c;
}

// Node values as the build leaves them: R per channel from r(node point), b = R·ratio.
std::vector<float> cacheOf(const node_grid_params& c, const std::function<float(vec3)>& r, vec3 ratio) {
  std::vector<float> v(size_t(node_grid_count(&c)) * MS_CACHE_STRIDE, 0.0f);
  const vec3 dims = vec3_make(2, 2, 2);
  for (int n = 0; n < node_grid_count(&c); ++n) {
    float* q = &v[size_t(n) * MS_CACHE_STRIDE];
    const float R = r(node_grid_point(&c, dims, n));
    for (int ch = 0; ch < 3; ++ch) {
      q[ch] = R;
      q[4 + 4 * ch] = R * ratio.x;
      q[5 + 4 * ch] = R * ratio.y;
      q[6 + 4 * ch] = R * ratio.z;
      q[MS_CACHE_LOG_R + ch] = R > 0 ? std::log(R) : -NV_INFINITY;
      q[MS_CACHE_RATIO + 3 * ch + 0] = R > 0 ? ratio.x : 0;
      q[MS_CACHE_RATIO + 3 * ch + 1] = R > 0 ? ratio.y : 0;
      q[MS_CACHE_RATIO + 3 * ch + 2] = R > 0 ? ratio.z : 0;
    }
    q[3] = 1;
  }
  return v;
}

// A field falling exponentially into the medium, R = 5·e^{−3x}·e^{−0.5y} (three mean free paths per
// cell along x, as at a dense cloud's lit face): the geometric mean is exact for it at every point,
// to float rounding (within 1e-5 relative: a few roundings of ln and exp), where the linear mix is
// off by a factor (1 + e^{−3})/(2e^{−1.5}) = 2.35 at a cell's middle.
TEST(MsCacheLookup, GeometricInterpolationIsExactForAnExponentialField) {
  const node_grid_params c = grid3();
  auto field = [](vec3 p) { return 5.0f * std::exp(-3.0f * p.x) * std::exp(-0.5f * p.y); };
  const std::vector<float> cache = cacheOf(c, field, vec3_make(0, 0, 0));
  const vec3 dims = vec3_make(2, 2, 2);
  for (float x : {0.1f, 0.5f, 1.3f, 1.9f})
    for (float y : {0.25f, 1.5f})
      for (float z : {0.0f, 0.7f}) {
        const vec3 p = vec3_make(x, y, z);
        const vec3 L = ms_cache_lookup(&c, cache.data(), dims, p, 0.0f, MS_CACHE_CLOSURE_LINEAR, vec3_make(0, 0, 1));
        EXPECT_NEAR(L.x, field(p), 1e-5 * field(p)) << x << "," << y << "," << z;
        EXPECT_EQ(L.x, L.y);
        EXPECT_EQ(L.x, L.z);
      }
  // The linear mix of the same nodes (node_grid_interpolate of R) at the middle of the first cell
  // along x: 2.35 times the field there.
  const vec3 mid = vec3_make(0.5f, 0.0f, 0.0f);
  const float linear = node_grid_interpolate(&c, cache.data(), MS_CACHE_STRIDE, node_grid_locate(&c, dims, mid));
  EXPECT_NEAR(linear / field(mid), 2.35, 0.01);
  EXPECT_NEAR(ms_cache_lookup(&c, cache.data(), dims, mid, 0.0f, MS_CACHE_CLOSURE_LINEAR, vec3_make(0, 0, 1))
                  .x,
              field(mid), 1e-5 * field(mid));
}

// The first moment: with b = R·m at every node, the in-scattering towards w_out is R·(1 + g·m·w_out)
// (clamped at 0); a node at R = 0 takes the running means' path and pulls its cell down
// continuously: at weight w → 0 the value tends to the other corners'.
TEST(MsCacheLookup, FirstMomentAndAZeroNode) {
  const node_grid_params c = grid3();
  const vec3 m = vec3_make(0.2f, -0.1f, 0.3f), w_out = vec3_make(0.6f, 0.0f, 0.8f);
  const std::vector<float> uniform = cacheOf(c, [](vec3) { return 2.0f; }, m);
  const vec3 dims = vec3_make(2, 2, 2);
  const vec3 L =
      ms_cache_lookup(&c, uniform.data(), dims, vec3_make(0.4f, 1.2f, 0.9f), 0.8f, MS_CACHE_CLOSURE_LINEAR, w_out);
  const float expected = 2.0f * (1.0f + 0.8f * (0.2f * 0.6f + 0.3f * 0.8f));
  EXPECT_NEAR(L.x, expected, 1e-6f * expected);
  // Against the mean: clamped at 0.
  const vec3 back = ms_cache_lookup(&c,
                                    cacheOf(
                                        c, [](vec3) { return 2.0f; }, vec3_make(0, 0, -2))
                                        .data(),
                                    dims, vec3_make(0.4f, 1.2f, 0.9f), 0.9f, MS_CACHE_CLOSURE_LINEAR, vec3_make(0, 0, 1));
  EXPECT_EQ(back.x, 0.0f);

  // Node (0, 0, 0) at 0, every other at 1: approaching the far corner of that cell the value tends to 1.
  const std::vector<float> hole = cacheOf(c, [](vec3 p) { return p.x + p.y + p.z == 0 ? 0.0f : 1.0f; }, m);
  double previous = -1;
  for (float s : {0.5f, 0.9f, 0.99f, 1.0f}) {
    const float v = ms_cache_lookup(&c, hole.data(), dims, vec3_make(s, s, s), 0.0f, MS_CACHE_CLOSURE_LINEAR, w_out)
                        .x;
    EXPECT_GE(v, previous);
    EXPECT_GE(v, 0.0f);
    previous = v;
  }
  EXPECT_NEAR(previous, 1.0, 1e-6);
  EXPECT_NEAR(ms_cache_lookup(&c, hole.data(), dims, vec3_make(0, 0, 0), 0.0f, MS_CACHE_CLOSURE_LINEAR, w_out)
                  .x,
              0.0f, 1e-9f);
}

// A field that is an HG lobe, L(w) = 4πR·p_HG(μ, w·b̂), has the moments R and b = 3Rμ·b̂; its exact
// in-scattering ∫ p_HG(g, w·w_out) L(w) dw is summed on the host (double, convolvedHgField).
double hgPhase(double g, double mu) { return (1 - g * g) / (4 * M_PI * std::pow(1 + g * g - 2 * g * mu, 1.5)); }

// ∫ p_HG(g, w·w_out)·4π·p_HG(μ, w·b̂) dw with b̂ = z and w_out in the xz plane: u = cos θ about b̂
// by adaptive Simpson (tolerance 1e-9), φ by the trapezoid rule on 4096 points (periodic and
// smooth: spectrally accurate).
double convolvedHgField(double g, double mu, double cosOut) {
  const double sinOut = std::sqrt(std::max(0.0, 1 - cosOut * cosOut));
  auto ring = [&](double u) {
    const double st = std::sqrt(std::max(0.0, 1 - u * u));
    const int NP = 4096;
    double sum = 0;
    for (int j = 0; j < NP; ++j) sum += hgPhase(g, st * std::cos(2 * M_PI * j / NP) * sinOut + u * cosOut);
    return 4 * M_PI * hgPhase(mu, u) * sum * (2 * M_PI / NP);
  };
  std::function<double(double, double, double, double, double, double, int)> simpson =
      [&](double a, double b, double fa, double fm, double fb, double whole, int depth) {
        const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
        const double flm = ring(lm), frm = ring(rm);
        const double left = (m - a) / 6 * (fa + 4 * flm + fm), right = (b - m) / 6 * (fm + 4 * frm + fb);
        if (depth <= 0 || std::fabs(left + right - whole) <= 15e-9) return left + right + (left + right - whole) / 15;
        return simpson(a, m, fa, flm, fm, left, depth - 1) + simpson(m, b, fm, frm, fb, right, depth - 1);
      };
  const double fa = ring(-1), fm = ring(0), fb = ring(1);
  return simpson(-1, 1, fa, fm, fb, 2.0 / 6 * (fa + 4 * fm + fb), 40);
}

// The linear closure against the exact in-scattering of an HG field (the quadrature above): right to first
// order in the field's anisotropy μ (|b|/3R 0.01: within 1e-3), clamped at 0 where a strongly one-sided
// field's expansion would go negative (μ 0.6 seen backwards; the exact value is positive there).
TEST(MsCacheLookup, LinearClosureIsFirstOrderInTheFieldsAnisotropyAndClamped) {
  const node_grid_params c = grid3();
  const vec3 dims = vec3_make(2, 2, 2), p = vec3_make(0.7f, 1.1f, 0.3f);
  // The linear closure's value and the exact one, for g, the field's μ and the cosine of w_out with b̂.
  auto closures = [&](double g, double mu, double cosOut) {
    const std::vector<float> cache = cacheOf(c, [](vec3) { return 2.0f; }, vec3_make(0, 0, float(3 * mu)));  // b/R
    const vec3 w_out = vec3_make(float(std::sqrt(1 - cosOut * cosOut)), 0, float(cosOut));
    return std::make_pair(ms_cache_lookup(&c, cache.data(), dims, p, float(g), MS_CACHE_CLOSURE_LINEAR, w_out).x,
                          2.0 * convolvedHgField(g, mu, cosOut));
  };
  for (double g : {0.8, 0.9}) {
    for (double cosOut : {1.0, 0.5, 0.0, -0.7, -1.0}) {
      const auto [linear, exact] = closures(g, 0.01, cosOut);
      EXPECT_NEAR(linear, exact, 1e-3 * exact) << "first order, g " << g << " cos " << cosOut;
    }
    const auto [linear, exact] = closures(g, 0.6, -1.0);
    EXPECT_EQ(linear, 0.0f) << "the linear closure clamps backwards, g " << g;
    EXPECT_GT(exact, 0.0);
  }
}

}  // namespace
}  // namespace narval::test
