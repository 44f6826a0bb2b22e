// Emissive media in all three algorithms (kernels/shared/emission.h; pbrt-v4's model: the medium
// emits σa(x)·Le(x) per unit length), against what the radiative transfer equation gives:
//   dL/ds = −σt L + σa Le + σs ∫ p L_in,
// on scenes where it has a closed form, and the shipped EmberGen fire rendered clean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "render/scene_grids.h"
#include "render_fixture.h"
#include "render/kernel_features.h"
#include "render/scene_upload.h"
#include "test_support.h"

namespace narval::test {
namespace {

// A homogeneous box of depth d (100 × 100 × d, centred at the origin) seen head-on from z = −5 with
// a 2° field of view, no light, a black background; `material` is the volume's JSON fields.
std::string slabScene(const std::string& material, double depth, int bounces = 3) {
  return R"({
    "materials": [{"name": "m", "type": "volume", )" + material + R"(}],
    "primitives": [{"type": "volume", "materialName": "m", "transform": {"scale": [100, 100, )" +
         std::to_string(depth) + R"(]}}],
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0], "vfov": 2},
    "renderer": {"resolution": [16, 16], "spp": 64, "bounces": )" + std::to_string(bounces) + R"(, "seed": 3}
  })";
}

// Pixel (x, y) of channel c.
float pixel(const RenderResult& r, int x, int y, int c) {
  return r.image.rgb[size_t(3 * (y * r.image.width + x) + c)];
}

// The path tracer's image against `expected(x, y, c)` per 4×4 tile: the tile mean of 16 pixels
// (each a mean of the scene's spp samples) against the mean expectation, in units of the tile
// mean's standard error estimated from the 16 pixels' spread. |z| < 5 for all 16 tiles × 3
// channels: a false alarm has probability about 48 · 6e-7 (normal tails; with the spread itself
// estimated from 16 values the tails are heavier, t with 15 degrees of freedom: about 48 · 2e-4).
template <typename Expected>
void expectTilesWithinNoise(const RenderResult& r, Expected expected, const std::string& what) {
  ASSERT_EQ(r.stats.status, 0u) << what;
  for (int ty = 0; ty < r.image.height; ty += 4)
    for (int tx = 0; tx < r.image.width; tx += 4)
      for (int c = 0; c < 3; ++c) {
        double sum = 0, sum2 = 0, want = 0;
        for (int y = ty; y < ty + 4; ++y)
          for (int x = tx; x < tx + 4; ++x) {
            const double v = pixel(r, x, y, c);
            sum += v;
            sum2 += v * v;
            want += expected(x, y, c);
          }
        const double mean = sum / 16, var = std::max(0.0, (sum2 - 16 * mean * mean) / 15);
        const double se = std::sqrt(var / 16) + 1e-12;
        EXPECT_LT(std::fabs(mean - want / 16) / se, 5.0)
            << what << " tile " << tx << "," << ty << " channel " << c << ": " << mean << " against " << want / 16
            << " (standard error " << se << ")";
      }
}

// The pixel centre's ray: its cosine to the slab's normal (+z), for the path length d / cos θ.
double pixelCosine(const camera_params& cam, int x, int y) {
  const Ray ray = pixelRay(cam, x + 0.5, y + 0.5);
  return ray.d[2] / std::sqrt(ray.d[0] * ray.d[0] + ray.d[1] * ray.d[1] + ray.d[2] * ray.d[2]);
}

// Absorbing, emitting slab (σs = 0): along a ray through it, dL/ds = −σa L + σa Le, L(0) = 0, so
// L = Le·(1 − e^{−σa·ℓ}) with ℓ = d / cos θ the ray's length inside. Grey σa takes the path
// tracer's analogue walk, chromatic σa spectral tracking; the real-time kernels' energy-conserving
// step is exact for constant σa and Le, so they must give it to float rounding.
TEST(EmissionRender, AbsorbingSlabGivesLeTimesOneMinusTransmittance) {
  struct Case {
    const char* absorption;
    double sa[3];
    double depth;
  };
  const Case cases[] = {{"[2, 2, 2]", {2, 2, 2}, 1.0}, {"[1, 2, 4]", {1, 2, 4}, 0.5}};
  const double Le[3] = {1.0 * 3, 0.5 * 3, 0.25 * 3};  // colour [1, 0.5, 0.25], scale 3
  for (const Case& k : cases) {
    const std::string material = std::string(R"("scattering": [0, 0, 0], "absorption": )") + k.absorption +
                                 R"(, "emission": {"color": [1, 0.5, 0.25], "scale": 3})";
    Scene scene = sceneFromJson(slabScene(material, k.depth));
    const camera_params cam = buildCamera(scene);
    auto expected = [&](int x, int y, int c) {
      const double ell = k.depth / pixelCosine(cam, x, y);
      return Le[c] * (1 - std::exp(-k.sa[c] * ell));
    };
    for (const char* renderer : {"raymarch", "lobe+eq7", "lobe+corrected"}) {
      const RenderResult r = renderWith(scene, renderer);
      ASSERT_EQ(r.stats.status, 0u) << renderer;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(pixel(r, x, y, c), expected(x, y, c), 2e-5 * expected(x, y, c))
                << renderer << " " << k.absorption << " pixel " << x << "," << y << " channel " << c;
    }
    expectTilesWithinNoise(renderWith(scene, "pathtrace"), expected, std::string("pathtrace ") + k.absorption);
  }
}

// The same slab at the numeric extremes, σa = 1e6 and 1e-6 over depth 1 (the hard cases): the
// real-time kernels' step weight (1 − e^{−x})/x, taken from its series below x = 0.1, keeps
// Le·(1 − e^{−σa·ℓ}) to 1e-5 of it at both ends (≈ Le, and ≈ Le·1e-6·ℓ). The path tracer, in the
// dense slab: every path's first tentative collision is real with probability σa/σ̄ = 1/(1 + 1e-5)
// and adds Le·σa/σ̄; with probability 1e-5 it is null and the next one adds as much again, so a
// pixel of 64 samples is Le·(64 + n)/(64·(1 + 1e-5)), n the null collisions among them (mostly 0,
// n ≥ 2 in a pixel with probability 2e-7): within 2/64 of Le per pixel, and the image mean within
// 1e-4 of Le. In the thin slab, where 16384 samples make about 0.02 collisions: finite pixels and a
// clean status only.
TEST(EmissionRender, ExtremeAbsorptionKeepsTheSlabsValue) {
  for (double sa : {1e6, 1e-6}) {
    const std::string material = R"("scattering": [0, 0, 0], "absorption": [)" + std::to_string(sa) + ", " +
                                 std::to_string(sa) + ", " + std::to_string(sa) +
                                 R"(], "emission": {"color": [1, 0.5, 0.25], "scale": 3})";
    Scene scene = sceneFromJson(slabScene(material, 1.0));
    const camera_params cam = buildCamera(scene);
    auto expected = [&](int x, int y, int c) {
      const double Le[3] = {3, 1.5, 0.75};
      return -Le[c] * std::expm1(-sa / pixelCosine(cam, x, y));
    };
    for (const char* renderer : {"raymarch", "lobe+eq7", "lobe+corrected", "pathtrace"}) {
      const RenderResult r = renderWith(scene, renderer);
      ASSERT_EQ(r.stats.status, 0u) << renderer << " σa " << sa;
      const bool pathtrace = std::string(renderer) == "pathtrace";
      double sum[3] = {0, 0, 0}, want[3] = {0, 0, 0};
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          for (int c = 0; c < 3; ++c) {
            const float v = pixel(r, x, y, c);
            ASSERT_TRUE(std::isfinite(v)) << renderer;
            sum[c] += v;
            want[c] += expected(x, y, c);
            if (!pathtrace)
              EXPECT_NEAR(v, expected(x, y, c), 1e-5 * expected(x, y, c)) << renderer << " σa " << sa;
            else if (sa > 1)
              EXPECT_NEAR(v, expected(x, y, c), 2.0 / 64 * expected(x, y, c)) << "pathtrace " << x << "," << y;
          }
      if (pathtrace && sa > 1)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], want[c], 1e-4 * want[c]) << "channel " << c;
    }
  }
}

