// march.h: the real-time kernels' quadrature skips empty majorant cells and spends all its steps
// on the occupied part of a ray.
#include <gtest/gtest.h>

#include <cmath>

#include "render/scene_upload.h"
#include "scene/scene.h"
#include "shared/march.h"
#include "unit/host_context.h"
#include "volume/dense_grid.h"
#include "volume/majorant_grid.h"

namespace narval {
namespace {

// A 32x8x8 grid whose density is non-zero only in voxels x = 12..19 (a smooth bump), in a box of
// one world unit per voxel. With 4x1x1 majorant cells of 8 voxels, a voxel j reaches points within
// (j + 0.5) ± 1, so voxels 12..19 reach x in (11.5, 20.5): cells 1 and 2 ([8, 24]) are occupied,
// cells 0 and 3 are exactly empty. A ray along +x therefore has 16 occupied units out of 32.
struct BumpFixture {
  DenseGrid grid;
  MajorantGrid majorants;
  DeviceScene ds;
  BumpFixture() {
    grid.nx = 32;
    grid.ny = grid.nz = 8;
    grid.data.assign(grid.voxelCount(), 0.0f);
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 12; x < 20; ++x)
          grid.data[size_t(x + 32 * (y + 8 * z))] = 0.5f + 0.5f * std::sin(0.7f * float(x) + 0.3f * float(y));
    grid.maxValue = 1.0f;
    majorants = buildMajorantGrid(grid, 4, 1, 1);
    const Scene scene = parseScene(R"({
      "materials": [{"name": "m", "type": "volume", "scattering": [0.3, 0.3, 0.3], "absorption": [0.1, 0.1, 0.1]}],
      "primitives": [{"name": "v", "type": "volume", "transform": {"scale": [32, 8, 8]}, "materialName": "m"}],
      "camera": {"position": [0, 0, -50], "lookAt": [0, 0, 0]},
      "renderer": {"resolution": [2, 2]}
    })", "bump.json");
    ds = buildDeviceScene(scene, &grid);
    ds.params.medium.majorant_grid = majorants.params();  // these 4 cells, not the renderer's choice
  }
};

TEST(MarchSkipsEmptySpace, StepsLandOnlyInOccupiedCells) {
  BumpFixture f;
  const medium_params& m = f.ds.params.medium;
  ASSERT_EQ(f.majorants.at(0, 0, 0), 0.0f);
  ASSERT_EQ(f.majorants.at(3, 0, 0), 0.0f);
  const grid_view skipping{f.grid.data.data(), 32, 8, 8, f.majorants.maxDensity.data()};
  medium_segment seg;
  ASSERT_TRUE(medium_intersect(&m, vec3_make(-20, 0.1f, 0.2f), vec3_make(1, 0, 0), 0.0f, 100.0f, &seg));
  march_iter it = march_begin(narval::test::hostContext(&m, &skipping, nullptr), &seg, 8);
  // The box spans world x in [-16, 16]; the occupied cells are index x in [8, 24] = world [-8, 8].
  EXPECT_NEAR(it.delta * 8, 16.0f, 1e-4f);
  float t;
  int samples = 0;
  while (march_next(&it, narval::test::hostContext(nullptr, &skipping, nullptr), &t)) {
    const float x = -20 + t;
    // Sample k sits at the midpoint of step k of the occupied stretch: x = -8 + (k + 0.5)·2.
    EXPECT_NEAR(x, -8 + (samples + 0.5f) * 2, 1e-4f) << "sample " << samples;
    ++samples;
  }
  EXPECT_EQ(samples, 8);
}

// A ray that crosses only empty cells costs no samples and has optical depth exactly 0, while the
// same ray without the majorant grid samples density (zero) all along the box.
TEST(MarchSkipsEmptySpace, EmptyRaysCostNoSamples) {
  BumpFixture f;
  const medium_params& m = f.ds.params.medium;
  const grid_view skipping{f.grid.data.data(), 32, 8, 8, f.majorants.maxDensity.data()};
  const grid_view whole{f.grid.data.data(), 32, 8, 8, nullptr};
  // A ray that crosses only empty cells costs no samples and has optical depth exactly 0.
  const grid_view& g = skipping;
  medium_segment seg;
  ASSERT_TRUE(medium_intersect(&m, vec3_make(-12, -10, 0), vec3_make(0, 1, 0), 0.0f, 100.0f, &seg));
  march_iter it = march_begin(narval::test::hostContext(&m, &g, nullptr), &seg, 50);
  float t;
  EXPECT_FALSE(march_next(&it, narval::test::hostContext(nullptr, &g, nullptr), &t));
  uint status = 0u;
  EXPECT_EQ(march_optical_depth(narval::test::hostContext(&m, &g, &status), vec3_make(-12, -10, 0),
                                vec3_make(0, 1, 0), 100.0f, 50).x,
            0.0f);
  EXPECT_EQ(status, 0u);
  march_iter plain = march_begin(narval::test::hostContext(&m, &whole, nullptr), &seg, 50);
  int samples = 0;
  while (march_next(&plain, narval::test::hostContext(nullptr, &whole, nullptr), &t)) ++samples;
  EXPECT_EQ(samples, 50);
}

}  // namespace
}  // namespace narval
