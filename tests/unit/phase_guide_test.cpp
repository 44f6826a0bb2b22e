// phase_guide.h: the one-sample mixture of the phase function and HG lobes about the directions to
// the lights, which the multiple-scattering cache's paths may draw their first direction from. Its
// pdf must be the density the samples follow (else the weight p/pdf and the MIS weights are wrong),
// and with no share it must be the phase function's sampling bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "shared/phase_guide.h"
#include "shared/structs.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

// A rectangle light (1 x 2, centre (0, 3, 1), facing −y) and a point light at (−2, −1, −3).
struct TwoLights {
  light_params l[2]{};
  TwoLights() {
    l[0].type = LIGHT_RECTANGLE;
    l[0].corner = {-0.5f, 3.0f, 0.0f, 0.0f};
    l[0].edge_u = {1.0f, 0.0f, 0.0f, 0.0f};
    l[0].edge_v = {0.0f, 0.0f, 2.0f, 0.0f};
    l[0].normal = {0.0f, -1.0f, 0.0f, 2.0f};  // w: the area
    l[0].radiance = {1.0f, 1.0f, 1.0f, 0.0f};
    l[1].type = LIGHT_POINT;
    l[1].corner = {-2.0f, -1.0f, -3.0f, 0.0f};
    l[1].radiance = {1.0f, 1.0f, 1.0f, 0.0f};
  }
};

const vec3 kX = vec3_make(0.2f, 0.1f, 0.3f);  // the scattering event
const float kG = 0.9f;                       // the medium's HG g

vec3 arrival() { return vec3_normalize(vec3_make(0.1f, -0.2f, 1.0f)); }  // the path's w_in

phase_guide guideOf(float share) {
  phase_guide gd = phase_guide_none();
  gd.x = kX;
  gd.share = share;
  gd.g = 0.6f;
  return gd;
}

// share 0: phase_sample's direction and pdf for the same numbers, bit for bit (the path tracer's
// arithmetic), and phase_guide_pdf returns the phase value itself.
TEST(PhaseGuide, NoShareIsThePhaseFunctionBitForBit) {
  const TwoLights lights;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const float u1 = u(rng), u2 = u(rng), u3 = u(rng);
    float f, pdf, expectedPdf;
    const vec3 w = phase_guide_sample(lights.l, 2, phase_make(PHASE_HG, kG), arrival(), guideOf(0.0f), u1, u2, u3, &f, &pdf);
    const vec3 expected = phase_sample(phase_make(PHASE_HG, kG), arrival(), u1, u2, &expectedPdf);
    ASSERT_EQ(w.x, expected.x);
    ASSERT_EQ(w.y, expected.y);
    ASSERT_EQ(w.z, expected.z);
    ASSERT_EQ(pdf, expectedPdf);
    ASSERT_EQ(f, expectedPdf);  // HG samples exactly: its pdf is its value
  }
}

