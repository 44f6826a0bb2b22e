// A dense medium far from the camera: delta and ratio tracking step from the segment's entry
// (kernels/shared/tracking.h, tracking_entry), not from the ray's origin, so a camera 10⁶ units
// away gives the image of a camera close by instead of walks that stand still until their cap.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render_fixture.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

// 8³ voxels, density 1 in the middle 4³ and 0 in a two-voxel margin: under the one global
// majorant the walks cross empty space inside the box, where every tentative collision is a null
// one and only the step moves them on.
DenseGrid hollowCube() {
  DenseGrid g;
  g.nx = g.ny = g.nz = 8;
  g.data.assign(g.voxelCount(), 0.0f);
  for (int z = 2; z < 6; ++z)
    for (int y = 2; y < 6; ++y)
      for (int x = 2; x < 6; ++x) g.data[size_t(x) + 8 * (size_t(y) + 8 * size_t(z))] = 1.0f;
  g.maxValue = 1.0f;
  g.source = "hollow.vdb";
  return g;
}

// The box (2 units, σs 2000, σa 100: σ̄ = 2100, so steps −ln(u)/σ̄ of at most 16.6/2100 = 0.008)
// seen from `distance` along −z, with the field of view that frames it alike (almost parallel rays
// either way), a point light above and in front.
Scene farScene(double distance) {
  const double vfov = 2.0 * std::atan(1.5 / distance) * 180.0 / M_PI;
  char camera[160];
  std::snprintf(camera, sizeof camera, R"("camera": {"position": [0, 0, %.1f], "lookAt": [0, 0, 0], "vfov": %.9g})",
                -distance, vfov);
  return sceneFromJson(std::string(R"({
    "materials": [
      {"name": "bulb", "type": "emitter", "albedo": [200, 200, 200]},
      {"name": "fog", "type": "volume", "scattering": [2000, 2000, 2000], "absorption": [100, 100, 100]}
    ],
    "primitives": [
      {"type": "point", "transform": {"position": [0, 2, -4]}, "materialName": "bulb"},
      {"type": "volume", "transform": {"scale": [2, 2, 2]}, "materialName": "fog"}
    ],)") + camera + R"(,
    "renderer": {"resolution": [16, 16], "spp": 16, "bounces": 4, "storage": "buffer"},
    "background": [0.1, 0.1, 0.1]
  })");
}

// At 10⁶ units the ulp of the ray parameter is 0.0625: every step (at most 0.008, below half an
// ulp) taken from the ray's origin rounds back to it, and in the empty margin every walk would run
// to its cap of 10⁷ steps: at the cap's 1.4 s a walk (tracking.h) some 45 minutes for this image on
// 2 cores, estimated; measured, the test gives no result within 60 s without the entry re-origin.
// From the entry the far image is the near one: per 4x4 tile, within 5% (the near camera's rays
// fan out by up to 1.7° from the axis, the far one's are parallel: the views differ that much)
// plus 4 standard errors of the difference (both images' pixel spread in the tile, an overestimate
// of their noise; about 1e-3 for one of the 16 tiles to exceed it by chance).
TEST(TrackingFar, ADenseBoxAMillionUnitsAwayLooksAsFromNearby) {
  const DenseGrid grid = hollowCube();
  RenderOptions options;
  options.majorant = "global";
  const RenderResult near = renderPathtrace(runtime(), farScene(50), &grid, options);
  const RenderResult far = renderPathtrace(runtime(), farScene(1e6), &grid, options);
  EXPECT_EQ(near.stats.status, 0u);
  EXPECT_EQ(far.stats.status & STATUS_ITERATION_CAP, 0u) << "a walk stood still until its cap";
  EXPECT_EQ(far.stats.status, 0u);
  EXPECT_EQ(far.stats.nanPixels, 0);
  double lit = 0;
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 4; ++tx) {
      double sn = 0, sf = 0, qn = 0, qf = 0;
      for (int y = ty * 4; y < ty * 4 + 4; ++y)
        for (int x = tx * 4; x < tx * 4 + 4; ++x) {
          const double a = near.image.pixel(x, y)[1], b = far.image.pixel(x, y)[1];
          sn += a, sf += b, qn += a * a, qf += b * b;
        }
      const double mn = sn / 16, mf = sf / 16;
      const double se = std::sqrt(std::max(0.0, qn / 16 - mn * mn) / 15 + std::max(0.0, qf / 16 - mf * mf) / 15);
      EXPECT_LE(std::fabs(mf - mn), 0.05 * mn + 4 * se) << "tile " << tx << "," << ty << ": near " << mn << " far " << mf;
      lit = std::max(lit, mn);
    }
  EXPECT_GT(lit, 0.2);  // the box is lit and in view (the background is 0.1)
}

}  // namespace
}  // namespace narval::test