// A large homogeneous medium that absorbs, scatters and emits (albedo a = σs/σt = 1/2), the camera
// at its centre, 500 mean free paths from every face (e^{−1000}: no boundary). Every path segment
// collects the emission up to its first real collision, ∫ T σa Le = (σa/σt)·Le = (1 − a)·Le, and
// scatters there with probability a, so with at most K scattering events the path tracer gives
//   L = (1 − a)·Le·Σ_{k=0..K} a^k = Le·(1 − a^{K+1})
// (3 bounces: 15/16 of Le; 40: Le to float precision). The ray marcher's own march holds the
// camera ray's emission, (1 − a)·Le; its multiple-scattering cache adds σs·L_in with L_in the
// emission arriving at the cache's nodes, (1 − a^{K+1})·Le by the same sum, so
//   L = (1 − a)·Le + a·(1 − a^{K+1})·Le = Le·(1 − a^{K+2}) → Le.
// The Lobe Estimator holds no scattered emission: (1 − a)·Le, like the march without the cache.
TEST(EmissionRender, DeepInsideAnEmittingScatteringMediumLApproachesLe) {
  const std::string material = R"("scattering": [1, 1, 1], "absorption": [1, 1, 1], "phaseFunction": "hg",
      "g": 0.5, "emission": {"color": [0.8, 0.4, 0.2]})";
  const double Le[3] = {0.8, 0.4, 0.2};
  auto scene = [&](int bounces) {
    Scene s = sceneFromJson(slabScene(material, 1000, bounces));
    s.primitives[0].transform.scale = {1000, 1000, 1000};
    s.camera.position = {0, 0, 0};
    s.camera.lookAt = {0, 0, 1};
    return s;
  };
  for (int K : {3, 40}) {
    const double share = 1 - std::pow(0.5, K + 1);
    expectTilesWithinNoise(renderWith(scene(K), "pathtrace"), [&](int, int, int c) { return Le[c] * share; },
                           "pathtrace, " + std::to_string(K) + " bounces");
  }
  for (const char* renderer : {"raymarch", "lobe+eq7", "lobe+corrected"}) {
    const RenderResult r = renderWith(scene(40), renderer);
    ASSERT_EQ(r.stats.status, 0u) << renderer;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(pixel(r, x, y, c), 0.5 * Le[c], 1e-5) << renderer << " " << x << "," << y;
  }
  // The cache: 5³ nodes, the camera on the centre node, 1024 paths each. A path's value is (1 − a)·Le
  // times its number of segments, about 1 + Geometric(1/2), so a node's estimate has a standard
  // deviation of about 0.5·Le·√2/√1024 = 0.022·Le, and the pixel a·that = 0.011·Le; 0.06·Le is
  // over 5 of them.
  Scene cached = scene(40);
  cached.renderer.algorithm = Algorithm::Raymarch;
  cached.renderer.raymarch.multipleScattering = MultipleScattering::Cache;
  cached.renderer.raymarch.msCache.resolution = 4;
  cached.renderer.raymarch.msCache.paths = 1024;
  const RenderResult r = renderAlgorithm(cached);
  ASSERT_EQ(r.stats.status, 0u);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(pixel(r, x, y, c), Le[c], 0.06 * Le[c]) << x << "," << y << " " << c;
}