// The mixture's pdf is a density: ∫ pdf dω = 1, by the midpoint rule over (cos θ, φ) about each
// lobe's axis would need three charts; instead over a fine uniform grid in (z, φ) on the sphere
// (dω = dz dφ), 4096 x 2048 cells, whose error for the sharpest lobe (HG 0.9 about w_in, peak
// 9.8/sr, width ~0.1 rad) is far below the 1e-3 asserted.
TEST(PhaseGuide, TheMixtureIntegratesToOne) {
  const TwoLights lights;
  for (float share : {0.25f, 0.6f}) {
    const phase_guide gd = guideOf(share);
    const int nz = 4096, nphi = 2048;
    double sum = 0.0;
    for (int i = 0; i < nz; ++i) {
      const double z = -1.0 + (i + 0.5) * 2.0 / nz, r = std::sqrt(std::max(0.0, 1.0 - z * z));
      for (int j = 0; j < nphi; ++j) {
        const double phi = (j + 0.5) * 2.0 * kPi / nphi;
        const vec3 w = vec3_make(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
        const float f = phase_eval(phase_make(PHASE_HG, kG), arrival(), w);
        sum += phase_guide_pdf(lights.l, 2, gd, f, w);
      }
    }
    EXPECT_NEAR(sum * (2.0 / nz) * (2.0 * kPi / nphi), 1.0, 1e-3) << "share " << share;
  }
}

// The weight p/pdf makes the samples estimate integrals against the phase function, whatever the
// share: for HG, whose Legendre coefficients are gˡ, E_p[P₂(ω·a)] = g²·P₂(w_in·a) for any unit a,
// so E_p[(ω·a)²] = (1 + 2g²·P₂(w_in·a))/3, P₂(c) = (3c² − 1)/2; and E_p[1] = 1. Taken with a the
// axis towards the rectangle's centre (where the guide puts its samples), from 400000 samples:
// within 4.5 standard errors (the samples' own, p < 1e-5 per check). Without the weight, or with a
// wrong pdf, the second moment reads the guide's concentration instead.
TEST(PhaseGuide, WeightedSamplesEstimateThePhaseFunctionsMoments) {
  const TwoLights lights;
  const vec3 a = phase_guide_axis(&lights.l[0], kX);
  const double c = vec3_dot(arrival(), a), p2 = 0.5 * (3.0 * c * c - 1.0);
  const double exact = (1.0 + 2.0 * double(kG) * kG * p2) / 3.0;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float share : {0.25f, 0.6f}) {
    const int n = 400000;
    double s1 = 0, s1sq = 0, s2 = 0, s2sq = 0, unweighted = 0;
    for (int i = 0; i < n; ++i) {
      float f, pdf;
      const vec3 w = phase_guide_sample(lights.l, 2, phase_make(PHASE_HG, kG), arrival(), guideOf(share), u(rng), u(rng), u(rng),
                                        &f, &pdf);
      ASSERT_GT(pdf, 0.0f);
      ASSERT_EQ(f, phase_eval(phase_make(PHASE_HG, kG), arrival(), w));
      const double weight = double(f) / pdf, m = double(vec3_dot(w, a)) * vec3_dot(w, a);
      s1 += weight;
      s1sq += weight * weight;
      s2 += weight * m;
      s2sq += weight * m * weight * m;
      unweighted += m;
    }
    const double mean1 = s1 / n, se1 = std::sqrt((s1sq / n - mean1 * mean1) / n);
    const double mean2 = s2 / n, se2 = std::sqrt((s2sq / n - mean2 * mean2) / n);
    EXPECT_NEAR(mean1, 1.0, 4.5 * se1) << "share " << share;
    EXPECT_NEAR(mean2, exact, 4.5 * se2) << "share " << share << " (exact " << exact << ")";
    EXPECT_GT(std::fabs(unweighted / n - exact), 20 * se2) << "share " << share;  // the weight matters
  }
}

// The guide sends samples towards the lights: the share of directions within 30° of the
// rectangle's axis grows from the phase function's (w_in points 88° away from it, so HG 0.9 sends
// under 1% there) by what the guide's lobe about that axis adds: it draws half of the guide's
// samples (two lights), and HG 0.6 puts 39.2% of its mass within 30° (∫ from cos 30° to 1 of
// (1 − g²)/(2(1 + g² − 2gμ)^{3/2}) dμ), so share·½·0.392 = 0.049 at share 0.25 (the point light's
// lobe, 150° away, adds nothing there); 100000 samples give it to ±0.002.
TEST(PhaseGuide, TheGuideAimsAtTheLights) {
  const TwoLights lights;
  const vec3 a = phase_guide_axis(&lights.l[0], kX);
  ASSERT_LT(vec3_dot(arrival(), a), 0.4f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto coneShare = [&](float share) {
    int in = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      float f, pdf;
      const vec3 w = phase_guide_sample(lights.l, 2, phase_make(PHASE_HG, kG), arrival(), guideOf(share), u(rng), u(rng), u(rng),
                                        &f, &pdf);
      in += vec3_dot(w, a) > std::cos(kPi / 6);
    }
    return double(in) / n;
  };
  const double phaseOnly = coneShare(0.0f), guided = coneShare(0.25f);
  EXPECT_LT(phaseOnly, 0.01);
  EXPECT_NEAR(guided - phaseOnly, 0.049, 0.008);
}

}  // namespace
