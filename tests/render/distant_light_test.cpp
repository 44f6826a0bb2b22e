// distant_light_test.cpp: the distant light (kernels/shared/light_distant.h) rendered, against
// answers derived here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "render/scene_upload.h"
#include "render_fixture.h"
#include "test_support.h"

namespace narval::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A thin homogeneous slab, z in [-0.25, 0.25] and 40 units wide, lit by a sun of irradiance E (grey)
// travelling along kSun, seen from above with a narrow camera; background black.
const double kSun[3] = {0.3, 0.2, -0.9};
constexpr double kE = 2.0, kSigmaS = 1.2, kSigmaA = 0.3, kG = 0.5, kZTop = 0.25, kZBottom = -0.25;

std::string slabJson(double angularDiameter, const std::string& renderer) {
  return R"({
    "materials": [
      {"name": "sun", "type": "emitter", "albedo": [2, 2, 2]},
      {"name": "fog", "type": "volume", "scattering": [1.2, 1.2, 1.2], "absorption": [0.3, 0.3, 0.3],
       "phaseFunction": "hg", "g": 0.5}
    ],
    "primitives": [
      {"type": "distant", "direction": [0.3, 0.2, -0.9], "angularDiameter": )" +
         std::to_string(angularDiameter) + R"(, "materialName": "sun"},
      {"type": "volume", "transform": {"scale": [40, 40, 0.5]}, "materialName": "fog"}
    ],
    "camera": {"position": [0, -3, 4], "lookAt": [0, 0, 0], "up": [0, 0, 1], "vfov": 6},
    "renderer": )" + renderer + R"(
  })";
}

// Single scattering of the slab along the pixel-centre ray (o, v), v pointing down: with u the
// length travelled inside the slab, the camera's transmittance is e^{−σt·u} and the sun's, from the
// point at depth |v_z|·u under the top face, e^{−σt·|v_z|·u/|ω_z|}, so
//   L = σs·p(μ)·E·∫_0^U e^{−σt·k·u} du = σs·p(μ)·E·(1 − e^{−σt·k·U})/(σt·k),
// k = 1 + |v_z|/|ω_z|, U = (z_top − z_bottom)/|v_z|, μ = ω·(−v) (the sun's travel against the
// direction towards the camera; HG, g > 0 forward). The slab's sides are 20 units away: every
// path here stays more than 19 units inside them.
double slabSingleScattering(const Ray& r) {
  const double n = std::sqrt(kSun[0] * kSun[0] + kSun[1] * kSun[1] + kSun[2] * kSun[2]);
  const double w[3] = {kSun[0] / n, kSun[1] / n, kSun[2] / n};
  const double st = kSigmaS + kSigmaA, vz = std::fabs(r.d[2]);
  const double k = 1 + vz / std::fabs(w[2]), U = (kZTop - kZBottom) / vz;
  const double mu = -(w[0] * r.d[0] + w[1] * r.d[1] + w[2] * r.d[2]);
  const double d = 1 + kG * kG - 2 * kG * mu;
  const double p = (1 - kG * kG) / (4 * kPi * d * std::sqrt(d));
  return kSigmaS * p * kE * (1 - std::exp(-st * k * U)) / (st * k);
}

// The path tracer with one bounce (single scattering: next-event estimation at the first event),
// per 4×4 tile against the closed form: z = (tile mean − expected)/(σ̂/4), σ̂ the spread of the 16
// pixels' residuals; |z| < 5 for each of the 16 tiles (a false alarm about 1 in 10⁵ per run, the
// residuals being near-normal at 512 spp). With a cone of 0.53° (the sun) and 2° the same bound
// holds: the cone averages p·T over directions within 1° of the axis, which moves L by under 1e-3
// relative here, far inside the tiles' noise (about 1%); so the cone converges to the delta light.
TEST(DistantLight, PathTracedSlabMatchesSingleScatteringPerTile) {
  for (double diameter : {0.0, 0.53, 2.0}) {
    SCOPED_TRACE("angularDiameter " + std::to_string(diameter));
    const Scene scene = sceneFromJson(slabJson(diameter, R"({"resolution": [16, 16], "spp": 512, "bounces": 1})"));
    const RenderResult r = render(scene);
    ASSERT_EQ(r.stats.status, 0u);
    const camera_params c = buildDeviceScene(scene, nullptr).params.camera;
    for (int ty = 0; ty < 4; ++ty)
      for (int tx = 0; tx < 4; ++tx) {
        double residual[16], mean = 0;
        int n = 0;
        for (int y = ty * 4; y < ty * 4 + 4; ++y)
          for (int x = tx * 4; x < tx * 4 + 4; ++x) {
            residual[n] = r.image.pixel(x, y)[0] - slabSingleScattering(pixelRay(c, x + 0.5, y + 0.5));
            mean += residual[n++] / 16;
          }
        double var = 0;
        for (double e : residual) var += (e - mean) * (e - mean) / 15;
        const double z = mean / (std::sqrt(var) / 4);
        EXPECT_LT(std::fabs(z), 5.0) << "tile " << tx << "," << ty << ": mean residual " << mean;
      }
  }
}

