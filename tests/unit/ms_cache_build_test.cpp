// Which nodes of the multiple-scattering cache a lookup can read (kernels/shared/ms_cache_build.h,
// ms_cache_node_is_read): the build skips the others.
#include <gtest/gtest.h>

#include <vector>

#include "shared/ms_cache_build.h"

namespace narval::test {
namespace {

// The index box [0, 8]³ under a 4x4x4 majorant grid (cells of 2 index units) whose only positive
// cell is (2, 1, 0) = [4, 6]×[2, 4]×[0, 2], and a 9x9x9 node grid (spacing 1). A sample of positive
// density lies in that cell, and every corner of its node cell must be read. The nodes read are those
// whose [p − 1, p + 1] (widened by MAJORANT_SLACK) meets it: x 3..7, y 1..5, z 0..3 (the box's edge
// clips z), 5·5·4 = 100 of 729; the build skips the other 629.
TEST(MsCacheBuild, ReadsExactlyTheNodesAroundPositiveMajorantCells) {
  medium_params m{};
  m.dims = nv_float4{8, 8, 8, 0};
  m.majorant_grid.cell_size = nv_float4{2, 2, 2, 0};
  m.majorant_grid.cells_x = m.majorant_grid.cells_y = m.majorant_grid.cells_z = 4;
  std::vector<float> majorants(64, 0.0f);
  majorants[2 + 4 * (1 + 4 * 0)] = 0.5f;
  grid_view grids{};
  grids.nx = grids.ny = grids.nz = 8;
  grids.majorants = majorants.data();
  kernel_context ctx = kernel_context_host(nullptr, nullptr, &m, &grids);
  node_grid_params c{};
  c.nx = c.ny = c.nz = 9;
  std::vector<int> read(size_t(node_grid_count(&c)));
  int count = 0;
  for (int n = 0; n < node_grid_count(&c); ++n) count += read[size_t(n)] = ms_cache_node_is_read(&ctx, &c, n);
  EXPECT_EQ(count, 100);
  const vec3 dims = vec3_make(8, 8, 8);
  for (float x = 4.0f; x <= 6.0f; x += 0.25f)
    for (float y = 2.0f; y <= 4.0f; y += 0.25f)
      for (float z = 0.0f; z <= 2.0f; z += 0.25f) {
        float w[8];
        size_t at[8];
        node_grid_corners(&c, node_grid_locate(&c, dims, vec3_make(x, y, z)), 1, at, w);
        for (int k = 0; k < 8; ++k)
          ASSERT_TRUE(read[at[k]]) << "the corner " << at[k] << " of the sample (" << x << ", " << y << ", " << z
                                   << ") is skipped";
      }
  // Without a positive cell nothing is read; the global majorant (one cell) reads every node.
  majorants[2 + 4 * (1 + 4 * 0)] = 0.0f;
  EXPECT_EQ(ms_cache_node_is_read(&ctx, &c, 4 + 9 * (3 + 9 * 1)), 0);
  m.majorant_grid.cells_x = m.majorant_grid.cells_y = m.majorant_grid.cells_z = 1;
  m.majorant_grid.cell_size = nv_float4{8, 8, 8, 0};
  const float global = 1.0f;
  grids.majorants = &global;
  for (int n = 0; n < node_grid_count(&c); ++n) ASSERT_TRUE(ms_cache_node_is_read(&ctx, &c, n));
}

}  // namespace
}  // namespace narval::test
