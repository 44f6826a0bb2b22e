// The native baseline's renderer (bench/native/native_render.h, issue 6 item 4): the shared kernel
// headers on host threads. No OpenCL: every render here runs on the host.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "../../bench/native/native_render.h"
#include "render/lobe_directions.h"
#include "render/realtime_renderer.h"
#include "render/render_fixture.h"  // absorptionBoxJson and its analytic transmittance (no device used)
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

// A lit chromatic cloud (spectral tracking, a rectangle and a point light, background): every code
// path the path tracer and the marches have, on a generated grid; the dissertation's march (the
// native build has no multiple-scattering cache).
const std::string kLitCloud = litCloudJson(R"({"resolution": [24, 17], "spp": 8, "bounces": 6, "seed": 5,
                                               "raymarch": {"multipleScattering": "none"}})",
                                           "[1.0, 1.3, 1.6]", "[0.05, 0.02, 0.02]");

native::NativeOptions optionsFor(const Scene& scene, const DeviceScene& ds, Algorithm algorithm) {
  native::NativeOptions o;
  o.algorithm = algorithm;
  o.spp = scene.renderer.spp;
  native::prepareRealtimeInputs(scene, ds, o);
  return o;
}

// Rows go to threads in whatever order the atomic counter hands them out, and each pixel's value
// depends on the pixel alone (counter-based RNG): 1, 2 and 4 threads (4 > rows per thread on 2
// cores, 17 rows: uneven shares) give the same bits, for every algorithm and both majorants.
TEST(NativeRender, ThreadCountNeverChangesTheBits) {
  const DenseGrid cloud = makeCloud(24, 3);
  const Scene scene = sceneFromJson(kLitCloud);
  const DeviceScene ds = buildDeviceScene(scene, &cloud);
  for (const Algorithm algorithm : {Algorithm::Pathtrace, Algorithm::Raymarch, Algorithm::Lobe})
    for (const char* majorant : {"grid", "global"}) {
      if (isRealtime(algorithm) && std::string(majorant) == "global") continue;
      const std::string alg = algorithmName(algorithm);
      native::NativeOptions o = optionsFor(scene, ds, algorithm);
      o.majorant = majorant;
      o.threads = 1;
      const native::NativeResult one = native::renderNative(ds, o);
      ASSERT_EQ(one.threads, 1);
      EXPECT_EQ(one.status, 0u) << alg << " " << majorant;
      EXPECT_EQ(one.nanPixels, 0) << alg << " " << majorant;
      double sum = 0;
      for (float v : one.image.rgb) sum += v;
      EXPECT_GT(sum, 0.0) << alg << ": not a black image";
      for (int threads : {2, 4}) {
        o.threads = threads;
        const native::NativeResult many = native::renderNative(ds, o);
        EXPECT_EQ(many.threads, threads);
        EXPECT_EQ(many.image.rgb, one.image.rgb) << alg << " " << majorant << ", " << threads << " threads";
        EXPECT_EQ(many.status, one.status);
      }
    }
}

// The same scene twice with the same seed: the same bits; another seed: another image (the seed
// reaches the per-sample random numbers).
TEST(NativeRender, SeedDeterminesThePathTracedImage) {
  const DenseGrid cloud = makeCloud(16, 2);
  Scene scene = sceneFromJson(kLitCloud);
  scene.renderer.spp = 2;
  const DeviceScene ds = buildDeviceScene(scene, &cloud);
  const native::NativeOptions o = optionsFor(scene, ds, Algorithm::Pathtrace);
  const ImageRGB a = native::renderNative(ds, o).image, b = native::renderNative(ds, o).image;
  EXPECT_EQ(a.rgb, b.rgb);
  scene.renderer.seed = 6;
  const DeviceScene other = buildDeviceScene(scene, &cloud);
  EXPECT_NE(native::renderNative(other, o).image.rgb, a.rgb);
}

// The absorption box of the render tests (σa = 0.7, 1 unit thick, light Le = (2, 3, 4) behind it).
// Path tracer: each sample is Le·[the walk is not absorbed], a Bernoulli of mean Tr = exp(−σ·d)
// (about 0.497 here; d = 1/cos θ per pixel), so the image mean over 16² pixels × 2560 spp estimates
// Le·mean(Tr) with a standard error of at most 0.5/√655360 = 6.2e-4, 1.2e-3 relative: the bound
// 0.005 relative is 4 standard errors (the same check as the device's analytic test; the seed is
// fixed, so the outcome is too). Ray marcher: no scattering, so L = Le·Π exp(−σ·Δ) over 60 steps
// whose lengths sum to d, deterministic: float rounding only (60 exps and products, ~1e-5).
TEST(NativeRender, AbsorptionBoxGivesBeerLambert) {
  const Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [16, 16], "spp": 2560, "bounces": 3,
                                                                 "raymarch": {"multipleScattering": "none"}})"));
  const DeviceScene ds = buildDeviceScene(scene, nullptr);
  const camera_params& c = ds.params.camera;
  double expected = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) expected += absorptionBoxTransmittance(c, x, y) / 256.0;

  const native::NativeResult pt = native::renderNative(ds, optionsFor(scene, ds, Algorithm::Pathtrace));
  EXPECT_EQ(pt.status, 0u);
  EXPECT_EQ(pt.nanPixels, 0);
  for (int ch = 0; ch < 3; ++ch) {
    const ChannelStats s = channelStats(pt.image, ch);
    std::printf("[ native ] absorption box, channel %d: mean Tr %.5f, expected %.5f\n", ch,
                s.mean / kAbsorptionBoxLe[ch], expected);
    EXPECT_NEAR(s.mean / kAbsorptionBoxLe[ch], expected, 0.005 * expected) << "channel " << ch;
  }

  const native::NativeResult rm = native::renderNative(ds, optionsFor(scene, ds, Algorithm::Raymarch));
  EXPECT_EQ(rm.status, 0u);
  double worst = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        const double want = kAbsorptionBoxLe[ch] * absorptionBoxTransmittance(c, x, y);
        const double got = rm.image.pixel(x, y)[ch];
        worst = std::max(worst, std::fabs(got - want) / want);
        EXPECT_NEAR(got, want, 2e-5 * want) << "pixel " << x << "," << y << " channel " << ch;
      }
  std::printf("[ native ] absorption box, raymarch: worst relative error %.2e\n", worst);
}

// (An unknown algorithm cannot be asked for: NativeOptions::algorithm is an Algorithm.)
TEST(NativeRender, RejectsUnknownMajorantAndLobeWithoutDirections) {
  const Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [2, 2], "spp": 1})"));
  const DeviceScene ds = buildDeviceScene(scene, nullptr);
  native::NativeOptions o;
  o.algorithm = Algorithm::Pathtrace;
  o.majorant = "local";
  EXPECT_THROW(native::renderNative(ds, o), std::invalid_argument);
  o.majorant = "grid";
  o.algorithm = Algorithm::Lobe;  // without directions
  EXPECT_THROW(native::renderNative(ds, o), std::invalid_argument);
}

}  // namespace
}  // namespace narval::test