// Albedo 1 (σa = 0): an emission object emits nothing (σa·Le = 0), and the white furnace still
// holds: with background 1, no light and a thin box (optical depth 1, 1000 bounces: no path is
// cut), every path tracer sample is exactly 1. The real-time kernels' pixels are those of the same
// scene without the emission object, bit for bit (their emission terms add exactly 0).
TEST(EmissionRender, WithoutAbsorptionNothingIsEmittedAndTheFurnaceHolds) {
  const std::string base = R"("scattering": [1, 1, 1], "absorption": [0, 0, 0], "phaseFunction": "hg", "g": 0.3)";
  auto scene = [&](bool emits) {
    Scene s = sceneFromJson(slabScene(base + (emits ? R"(, "emission": {"color": [5, 5, 5], "scale": 2})" : ""), 1,
                                      1000));
    s.background = {1, 1, 1};
    return s;
  };
  const Scene emitting = scene(true);
  EXPECT_NE(buildDeviceScene(emitting, SceneGrids{}).buildOptions.find("-DEMISSION"), std::string::npos);
  const RenderResult pt = renderWith(emitting, "pathtrace");
  ASSERT_EQ(pt.stats.status, 0u);
  for (float v : pt.image.rgb) ASSERT_EQ(v, 1.0f);
  for (const char* renderer : {"raymarch", "lobe+eq7", "lobe+corrected"}) {
    const RenderResult a = renderWith(emitting, renderer), b = renderWith(scene(false), renderer);
    EXPECT_TRUE(a.image.rgb == b.image.rgb) << renderer;
  }
}

// The EmberGen fire as shipped (scenes/fire.json: density from `flames`, blackbody emission from
// `temperature`, two grids with different bounding boxes), small, in every algorithm and
// real-time option: no NaN, no status bit, and it glows: its brightest pixels are far above the
// background and orange (red > green > blue, as a blackbody below 4000 K is).
TEST(EmissionRender, TheEmberGenFireRendersCleanEverywhere) {
  NARVAL_REQUIRE_REAL_DATA(realDataPath("embergen_fire_a_50.vdb"));
  const Scene scene = loadScene(std::string(NARVAL_SOURCE_DIR) + "/scenes/fire.json",
                                {"renderer.resolution=[48,36]", "renderer.spp=4"});
  SceneGridStorage storage;
  const SceneGrids grids = loadSceneGrids(scene, storage);
  ASSERT_NE(grids.emission, nullptr);
  ASSERT_NE(grids.emission, grids.density);
  for (const char* renderer : kHardCaseRenderers) {
    const RenderResult r = renderWith(scene, renderer, grids);
    EXPECT_EQ(r.stats.status, 0u) << renderer;
    float peak[3] = {0, 0, 0};
    size_t brightest = 0;
    for (size_t i = 0; i < r.image.rgb.size(); ++i) {
      ASSERT_TRUE(std::isfinite(r.image.rgb[i])) << renderer;
      if (i % 3 == 0 && r.image.rgb[i] > r.image.rgb[brightest]) brightest = i;
    }
    for (int c = 0; c < 3; ++c) peak[c] = r.image.rgb[brightest + size_t(c)];
    EXPECT_GT(peak[0], 20 * scene.background[0]) << renderer;
    EXPECT_GT(peak[0], peak[1]) << renderer;
    EXPECT_GT(peak[1], peak[2]) << renderer;
  }
}

}  // namespace
}  // namespace narval::test
