// Determinism: pixels depend only on (scene, seed, pixel, sample index) through the counter-based
// RNG (kernels/shared/rng.h), so renders are bitwise identical across runs and work-group shapes,
// and a different seed gives a different image.
#include <gtest/gtest.h>

#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

const std::string kCloudScene = litCloudJson(R"({"resolution": [37, 23], "spp": 8, "bounces": 6, "seed": 11})");

TEST(RenderDeterminism, BitwiseIdenticalAcrossRunsAndLocalSizes) {
  const DenseGrid cloud = makeCloud(24, 3);
  const Scene scene = sceneFromJson(kCloudScene);
  const RenderResult a = render(scene, &cloud, 8, 8);
  const RenderResult b = render(scene, &cloud, 8, 8);
  const RenderResult c = render(scene, &cloud, 3, 5);
  const RenderResult d = render(scene, &cloud, 16, 1);
  EXPECT_EQ(a.image.rgb, b.image.rgb);
  EXPECT_EQ(a.image.rgb, c.image.rgb);
  EXPECT_EQ(a.image.rgb, d.image.rgb);
  // Not a black image: the scene has light in it.
  double sum = 0;
  for (float v : a.image.rgb) sum += v;
  EXPECT_GT(sum / a.image.rgb.size(), 0.05);
}

TEST(RenderDeterminism, SeedChangesTheImage) {
  const DenseGrid cloud = makeCloud(24, 3);
  Scene scene = sceneFromJson(kCloudScene);
  const RenderResult a = render(scene, &cloud);
  scene.renderer.seed = 12;
  const RenderResult b = render(scene, &cloud);
  EXPECT_NE(a.image.rgb, b.image.rgb);
}

}  // namespace
}  // namespace narval::test