// The ray marcher sees the sun as its one direction with irradiance E: its single scattering is the
// same closed form, per pixel, to the quadrature's error: 256 midpoint steps over an optical depth
// under 1.3 leave the source's exponential e^{−σt(k−1)u} integrated to O((σt(k−1)Δ)²/24) ≈ 1e-6
// relative, and the shadow rays cross constant density (exact); 1e-4 holds with float rounding.
// With the light-transmittance cache (the column linear in height, interpolated exactly) as well.
TEST(DistantLight, RayMarchedSlabMatchesSingleScatteringPerPixel) {
  for (const char* cache : {"0", "\"auto\""}) {
    SCOPED_TRACE(std::string("lightCache.resolution ") + cache);
    const Scene scene = sceneFromJson(slabJson(
        0.0, std::string(R"({"resolution": [16, 16], "algorithm": "raymarch", "raymarch": {"multipleScattering": "none", "steps": 256}, "lightCache": {"resolution": )") +
                 cache + "}}"));
    const RenderResult r = renderAlgorithm(scene);
    ASSERT_EQ(r.stats.status, 0u);
    const camera_params c = buildDeviceScene(scene, nullptr).params.camera;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const double expected = slabSingleScattering(pixelRay(c, x + 0.5, y + 0.5));
        EXPECT_NEAR(r.image.pixel(x, y)[0], expected, 1e-4 * expected) << x << "," << y;
      }
  }
}

// Looking straight at a cone of 2° through nothing: the centre pixel (1° wide, its rays within
// 0.71° of the axis whatever the path tracer's jitter) lies inside the cone and sees the background
// plus the cone's radiance E/(π sin²θc) as light_distant_make stored it, in float exactly (the
// real-time kernels' background is that one sum; the path tracer's single sample as well, to its
// accumulator's rounding); a corner pixel, at least 2.1° off the axis, sees the background alone.
// Every algorithm.
TEST(DistantLight, TheSunSeenThroughNothingIsItsRadiance) {
  const std::string json = R"({
    "materials": [{"name": "sun", "type": "emitter", "albedo": [1, 2, 3]}],
    "primitives": [{"type": "distant", "direction": [0, 0, -1], "angularDiameter": 2, "materialName": "sun"}],
    "camera": {"position": [0, 0, 0], "lookAt": [0, 0, 1], "up": [0, 1, 0], "vfov": 5},
    "renderer": {"resolution": [5, 5], "spp": 1},
    "background": [0.25, 0.25, 0.25]
  })";
  const Scene scene = sceneFromJson(json);
  const light_params l = buildDeviceScene(scene, nullptr).lights.at(0);
  const double sinC = std::sin(1.0 * kPi / 180);
  EXPECT_NEAR(l.edge_u.z, 1 / (kPi * sinC * sinC), 1e-5 / (kPi * sinC * sinC));
  for (const char* algorithm : {"pathtrace", "raymarch", "lobe"}) {
    SCOPED_TRACE(algorithm);
    const RenderResult r = renderWith(scene, algorithm);
    ASSERT_EQ(r.stats.status, 0u);
    const float albedo[3] = {1, 2, 3};
    // The path tracer's fixed-point accumulator rounds a sample to 2^-24 of its scale: 1e-6 relative.
    const float tol = std::string(algorithm) == "pathtrace" ? 1e-6f : 0.0f;
    for (int ch = 0; ch < 3; ++ch) {
      const float sun = 0.25f + albedo[ch] * l.edge_u.z;
      EXPECT_NEAR(r.image.pixel(2, 2)[ch], sun, tol * sun) << "channel " << ch;
      EXPECT_NEAR(r.image.pixel(0, 0)[ch], 0.25f, tol) << "channel " << ch;
    }
  }
}

// A white furnace lit by two distant lights: cones of 180° (hemispheres) about +z and −z, each of
// radiance 1 (E = π: L = E/(π sin²90°)), background black: a uniform environment of radiance 1. An
// albedo-1 medium then gives 1 everywhere in expectation, through the cones' sampling, their MIS
// against phase sampling and the escaping rays that see them. The image mean within 4 standard
// errors and 1%, and each 4x4 tile within 5 (a false alarm about 1 in 10⁵ per run).
TEST(DistantLight, WhiteFurnaceOfTwoHemispheresIsOne) {
  const Scene scene = sceneFromJson(R"({
    "materials": [
      {"name": "sky", "type": "emitter", "albedo": [3.14159265, 3.14159265, 3.14159265]},
      {"name": "white", "type": "volume", "scattering": [1, 1, 1], "absorption": [0, 0, 0], "phaseFunction": "hg",
       "g": 0.6, "density": 3}
    ],
    "primitives": [
      {"type": "distant", "direction": [0, 0, -1], "angularDiameter": 180, "materialName": "sky"},
      {"type": "distant", "direction": [0, 0, 1], "angularDiameter": 180, "materialName": "sky"},
      {"type": "volume", "transform": {"scale": [2, 1.5, 1], "rotation": [20, 30, 0]}, "materialName": "white"}
    ],
    "camera": {"position": [0, 0, -4], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 40},
    "renderer": {"resolution": [16, 16], "spp": 256, "bounces": 1000}
  })");
  const RenderResult r = render(scene);
  ASSERT_EQ(r.stats.status, 0u);
  const ChannelStats s = channelStats(r.image, 0);
  EXPECT_NEAR(s.mean, 1.0, std::max(4 * s.stderrOfMean, 1e-6));
  EXPECT_NEAR(s.mean, 1.0, 0.01);
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 4; ++tx) {
      double v[16], mean = 0;
      int n = 0;
      for (int y = ty * 4; y < ty * 4 + 4; ++y)
        for (int x = tx * 4; x < tx * 4 + 4; ++x) mean += (v[n++] = r.image.pixel(x, y)[0]) / 16;
      double var = 0;
      for (double e : v) var += (e - mean) * (e - mean) / 15;
      if (var == 0) {
        EXPECT_NEAR(mean, 1.0, 1e-5) << "tile " << tx << "," << ty;  // nothing but the sky: exactly its radiance
        continue;
      }
      EXPECT_LT(std::fabs(mean - 1.0) / (std::sqrt(var) / 4), 5.0) << "tile " << tx << "," << ty;
    }
}

}  // namespace
}  // namespace narval::test
