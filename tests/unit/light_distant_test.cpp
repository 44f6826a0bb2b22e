// light_distant_test.cpp: the distant light's sampling (kernels/shared/light_distant.h) on the
// host, the very code the kernels run.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "shared/light.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

light_params sun(float diameterDegrees, vec3 travel, vec3 irradiance) {
  light_placement pl{};
  pl.vector = travel;
  pl.parameter = diameterDegrees;
  pl.scene_radius = 2.0f;
  return light_make(LIGHT_DISTANT, irradiance, pl);
}

// ∫_cone f(ω) dω in double: the midpoint rule in (θ, φ) about the axis a, n × 4n cells.
template <typename F>
double coneIntegral(const double a[3], double halfAngle, F f, int n) {
  // An orthonormal frame (t, b, a).
  double t[3] = {0, -a[2], a[1]};
  if (std::fabs(a[0]) > 0.9) t[0] = a[2], t[1] = 0, t[2] = -a[0];
  const double tn = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  for (double& v : t) v /= tn;
  const double b[3] = {a[1] * t[2] - a[2] * t[1], a[2] * t[0] - a[0] * t[2], a[0] * t[1] - a[1] * t[0]};
  double sum = 0;
  const double dth = halfAngle / n, dph = 2 * kPi / (4 * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 4 * n; ++j) {
      const double th = (i + 0.5) * dth, ph = (j + 0.5) * dph;
      double w[3];
      for (int k = 0; k < 3; ++k)
        w[k] = std::sin(th) * (std::cos(ph) * t[k] + std::sin(ph) * b[k]) + std::cos(th) * a[k];
      sum += f(w) * std::sin(th) * dth * dph;
    }
  return sum;
}

// Next-event estimation of a cone light: E[L·f(ω)/pdf] over its samples must be L·∫_cone f dω, for
// f an HG lobe (g 0.8) whose axis lies 5° off the cone's, so f varies across a cone of 20°. Each
// sample lies inside the cone with pdf = light_pdf of its direction. N = 2·10⁵: |z| < 5 (a false
// alarm about 6e-7). The quadrature (400 × 1600 cells) is exact to 1e-6 relative here.
TEST(LightDistant, ConeSamplingIsUnbiased) {
  const vec3 travel = vec3_make(0.2f, -1.0f, 0.1f);
  const light_params l = sun(20.0f, travel, vec3_make(3, 3, 3));
  const vec3 axis = vec3_normalize(vec3_scale(travel, -1.0f));
  const double a[3] = {axis.x, axis.y, axis.z};
  const double off = 5 * kPi / 180;  // f's axis: the cone's, turned by 5° about a perpendicular
  double perp[3] = {0, -a[2], a[1]};
  const double pn = std::sqrt(perp[1] * perp[1] + perp[2] * perp[2]);
  const double c[3] = {std::cos(off) * a[0], std::cos(off) * a[1] + std::sin(off) * perp[1] / pn,
                       std::cos(off) * a[2] + std::sin(off) * perp[2] / pn};
  auto f = [&](const double* w) {
    const double mu = w[0] * c[0] + w[1] * c[1] + w[2] * c[2], g = 0.8, d = 1 + g * g - 2 * g * mu;
    return (1 - g * g) / (4 * kPi * d * std::sqrt(d));
  };
  const double half = 10 * kPi / 180, L = 3 / (kPi * std::sin(half) * std::sin(half));
  const double expected = L * coneIntegral(a, half, f, 400);

  std::mt19937 gen(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    light_sample s;
    ASSERT_TRUE(light_sample_point(&l, vec3_make(1, 2, 3), uni(gen), uni(gen), &s));
    ASSERT_GE(vec3_dot(s.dir, axis), l.edge_u.x - 1e-6f);
    ASSERT_EQ(s.pdf, light_pdf(&l, s.dir, NV_INFINITY));
    ASSERT_TRUE(std::isinf(s.dist));
    const double w[3] = {s.dir.x, s.dir.y, s.dir.z};
    const double v = s.radiance.x * f(w) / s.pdf;
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
  EXPECT_LT(std::fabs(mean - expected) / se, 5.0) << "mean " << mean << ", expected " << expected;
}

// The delta light (diameter 0): its one direction against the travel, the irradiance itself, pdf 0
// (no MIS), nothing for an escaping ray; a cone's radiance is E/(π sin²θc) inside it and 0 outside.
TEST(LightDistant, DeltaAndConeRadiance) {
  const light_params delta = sun(0.0f, vec3_make(0, 0, -2), vec3_make(1, 2, 3));
  light_sample s;
  ASSERT_TRUE(light_sample_point(&delta, vec3_make(0, 0, 0), 0.3f, 0.7f, &s));
  EXPECT_EQ(s.dir.z, 1.0f);
  EXPECT_EQ(s.radiance.y, 2.0f);
  EXPECT_EQ(s.pdf, 0.0f);
  EXPECT_TRUE(vec3_is_zero(light_escaped(&delta, vec3_make(0, 0, 1))));
  const light_params cone = sun(4.0f, vec3_make(0, 0, -1), vec3_make(1, 2, 3));
  const double sinC = std::sin(2 * kPi / 180);
  EXPECT_NEAR(light_escaped(&cone, vec3_make(0, 0, 1)).x, 1 / (kPi * sinC * sinC), 1e-5 / (kPi * sinC * sinC));
  const float off = std::sin(float(2.5 * kPi / 180));
  EXPECT_TRUE(vec3_is_zero(light_escaped(&cone, vec3_normalize(vec3_make(off, 0, std::sqrt(1 - off * off))))));
  // The power through a disc of the scene's radius (2): π r² E, mean over the channels.
  EXPECT_NEAR(light_power(&cone), kPi * 4 * 2, 1e-5);
}

}  // namespace
