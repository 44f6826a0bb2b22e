// The path tracer's sampling choices (renderer.pathtrace: one light per event, Russian roulette on
// shadow rays and on paths) leave its expectation unchanged: on a scene with one very bright and
// one dim light, each converges to the image that next-event estimation towards every light gives.
//
// The test, per quadrant of the image and per channel: each configuration is rendered twice with
// independent seeds, x₁ and x₂, and its image is their mean x̄ = (x₁ + x₂)/2, whose noise variance
// per pixel is estimated without bias by (x₁ − x₂)²/4, pooled over the quadrant's n = 96 pixels (v).
// z = mean over the quadrant of (x̄_test − x̄_base) / √((v_test + v_base)/n) is standard normal for
// an unbiased pair (both means over 96 independent pixels); |z| < 4 over the 4 × 3 = 12 tests is a
// false alarm of 12 · 6.3e-5 = 8e-4. The noise comes from the replicates, not from the spread of
// the difference over the quadrant, which a real bias that varies across pixels would inflate.
// The quadrants keep a bias local to one light from hiding in the image's mean: the bright
// rectangle lights the left half, the dim point light the right. The control, the dim light 25%
// brighter (a change of its contribution only), must fail the same test: the test resolves a bias
// of that size in the dim light's light. Measured on PoCL: the choices' max |z| 2.0–2.8 at 4096 spp
// and still at most 2.5 at 16384 (no bias growing with the samples), the control 8.6 and 12.5.
// The noise of one-light selection is heavy-tailed (a pixel gets the dim light's 30x weight a few
// times), which is why the renders take 4096 spp: at 1024 the choices reached 3.3, the control 5.1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

constexpr int kWidth = 24, kHeight = 16;

// The generated cloud (makeCloud(32, 7), density ×3) in a chromatic box 4×3×3 (σt up to (3.3,
// 4.2, 5.1) per unit, g 0.5: ratio tracking walks it, and shadow rays from deep inside cross
// enough mean free paths for their transmittance to fall below the roulette's 0.05; a homogeneous
// medium would not do, its transmittance is Beer–Lambert's closed form with no walk to end), the
// rectangle (radiance 60, 2×2) beside it at x = +6, facing it and out of the camera's view, which
// shows +x on the image's left, the point light (intensity `dim`) in front of the box at −x, so on
// the image's right:
// the rectangle's power is 60·π·4 ≈ 754, the point light's 4π·dim ≈ 25 at dim = 2, so power
// selection aims at it one event in 30.
std::string sceneJson(const std::string& pathtrace, int seed, double dim = 2.0) {
  const std::string d = std::to_string(dim);
  return R"({
    "materials": [
      {"name": "bright", "type": "emitter", "albedo": [60, 60, 60]},
      {"name": "dim", "type": "emitter", "albedo": [)" + d + ", " + d + ", " + d + R"(]},
      {"name": "fog", "type": "volume", "scattering": [1.0, 1.3, 1.6], "absorption": [0.1, 0.1, 0.1],
       "phaseFunction": "hg", "g": 0.5, "density": 3}],
    "primitives": [
      {"type": "rectangle", "materialName": "bright",
       "transform": {"position": [6, 0, 0], "scale": [2, 2, 1], "rotation": [0, 90, 0]}},
      {"type": "point", "materialName": "dim", "transform": {"position": [-1.0, 0.0, -1.8]}},
      {"type": "volume", "materialName": "fog", "transform": {"scale": [4, 3, 3]}}],
    "camera": {"position": [0, 0, -6], "lookAt": [0, 0, 0], "vfov": 45},
    "renderer": {"resolution": [24, 16], "spp": 4096, "bounces": 4, "seed": )" +
         std::to_string(seed) + R"(, "pathtrace": )" + pathtrace + R"(},
    "background": [0, 0, 0]})";
}

ImageRGB renderScene(const std::string& json) {
  static const DenseGrid cloud = makeCloud(32, 7);
  const RenderResult r = render(sceneFromJson(json), &cloud);
  EXPECT_EQ(r.stats.status, 0u);
  return r.image;
}

// Two renders of one configuration with independent seeds (2·k + 1, 2·k + 2).
struct Replicates {
  ImageRGB a, b;
};
Replicates renderTwice(const std::string& pathtrace, int k, double dim = 2.0) {
  return {renderScene(sceneJson(pathtrace, 2 * k + 1, dim)), renderScene(sceneJson(pathtrace, 2 * k + 2, dim))};
}

// The largest |z| of test − base over the four quadrants and three channels (above).
double worstQuadrantZ(const Replicates& test, const Replicates& base) {
  double worst = 0;
  for (int q = 0; q < 4; ++q)
    for (int c = 0; c < 3; ++c) {
      double diff = 0, varTest = 0, varBase = 0;
      int n = 0;
      for (int y = (q / 2) * kHeight / 2; y < (q / 2 + 1) * kHeight / 2; ++y)
        for (int x = (q % 2) * kWidth / 2; x < (q % 2 + 1) * kWidth / 2; ++x) {
          const double t1 = test.a.pixel(x, y)[c], t2 = test.b.pixel(x, y)[c];
          const double b1 = base.a.pixel(x, y)[c], b2 = base.b.pixel(x, y)[c];
          diff += (t1 + t2) / 2 - (b1 + b2) / 2;
          varTest += (t1 - t2) * (t1 - t2) / 4;
          varBase += (b1 - b2) * (b1 - b2) / 4;
          ++n;
        }
      const double se = std::sqrt((varTest / n + varBase / n) / n);
      worst = std::max(worst, std::fabs(diff / n) / se);
    }
  return worst;
}

TEST(PathtraceSampling, EveryChoiceConvergesToTheAllLightsImage) {
  // The base: every light, no roulette (each choice below names both keys, the defaults aside).
  const char* const plain = R"({"lightSampling": "all", "shadowRoulette": 0})";
  const Replicates base = renderTwice(plain, 0);
  // The same seed without the roulette: the roulette must have played (the images differ).
  EXPECT_NE(renderScene(sceneJson(R"({"lightSampling": "all", "shadowRoulette": 0.05})", 3)).rgb,
            renderScene(sceneJson(plain, 3)).rgb);
  for (const char* choice :
       {R"({"lightSampling": "power", "shadowRoulette": 0})", R"({"lightSampling": "fluence", "shadowRoulette": 0})",
        R"({"lightSampling": "all", "shadowRoulette": 0.05})", R"({"lightSampling": "fluence", "shadowRoulette": 0.05})"}) {
    const double z = worstQuadrantZ(renderTwice(choice, 1), base);
    std::printf("[ sampling  ] %s: max |z| %.2f\n", choice, z);
    EXPECT_LT(z, 4.0) << choice;
  }
  // Control: the dim light 25% brighter, every light sampled, no roulette.
  const double control = worstQuadrantZ(renderTwice(plain, 1, 2.5), base);
  std::printf("[ sampling  ] control (the dim light x1.25): max |z| %.2f\n", control);
  EXPECT_GT(control, 4.0);
}

}  // namespace
}  // namespace narval::test
