// The view cache under a moving camera (kernels/shared/ms_cache_reproject.h, host/render/device_ms_cache.h):
// in a budgeted refine the old cache is drawn reprojected to the new pose from the first frame, faded
// out as the new paths come in, and the cache ends as the one built at the new pose.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/device_ms_cache.h"
#include "render/device_scene.h"
#include "render/node_grid_layout.h"
#include "render/realtime_params.h"
#include "render/realtime_renderer.h"
#include "render_fixture.h"
#include "shared/ms_cache_reproject.h"

namespace narval::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// `scene` with its camera orbited by `degrees` about the vertical axis through its look-at point.
Scene orbited(const Scene& scene, double degrees) {
  Scene out = scene;
  const Vec3f& at = scene.camera.lookAt;
  const double a = degrees * kPi / 180, dx = scene.camera.position[0] - at[0], dz = scene.camera.position[2] - at[2];
  out.camera.position[0] = float(at[0] + dx * std::cos(a) + dz * std::sin(a));
  out.camera.position[2] = float(at[2] - dx * std::sin(a) + dz * std::cos(a));
  return out;
}

std::vector<float> readBuffer(const cl::Buffer& b, size_t floats) {
  std::vector<float> v(floats);
  runtime().queue.enqueueReadBuffer(b, CL_TRUE, 0, floats * sizeof(float), v.data());
  return v;
}

// The white furnace (albedo 1, background 1, no light: radiance 1 everywhere, in every direction)
// with a filtered view cache of one-pixel columns (the box's silhouette moves across them): every node
// of a cache built anywhere holds exactly 1, so its reprojection to any pose does too (a node the old
// camera did not see reads its nearest columns' 1, worth no paths), and so does every blend of 1s.
// Each frame after an orbit of 5°, 30° and 90°, then 120° drawn at half the size (the viewer's frames
// while the camera moves) and 150° at the full size again, within a budget of 0.3 ms (dozens of
// frames a pose, the first ones drawing the prior alone), reads 1 within the march's rounding
// (ms_cache_test.cpp's furnace: 1e-5) until the cache is whole again. (Drawing the old nodes in place
// instead, the columns the box newly covers read 0: 0.87 at 30°. The first build, at 0°, has nothing
// to draw before its first paths.)
TEST(MsCacheMotion, TheWhiteFurnaceIsOneInEveryFrameAcrossOrbits) {
  const Scene scene = sceneFromJson(R"({
    "materials": [{"name": "white", "type": "volume", "scattering": [1, 1, 1], "absorption": [0, 0, 0], "density": 1}],
    "primitives": [{"name": "box", "type": "volume", "transform": {"scale": [1, 1, 1]}, "materialName": "white"}],
    "camera": {"position": [0, 0, -3], "lookAt": [0, 0, 0], "vfov": 30},
    "renderer": {"resolution": [16, 16], "algorithm": "raymarch", "bounces": 1000, "storage": "buffer",
                 "raymarch": {"steps": 40, "minTransmittance": 0, "multipleScattering": "cache",
                              "msCache": {"layout": "view", "tile": 1, "filter": 1.5, "paths": 4}}},
    "background": [1, 1, 1]
  })");
  RealtimeRenderer r(runtime(), scene, nullptr);
  int builds = 0;
  for (const double degrees : {0.0, 5.0, 30.0, 90.0, 120.0, 150.0}) {
    SCOPED_TRACE(testing::Message() << "orbit " << degrees << "°");
    Scene view = orbited(scene, degrees);
    if (degrees == 120) view.renderer.width = view.renderer.height = 8;
    r.setView(view);
    int frames = 0, partial = 0;
    for (double progress = 0; (progress < 1 || frames < 3) && frames < 2000; ++frames) {
      r.renderFrame(0.3);
      const RenderResult out = r.result();
      ASSERT_EQ(out.stats.status, 0u);
      progress = out.stats.msCache.progress;
      partial += progress < 1;
      if (degrees == 0) continue;  // the first build has nothing to draw before its first paths
      for (size_t i = 0; i < out.image.rgb.size(); ++i) ASSERT_NEAR(out.image.rgb[i], 1.0f, 1e-5f) << "value " << i;
    }
    EXPECT_GT(partial, 3);  // frames drawn before the cache at this pose was whole
    EXPECT_EQ(r.result().stats.msCache.builds, ++builds);
  }
}

// The lit box's filtered view cache (tile 1), built at its pose, then the camera orbited 30° in a
// budgeted refine: the first call draws the prior, the old filtered cache reprojected to the new nodes
// (the device's values are those of the shared code run here on the old drawn cache and the new
// placement, to float rounding), with no new paths yet; once the new paths are all in, the prior is
// gone and the cache, running means and filtered copy, is the one built at the new pose from nothing,
// bit for bit.
TEST(MsCacheMotion, AnOrbitDrawsTheReprojectionThenEndsAsTheCacheBuiltThere) {
  Scene before = litBox();
  before.renderer.raymarch.msCache.layout = MsCacheLayout::View;
  before.renderer.raymarch.msCache.tile = 1;
  before.renderer.raymarch.msCache.filter = 1.5f;
  const Scene after = orbited(before, 30);
  DeviceSceneBuffers devBefore(runtime(), before, nullptr), devAfter(runtime(), after, nullptr);
  const ms_cache_params params = realtimeParams(before, devBefore.scene).msCache;
  const size_t floats = nodeGridCount(params.grid) * MS_CACHE_STRIDE;
  const auto whole = [&](DeviceMsCache& cache, DeviceSceneBuffers& dev) {
    for (int calls = 0; (cache.paths() < 24 || cache.filterPending() || cache.reprojected()) && calls < 100000; ++calls)
      cache.refine(runtime(), dev, params, 24, 32, "lit_box.json", 0.01);
  };
  DeviceMsCache cache;
  whole(cache, devBefore);
  EXPECT_FALSE(cache.reprojected());
  const std::vector<float> drawnBefore = readBuffer(cache.buffer(), floats);

  cache.refine(runtime(), devAfter, params, 24, 32, "lit_box.json", 0.001);
  ASSERT_TRUE(cache.reprojected());
  EXPECT_EQ(cache.paths(), 0);
  const std::vector<float> prior = readBuffer(cache.buffer(), floats), placed = readBuffer(cache.means(), floats);
  camera_params oldCamera = devBefore.scene.params.camera, newCamera = devAfter.scene.params.camera;
  std::vector<float> expected(floats);
  int seen = 0;
  for (int node = 0; node < nodeGridCount(params.grid); ++node) {
    const size_t at = size_t(node) * MS_CACHE_STRIDE;
    ms_view_reproject_node(&newCamera, devAfter.scene.params.medium.phase, &oldCamera, &params, &params,
                           drawnBefore.data(), placed.data(), node, expected.data() + at);
    for (int i = 0; i < 4; ++i) ASSERT_NEAR(prior[at + i], expected[at + i], 1e-5f * (1 + std::fabs(expected[at + i])));
    seen += prior[at + 3] > 0;
  }
  EXPECT_GT(seen, 0);

  whole(cache, devAfter);
  EXPECT_FALSE(cache.reprojected());
  EXPECT_EQ(cache.rebuilds(), 2);
  DeviceMsCache scratch;
  whole(scratch, devAfter);
  EXPECT_EQ(readBuffer(cache.means(), floats), readBuffer(scratch.means(), floats));
  EXPECT_EQ(readBuffer(cache.buffer(), floats), readBuffer(scratch.buffer(), floats));
}

}  // namespace
}  // namespace narval::test
