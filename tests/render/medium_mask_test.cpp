// The medium mask (render/medium_mask.h): which pixels' centre rays meet the medium, checked against
// the camera's rays and the box computed here in double precision, on a homogeneous box and on a
// grid whose density fills only its lower half in x; both renderers write the same mask.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "render/medium_mask.h"
#include "render/render_fixture.h"
#include "render/scene_upload.h"
#include "volume/dense_grid.h"

namespace narval {
namespace {

using test::Ray;
using test::pixelCentreRay;
using test::renderAlgorithm;
using test::sceneFromJson;
using test::xSlabGrid;

// HG, chromatic, no light: the kernels' variant many render tests share (no extra compilation).
std::string boxScene(const std::string& extra) {
  return R"({
    "materials": [{"name": "m", "type": "volume", "scattering": [0.5, 0.4, 0.3], "absorption": [0.1, 0.1, 0.1],
                   "phaseFunction": "hg", "g": 0.3)" + extra + R"(}],
    "primitives": [{"name": "v", "type": "volume", "transform": {"position": [1, 0.5, 0], "scale": [16, 16, 16]},
                    "materialName": "m"}],
    "camera": {"position": [1, 0.5, -200], "lookAt": [1, 0.5, 0], "vfov": 7},
    "renderer": {"resolution": [36, 24], "spp": 1}
  })";
}

// The ray of pixel (x, y) against the axis-aligned box [lo, hi]: the entry and exit t, or false.
bool slab(const Ray& r, const double lo[3], const double hi[3], double* t0, double* t1) {
  *t0 = -1e30;
  *t1 = 1e30;
  for (int k = 0; k < 3; ++k) {
    const double a = (lo[k] - r.o[k]) / r.d[k], b = (hi[k] - r.o[k]) / r.d[k];
    *t0 = std::max(*t0, std::min(a, b));
    *t1 = std::min(*t1, std::max(a, b));
  }
  return *t0 < *t1;
}

// A homogeneous box: exactly the pixels whose ray crosses it. Rays within 1e-3 of an edge are not
// judged (float against double).
TEST(MediumMask, AHomogeneousBoxIsThePixelsWhoseRayCrossesIt) {
  const Scene scene = sceneFromJson(boxScene(""));
  const DeviceScene ds = buildDeviceScene(scene, {});
  const std::vector<uint32_t> mask = MediumMask().pixels(ds);
  const camera_params& cam = ds.params.camera;
  ASSERT_EQ(mask.size(), size_t(36 * 24));
  const double lo[3] = {1 - 8, 0.5 - 8, -8}, hi[3] = {1 + 8, 0.5 + 8, 8};
  const double loIn[3] = {lo[0] + 1e-3, lo[1] + 1e-3, lo[2]}, hiIn[3] = {hi[0] - 1e-3, hi[1] - 1e-3, hi[2]};
  const double loOut[3] = {lo[0] - 1e-3, lo[1] - 1e-3, lo[2]}, hiOut[3] = {hi[0] + 1e-3, hi[1] + 1e-3, hi[2]};
  int in = 0, out = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 36; ++x) {
      const Ray r = pixelCentreRay(cam, x, y);
      double t0, t1;
      const uint32_t m = mask[size_t(y) * 36 + size_t(x)];
      if (slab(r, loIn, hiIn, &t0, &t1)) {
        EXPECT_EQ(m, 1u) << "pixel " << x << "," << y;
        ++in;
      } else if (!slab(r, loOut, hiOut, &t0, &t1)) {
        EXPECT_EQ(m, 0u) << "pixel " << x << "," << y;
        ++out;
      }
    }
  // The 7° view (28 units across at the box) holds the 16-unit box with empty space around it.
  EXPECT_GT(in, 200);
  EXPECT_GT(out, 200);
}

// A 16³ grid with density in its voxels x < 8 only. Voxel 7's trilinear support ends at index 8.5,
// so the mask's cells (one voxel each: 16 < 64) hold density up to index 9 and none beyond: pixels
// whose ray stays below index x 8.9 inside the box are in the mask, those above 9.1 are not (the
// view is nearly parallel: the ray's index x moves by 16·tan(3.5°)·(28/16)/2 < 0.9 through the box,
// checked at its entry and exit). A mirrored mask fails the second half.
TEST(MediumMask, AGridIsMaskedWhereItHoldsDensity) {
  const DenseGrid half = xSlabGrid(16, 0, 8);
  const Scene scene = sceneFromJson(boxScene(R"(, "density": 1)"));
  const DeviceScene ds = buildDeviceScene(scene, &half);
  const std::vector<uint32_t> mask = MediumMask().pixels(ds);
  const camera_params& cam = ds.params.camera;
  const nv_affine& toIndex = ds.params.medium.world_to_index;
  const double lo[3] = {1 - 8, 0.5 - 8, -8}, hi[3] = {1 + 8, 0.5 + 8, 8};
  int in = 0, out = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 36; ++x) {
      const Ray r = pixelCentreRay(cam, x, y);
      double t0, t1;
      if (!slab(r, lo, hi, &t0, &t1)) continue;
      double ix[2];
      for (int e = 0; e < 2; ++e) {
        const double t = e == 0 ? t0 : t1;
        const vec3 p = vec3_make(float(r.o[0] + t * r.d[0]), float(r.o[1] + t * r.d[1]), float(r.o[2] + t * r.d[2]));
        ix[e] = affine_point(toIndex, p).x;
      }
      const uint32_t m = mask[size_t(y) * 36 + size_t(x)];
      if (std::max(ix[0], ix[1]) < 8.9) {
        EXPECT_EQ(m, 1u) << "pixel " << x << "," << y << " index x " << ix[0] << ".." << ix[1];
        ++in;
      } else if (std::min(ix[0], ix[1]) > 9.1) {
        EXPECT_EQ(m, 0u) << "pixel " << x << "," << y << " index x " << ix[0] << ".." << ix[1];
        ++out;
      }
    }
  EXPECT_GT(in, 100);
  EXPECT_GT(out, 60);

  // Each renderer hands the mask on with its image (render/render_exr.cpp writes it).
  for (const char* algorithm : {"pathtrace", "raymarch"}) {
    Scene s = scene;
    s.renderer.algorithm = algorithm == std::string("pathtrace") ? Algorithm::Pathtrace : Algorithm::Raymarch;
    EXPECT_EQ(renderAlgorithm(s, &half).mediumMask, mask) << algorithm;
  }
}

}  // namespace
}  // namespace narval
