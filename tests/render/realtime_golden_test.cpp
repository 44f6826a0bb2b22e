// The real-time kernels' exact path must not move: with the light-transmittance cache off
// (renderer.lightCache.resolution 0), early termination off (minTransmittance 0) and the lobe's
// view transmittances at its shadow step count (lobe.viewSteps = lobe.shadowSteps, as before they
// had their own key), raymarch and lobe give the pixels they gave before those economies existed.
// The references, tests/data/reference/realtime_*_32x24.exr, were rendered by this test with
// NARVAL_WRITE_REFERENCE=1 on PoCL by the kernels as they were before the cache (commit 5628be8),
// then committed; each carries the device it was rendered on (narval:device).
//
// On that device the comparison is bitwise (memcmp of every float). A different CPU may let PoCL
// contract multiply-adds differently, so elsewhere each pixel must agree to 1e-5 relative (plus
// 1e-7 absolute), a few float roundings over a march of ~10^3 operations, and the test says which
// comparison it made.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "image/image.h"
#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

struct GoldenCase {
  const char* name;
  const char* renderer;  // the JSON renderer object
  bool grid;             // on makeCloud(32, 7), else the homogeneous box
};

// Every economy off: the exact marching of the kernels as they were.
const GoldenCase kCases[] = {
    {"raymarch_grid",
     R"({"resolution": [32, 24], "algorithm": "raymarch", "storage": "buffer", "lightCache": {"resolution": 0},
         "raymarch": {"multipleScattering": "none", "steps": 60, "shadowSteps": 10, "minTransmittance": 0, "shadowAreaSamples": 1}})",
     true},
    {"raymarch_octaves_grid",
     R"({"resolution": [32, 24], "algorithm": "raymarch", "storage": "buffer", "lightCache": {"resolution": 0},
         "raymarch": {"steps": 40, "shadowSteps": 12, "octaves": 4, "minTransmittance": 0, "shadowAreaSamples": 1}})",
     true},
    {"raymarch_homogeneous",
     R"({"resolution": [32, 24], "algorithm": "raymarch", "lightCache": {"resolution": 0},
         "raymarch": {"multipleScattering": "none", "steps": 30, "shadowSteps": 8, "minTransmittance": 0, "shadowAreaSamples": 1}})",
     false},
    {"lobe_grid",
     R"({"resolution": [32, 24], "algorithm": "lobe", "storage": "buffer", "lightCache": {"resolution": 0},
         "raymarch": {"steps": 60}, "lobe": {"variant": "eq7", "firstHitSteps": 60, "shadowSteps": 40, "viewSteps": 40,
         "lobePoints": 12, "depthFactor": 3, "lobeRadius": 0.4, "minTransmittance": 0}})",
     true},
    {"lobe_homogeneous",
     R"({"resolution": [32, 24], "algorithm": "lobe", "lightCache": {"resolution": 0},
         "raymarch": {"steps": 60}, "lobe": {"variant": "eq7", "firstHitSteps": 60, "shadowSteps": 30, "viewSteps": 30,
         "lobePoints": 10, "depthFactor": 2, "lobeRadius": 0.5, "minTransmittance": 0}})",
     false},
};

std::string referencePath(const std::string& name) {
  return std::string(NARVAL_SOURCE_DIR) + "/tests/data/reference/realtime_" + name + "_32x24.exr";
}

TEST(RealtimeGolden, ExactMarchingGivesThePixelsOfTheKernelsBeforeTheCache) {
  const DenseGrid cloud = makeCloud(32, 7);
  const std::string device = runtime().selected.info.name;
  for (const GoldenCase& c : kCases) {
    SCOPED_TRACE(c.name);
    const RenderResult r = renderAlgorithm(sceneFromJson(litCloudJson(c.renderer)), c.grid ? &cloud : nullptr);
    ASSERT_EQ(r.stats.status, 0u);
    const std::string path = referencePath(c.name);
    if (std::getenv("NARVAL_WRITE_REFERENCE")) {
      std::filesystem::create_directories(std::filesystem::path(path).parent_path());
      writeExr(path, r.image, {{"narval:device", device}});
    }
    const ImageRGB ref = readExr(path);
    ASSERT_EQ(ref.width, 32);
    ASSERT_EQ(ref.height, 24);
    ASSERT_EQ(ref.rgb.size(), r.image.rgb.size());
    const std::string refDevice = readExrAttributes(path).at("narval:device");
    if (refDevice == device) {
      std::printf("[ golden ] %s: bitwise on %s\n", c.name, device.c_str());
      EXPECT_EQ(std::memcmp(ref.rgb.data(), r.image.rgb.data(), ref.rgb.size() * sizeof(float)), 0);
    } else {
      std::printf("[ golden ] %s: rendered on %s, reference from %s: 1e-5 relative\n", c.name, device.c_str(),
                  refDevice.c_str());
    }
    int differing = 0;
    for (size_t i = 0; i < ref.rgb.size(); ++i) {
      const double tol = refDevice == device ? 0.0 : 1e-5 * std::fabs(ref.rgb[i]) + 1e-7;
      if (std::fabs(double(ref.rgb[i]) - r.image.rgb[i]) > tol && ++differing <= 3)
        ADD_FAILURE() << "value " << i << ": reference " << ref.rgb[i] << ", now " << r.image.rgb[i];
    }
    EXPECT_EQ(differing, 0);
  }
}

}  // namespace
}  // namespace narval::test
