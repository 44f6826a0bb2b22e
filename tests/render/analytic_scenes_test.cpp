// Rendered scenes with answers known in closed form or by independent quadrature (Nori style:
// each scene carries its expected value and its derivation).
#include <gtest/gtest.h>

#include <cmath>

#include "render/scene_upload.h"
#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

// Absorption-only homogeneous box, 1 unit thick along z, between the camera and a large rectangle
// light facing it. Every camera ray crosses the box face to face, then hits the light, so
// L = Le · exp(-σa · 1/cos θ) with θ the ray's angle to the z axis (the VRE with σs = 0,
// dissertation Eq. 3). With vfov = 2° the pixel-centre cos θ differs from 1 by at most 3e-4; the test
// uses each pixel centre's exact path length. Each path is a Bernoulli trial with p = T ≈ 0.50
// (analogue delta tracking absorbs or passes), variance T(1-T) ≈ 0.25: 256 px × 2560 spp give a
// relative standard error of 0.125%, so 0.5% is a 4σ bound (false failure rate ~6e-5).
TEST(RenderAnalytic, AbsorptionOnlyBoxMatchesBeerLambert) {
  const Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [16, 16], "spp": 2560, "bounces": 3})"));
  const RenderResult r = render(scene);
  const camera_params c = buildDeviceScene(scene, nullptr).params.camera;
  double expected = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) expected += absorptionBoxTransmittance(c, x, y) / 256.0;
  for (int ch = 0; ch < 3; ++ch) {
    const ChannelStats s = channelStats(r.image, ch);
    EXPECT_NEAR(s.mean / kAbsorptionBoxLe[ch], expected, 0.005 * expected) << "channel " << ch;
  }
  // Per 4x4 tile as well (an image mean would let a shifted or mirrored image pass): 16 px × 2560
  // Bernoulli samples, standard error sqrt(T(1−T)/40960) ≈ 0.0025; 4.5 of them per tile and
  // channel, a false alarm about 1 in 3000 over the 48.
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 4; ++tx) {
      double tile[3] = {0, 0, 0}, T = 0;
      for (int y = ty * 4; y < ty * 4 + 4; ++y)
        for (int x = tx * 4; x < tx * 4 + 4; ++x) {
          T += absorptionBoxTransmittance(c, x, y) / 16.0;
          for (int ch = 0; ch < 3; ++ch) tile[ch] += r.image.pixel(x, y)[ch] / kAbsorptionBoxLe[ch] / 16.0;
        }
      const double se = std::sqrt(T * (1 - T) / (16.0 * 2560.0));
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(tile[ch], T, 4.5 * se) << "tile " << tx << "," << ty << " channel " << ch;
    }
  EXPECT_EQ(r.stats.status, 0u);
  EXPECT_EQ(r.stats.nanPixels, 0);
}

// White furnace: albedo 1 (σa = 0), no lights, background 1. Every path ends by escaping, and for a
// grey medium the analogue walk never changes the throughput, so every sample is exactly 1 and so
// is every pixel, bit for bit, wherever the camera looks (into the box or past it). The bounce cap
// (1000) would darken a path only after 1000 real collisions: with optical thickness ≤ 6 the chance
// of that is far below 1e-12.
std::string furnaceScene(const std::string& volumeExtra, const std::string& scattering,
                         const std::string& phase = R"("phaseFunction": "hg", "g": 0.6)") {
  return R"({
    "materials": [
      {"name": "white", "type": "volume", "scattering": )" + scattering + R"(, "absorption": [0, 0, 0],
       )" + phase + R"(, "density": 3)" + volumeExtra + R"(}
    ],
    "primitives": [
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [2, 1.5, 1], "rotation": [20, 30, 0]},
       "materialName": "white"}
    ],
    "camera": {"position": [0, 0, -4], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 40},
    "renderer": {"resolution": [24, 16], "spp": 64, "bounces": 1000},
    "background": [1, 1, 1]
  })";
}

void expectAllExactlyOne(const ImageRGB& img) {
  size_t wrong = 0;
  for (float v : img.rgb) wrong += v != 1.0f;
  EXPECT_EQ(wrong, 0u) << "of " << img.rgb.size() << " values";
}

TEST(RenderAnalytic, WhiteFurnaceHomogeneousIsExactlyOne) {
  const RenderResult r = render(sceneFromJson(furnaceScene("", "[1, 1, 1]")));
  expectAllExactlyOne(r.image);
  EXPECT_EQ(r.stats.status, 0u);
}

