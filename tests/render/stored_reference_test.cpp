// Optimisations must keep images within noise of a stored reference. The reference,
// tests/data/reference/lit_cloud_32x24.exr, is the path tracer's image of the lit chromatic cloud
// (test_support.h litCloudJson on makeCloud(32, 7)) at 16384 spp, seed 1, global majorant, buffer
// storage, rendered on PoCL by this test with NARVAL_WRITE_REFERENCE=1 (then committed). A change
// to the renderer that moves the image (a biased estimator, a wrong majorant, a storage mismatch)
// fails here even when it moves every configuration alike, which the mode-against-mode tests
// (majorant_render_test, grid_storage_test) cannot see. The reference predates the shadow rays'
// Russian roulette, which every configuration here now plays (the default): a second estimator of
// the same image.
//
// Each configuration renders 512 spp with seed 2 (independent of the reference's samples). Per
// pixel D = test − ref; pixels are independent, so z = mean(D) / (sd(D)/√n) over n = 768 pixels is
// standard normal for an unbiased renderer (the reference's own noise is part of sd(D)); |z| < 4
// per channel, a false alarm of 6e-5 each. The control, a 10% denser medium (density ×1.1), must
// fail the same test: the test resolves changes of that order (measured on PoCL: ×1.02 gives
// z = 2.3, ×1.05 4.2). And the mean ΔE76 under
// the display transform must be no more than 1.3x the baseline configuration's (global, buffer):
// the noise level must not grow either.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "analysis/image_compare.h"
#include "image/image.h"
#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

const std::string kReference = std::string(NARVAL_SOURCE_DIR) + "/tests/data/reference/lit_cloud_32x24.exr";

std::string sceneJson(int spp, int seed, const std::string& storage, double density = 4,
                      const std::string& lightSampling = "all") {
  std::string json = litCloudJson(R"({"resolution": [32, 24], "spp": )" + std::to_string(spp) + R"(, "bounces": 6, "seed": )" +
                                      std::to_string(seed) + R"(, "storage": ")" + storage +
                                      R"(", "pathtrace": {"lightSampling": ")" + lightSampling + R"("}})",
                                  "[1.0, 1.3, 1.6]", "[0.05, 0.02, 0.02]");
  const std::string key = "\"density\": 4}";
  json.replace(json.find(key), key.size(), "\"density\": " + std::to_string(density) + "}");
  return json;
}

RenderResult renderWith(const std::string& json, const DenseGrid& grid, const std::string& majorant) {
  RenderOptions o;
  o.majorant = majorant;
  return renderPathtrace(runtime(), sceneFromJson(json), &grid, o);
}

// The largest |z| over the three channels of test − reference.
double maxAbsZ(const ImageRGB& test, const ImageRGB& ref) {
  double worst = 0;
  const size_t n = size_t(ref.width) * size_t(ref.height);
  for (int c = 0; c < 3; ++c) {
    double sum = 0, sum2 = 0;
    for (size_t i = 0; i < n; ++i) {
      const double d = double(test.rgb[i * 3 + c]) - ref.rgb[i * 3 + c];
      sum += d;
      sum2 += d * d;
    }
    const double mean = sum / n, var = (sum2 - n * mean * mean) / (n - 1);
    worst = std::max(worst, std::fabs(mean) / std::sqrt(var / n));
  }
  return worst;
}

TEST(StoredReference, EveryMajorantAndStorageStaysWithinNoiseOfIt) {
  const DenseGrid cloud = makeCloud(32, 7);
  if (std::getenv("NARVAL_WRITE_REFERENCE")) {
    const RenderResult r = renderWith(sceneJson(16384, 1, "buffer"), cloud, "global");
    std::filesystem::create_directories(std::filesystem::path(kReference).parent_path());
    writeExr(kReference, r.image, {{"narval:spp", "16384"}, {"narval:seed", "1"}});
  }
  const ImageRGB ref = readExr(kReference);
  ASSERT_EQ(ref.width, 32);
  ASSERT_EQ(ref.height, 24);
  const DisplaySettings display{0.0f, ToneMapping::Aces};

  const RenderResult base = renderWith(sceneJson(512, 2, "buffer"), cloud, "global");
  const double baseDeltaE = compareImages(ref, base.image, display).stats76.mean;
  EXPECT_LT(maxAbsZ(base.image, ref), 4.0);
  for (const char* majorant : {"grid", "global"})
    for (const char* storage : {"buffer", "image", "bricks"}) {
      const RenderResult r = renderWith(sceneJson(512, 2, storage), cloud, majorant);
      EXPECT_EQ(r.stats.status, 0u);
      const double z = maxAbsZ(r.image, ref);
      const double dE = compareImages(ref, r.image, display).stats76.mean;
      EXPECT_LT(z, 4.0) << majorant << " " << storage;
      EXPECT_LT(dE, 1.3 * baseDeltaE) << majorant << " " << storage << " (baseline " << baseDeltaE << ")";
      std::printf("[ reference ] %s/%s: max |z| %.2f, mean dE76 %.4f (baseline %.4f)\n", majorant, storage, z, dE,
                  baseDeltaE);
    }
  // One light per event (the rectangle and the point light, picked by power or by fluence): the
  // same expectation, more noise (so only z is bounded).
  for (const char* sampling : {"power", "fluence"}) {
    const RenderResult r = renderWith(sceneJson(512, 2, "buffer", 4, sampling), cloud, "grid");
    EXPECT_EQ(r.stats.status, 0u);
    const double z = maxAbsZ(r.image, ref);
    EXPECT_LT(z, 4.0) << sampling;
    std::printf("[ reference ] lightSampling %s: max |z| %.2f\n", sampling, z);
  }
  // Control: 10% more density is a change the test must catch.
  const RenderResult denser = renderWith(sceneJson(512, 2, "buffer", 4 * 1.1), cloud, "grid");
  const double zDenser = maxAbsZ(denser.image, ref);
  std::printf("[ reference ] control (density x1.1): max |z| %.2f\n", zDenser);
  EXPECT_GT(zDenser, 4.0);
}

}  // namespace
}  // namespace narval::test
