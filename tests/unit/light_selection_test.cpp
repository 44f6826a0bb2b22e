// The one-light next-event estimator's choice (kernels/shared/light_select.h) and the weights the
// host gives it (host/render/light_selection.h): exact values derived in each test.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "render/light_selection.h"
#include "render/scene_upload.h"
#include "scene/scene.h"
#include "shared/light_select.h"

namespace narval {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A homogeneous unit box at the origin, a rectangle of `rectScale`² facing it from z = +4 and a
// point light at (0, 4, 0).
std::string scene(const std::string& sampling, float rectRadiance = 2, float pointIntensity = 3, float rectScale = 2) {
  return R"({"materials": [
      {"name": "rect", "type": "emitter", "albedo": [)" + std::to_string(rectRadiance) + R"(, )" +
         std::to_string(rectRadiance) + R"(, )" + std::to_string(rectRadiance) + R"(]},
      {"name": "bulb", "type": "emitter", "albedo": [)" + std::to_string(pointIntensity * 0.5f) + R"(, )" +
         std::to_string(pointIntensity) + R"(, )" + std::to_string(pointIntensity * 1.5f) + R"(]},
      {"name": "fog", "type": "volume", "scattering": [1, 1, 1], "absorption": [0, 0, 0]}],
    "primitives": [
      {"type": "rectangle", "materialName": "rect",
       "transform": {"position": [0, 0, 4], "scale": [)" + std::to_string(rectScale) + ", " + std::to_string(rectScale) +
         R"(, 1]}},
      {"type": "point", "materialName": "bulb", "transform": {"position": [0, 4, 0]}},
      {"type": "volume", "materialName": "fog"}],
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
    "renderer": {"resolution": [4, 4], "pathtrace": {"lightSampling": ")" + sampling + R"("}}})";
}

DeviceScene build(const std::string& json) { return buildDeviceScene(parseScene(json, "lights.json"), SceneGrids{}); }

TEST(LightSelection, PowerIsPiAreaRadianceAndFourPiIntensity) {
  const DeviceScene ds = build(scene("power"));
  const std::vector<double> w = lightSelectionWeights(ds, LightSampling::Power);
  ASSERT_EQ(w.size(), 2u);
  // Rectangle: Φ = π·A·Le = π·(2·2)·2 (one-sided Lambertian emitter). Point: Φ = 4π·I, I the mean of
  // (1.5, 3, 4.5) = 3. Each kind's header computes it in float (light_power): a few roundings of
  // 2^-24, within 1e-6 relative.
  EXPECT_NEAR(w[0], kPi * 4 * 2, 1e-6 * kPi * 4 * 2);
  EXPECT_NEAR(w[1], 4 * kPi * 3, 1e-6 * 4 * kPi * 3);
  EXPECT_EQ(ds.params.light_sampling, LIGHT_SAMPLING_ONE);
  const double p0 = 8.0 / (8.0 + 12.0);
  EXPECT_FLOAT_EQ(ds.lights[0].select_prob, float(p0));
  EXPECT_FLOAT_EQ(ds.lights[1].select_prob, float(1 - p0));
}

TEST(LightSelection, FluenceFollowsTheInverseSquareLawAndKeepsAUniformShare) {
  // The medium's points (an 8³ lattice of the unit box) see the point light at (0, 4, 0) from
  // distances 3.5–4.5 and the rectangle at z = 4 likewise: the weights are the lattice sums of
  // I/d² and of Σ cos θ_l·ΔA·Le/d² over 4×4 patches, recomputed here in double.
  const DeviceScene ds = build(scene("fluence"));
  const std::vector<double> w = lightSelectionWeights(ds, LightSampling::Fluence);
  double point = 0, rect = 0;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const double x = (i + 0.5) / 8 - 0.5, y = (j + 0.5) / 8 - 0.5, z = (k + 0.5) / 8 - 0.5;
        point += 3.0 / (x * x + (y - 4) * (y - 4) + z * z);
        for (int b = 0; b < 4; ++b)
          for (int a = 0; a < 4; ++a) {
            const double lx = -1 + (a + 0.5) / 2, ly = -1 + (b + 0.5) / 2;  // the 2×2 rectangle's patches
            const double dx = x - lx, dy = y - ly, dz = z - 4, d2 = dx * dx + dy * dy + dz * dz;
            rect += 2.0 * (-dz / std::sqrt(d2)) * (4.0 / 16) / d2;  // emits along −z: cos θ_l = −dz/d
          }
      }
  EXPECT_NEAR(w[0] / rect, 1.0, 1e-5);
  EXPECT_NEAR(w[1] / point, 1.0, 1e-5);
  const double p0 = 0.9 * rect / (rect + point) + 0.05;
  EXPECT_NEAR(ds.lights[0].select_prob, p0, 1e-6);
  EXPECT_NEAR(ds.lights[1].select_prob, 1 - p0, 1e-6);
}

TEST(LightSelection, AllGivesEveryLightItsOwnShadowRay) {
  const DeviceScene ds = build(scene("all"));
  EXPECT_EQ(ds.params.light_sampling, LIGHT_SAMPLING_ALL);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(light_select_prob(&ds.params, ds.lights.data(), i), 1.0f);
}

TEST(LightSelection, TheKernelPicksEachLightWithItsProbability) {
  // light_select maps u in [0, 1) through the cdf it sums: [0, P0) → 0, [P0, 1) → 1, and a light of
  // probability 0 is never picked (u at the cdf's end falls back to the last light that can be).
  DeviceScene ds = build(scene("power"));
  const float p0 = ds.lights[0].select_prob;
  EXPECT_EQ(light_select(ds.lights.data(), 2, 0.0f), 0);
  EXPECT_EQ(light_select(ds.lights.data(), 2, std::nextafter(p0, 0.0f)), 0);
  EXPECT_EQ(light_select(ds.lights.data(), 2, p0), 1);
  EXPECT_EQ(light_select(ds.lights.data(), 2, std::nextafter(1.0f, 0.0f)), 1);
  EXPECT_EQ(light_select(ds.lights.data(), 2, 1.0f), 1);
  ds.lights[1].select_prob = 0.0f;
  EXPECT_EQ(light_select(ds.lights.data(), 2, 0.99f), 0);
  ds.lights[0].select_prob = 0.0f;
  EXPECT_EQ(light_select(ds.lights.data(), 2, 0.5f), -1);
}

TEST(LightSelection, ADarkSceneFallsBackToUniform) {
  // No light has power: the weights are all 0 and each light gets 1/N (never a division by 0).
  const DeviceScene ds = build(scene("power", 0, 0));
  EXPECT_FLOAT_EQ(ds.lights[0].select_prob, 0.5f);
  EXPECT_FLOAT_EQ(ds.lights[1].select_prob, 0.5f);
}

}  // namespace
}  // namespace narval