// Mie (phase_mie.h) samples its blend exactly, so the walk's throughput stays 1 as with HG: in each
// of the fit's three diameter ranges, and on a grid as well.
TEST(RenderAnalytic, WhiteFurnaceWithMiePhaseIsExactlyOne) {
  const DenseGrid cloud = makeCloud(32, 7);
  for (const char* diameter : {"0.3", "2", "20"}) {
    SCOPED_TRACE(std::string("dropletDiameter ") + diameter);
    const std::string phase = std::string(R"("phaseFunction": "mie", "dropletDiameter": )") + diameter;
    const RenderResult r = render(sceneFromJson(furnaceScene("", "[1, 1, 1]", phase)));
    expectAllExactlyOne(r.image);
    EXPECT_EQ(r.stats.status, 0u);
  }
  const RenderResult r = render(sceneFromJson(furnaceScene("", "[1, 1, 1]", R"("phaseFunction": "mie")")), &cloud);
  expectAllExactlyOne(r.image);
}

// On grids, in every grid storage (renderer.storage: image, buffer, bricks): the walk's decisions
// depend on the density, the throughput never does, so the image filter's rounding cannot move a
// pixel off 1, nor can the bricks' empty space.
void expectFurnaceExactlyOneInEveryStorage(const DenseGrid& cloud) {
  for (const GridStorage storage : {GridStorage::Image, GridStorage::Buffer, GridStorage::Bricks}) {
    SCOPED_TRACE(gridStorageName(storage));
    Scene scene = sceneFromJson(furnaceScene("", "[1, 1, 1]"));
    scene.renderer.storage = storage;
    const RenderResult r = render(scene, &cloud);
    EXPECT_EQ(r.stats.storage, gridStorageName(storage));
    expectAllExactlyOne(r.image);
  }
}

TEST(RenderAnalytic, WhiteFurnaceOnGeneratedCloudIsExactlyOne) {
  expectFurnaceExactlyOneInEveryStorage(makeCloud(32, 7));
}

TEST(RenderAnalytic, WhiteFurnaceOnDisneyCloudIsExactlyOne) {
  const std::string path = realDataPath("wdas_cloud_sixteenth.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  expectFurnaceExactlyOneInEveryStorage(loadGrid(path, "density"));
}

// Chromatic white furnace: σs = (1, 2, 3)·D, σa = 0. Spectral tracking reweights the throughput, so
// samples are no longer exactly 1, but each channel is still an unbiased estimate of 1. Bound: the
// image mean per channel within 4 standard errors (estimated from the pixels) and 1%.
TEST(RenderAnalytic, ChromaticWhiteFurnaceIsOneOnAverage) {
  const RenderResult r = render(sceneFromJson(furnaceScene("", "[0.5, 1, 1.5]")));
  for (int ch = 0; ch < 3; ++ch) {
    const ChannelStats s = channelStats(r.image, ch);
    EXPECT_NEAR(s.mean, 1.0, std::max(4 * s.stderrOfMean, 1e-6)) << "channel " << ch;
    EXPECT_NEAR(s.mean, 1.0, 0.01) << "channel " << ch;
  }
  EXPECT_EQ(r.stats.status, 0u);
}

}  // namespace
}  // namespace narval::test

namespace narval::test {
namespace {

// Accumulation: no medium, no light, background 0.1 (not a binary fraction): every sample is
// exactly 0.1f, so after 10⁶ samples the pixel must still be 0.1f to 1e-6 relative. A naive float
// running sum is off by 0.96% by then (measured: 10⁶ adds of 0.1f give 100958.3; each add rounds at
// up to ulp(sum)/2 = 2^-8 once the sum passes 65536); the exact fixed-point sum (accum.h) divided by
// 10⁶ rounds back to the float it started from.
TEST(RenderAccumulation, MillionSamplesOfAConstantStayExact) {
  const RenderResult r = render(sceneFromJson(R"({
    "materials": [], "primitives": [],
    "camera": {"position": [0, 0, -1], "lookAt": [0, 0, 0]},
    "renderer": {"resolution": [2, 2], "spp": 1000000, "bounces": 0},
    "background": [0.1, 0.2, 0.3]
  })"));
  const float expected[3] = {0.1f, 0.2f, 0.3f};
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r.image.rgb[size_t(i * 3 + c)], expected[c], 1e-6 * expected[c]) << "pixel " << i << " channel " << c;
}

}  // namespace
}  // namespace narval::test
