// cloud_slab_test.cpp: large generated clouds without a dense copy (issue 6, item 6). make-cloud
// writes its .vdb slab by slab (makeCloudSlab + writeVdbSlabs), so a 1024³ or 2048³ cloud never
// exists densely in memory; the slabs must give exactly what the dense path gives: the same bits
// per slice, and a file that loads to the same grid.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <vector>

#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval {
namespace {

TEST(CloudSlabs, SlicesAreTheDenseCloudsBits) {
  const int r = 37;
  const DenseGrid whole = makeCloud(r, 4);
  const size_t slice = size_t(r) * r;
  for (int z0 = 0; z0 < r; z0 += 10) {
    const int z1 = std::min(r, z0 + 10);
    std::vector<float> slab(slice * size_t(z1 - z0), -1.0f);
    makeCloudSlab(r, 4, z0, z1, slab.data());
    EXPECT_EQ(std::memcmp(slab.data(), whole.data.data() + slice * size_t(z0), slab.size() * sizeof(float)), 0)
        << "slices " << z0 << ".." << z1;
  }
  std::vector<float> none(1);
  EXPECT_THROW(makeCloudSlab(r, 4, 5, r + 1, none.data()), std::invalid_argument);
  EXPECT_THROW(makeCloudSlab(r, 4, 6, 5, none.data()), std::invalid_argument);
}

// The file written in slabs (8 and 16 slices; 37 is no multiple of either) loads to the grid the
// file written from the dense cloud loads to: dims, transform and every value.
TEST(CloudSlabs, FileWrittenInSlabsLoadsAsTheDenseOnesFile) {
  test::TempDir dir;
  const int r = 37;
  const DenseGrid cloud = makeCloud(r, 9);
  writeVdb(dir.file("dense.vdb"), cloud, "density", 1.0f / r);
  const DenseGrid dense = loadVdb(dir.file("dense.vdb"), "density");
  for (int slabSlices : {8, 16, 64}) {
    SCOPED_TRACE(slabSlices);
    int calls = 0;
    writeVdbSlabs(
        dir.file("slabs.vdb"), r, r, r, slabSlices,
        [&](int z0, int z1, float* out) {
          ++calls;
          makeCloudSlab(r, 9, z0, z1, out);
        },
        "density", 1.0f / r);
    EXPECT_EQ(calls, (r + slabSlices - 1) / slabSlices);
    const DenseGrid slabs = loadVdb(dir.file("slabs.vdb"), "density");
    EXPECT_EQ(slabs.nx, dense.nx);
    EXPECT_EQ(slabs.ny, dense.ny);
    EXPECT_EQ(slabs.nz, dense.nz);
    EXPECT_EQ(slabs.indexToWorld, dense.indexToWorld);
    EXPECT_EQ(slabs.maxValue, dense.maxValue);
    EXPECT_TRUE(slabs.data == dense.data);
  }
  EXPECT_THROW(writeVdbSlabs(dir.file("bad.vdb"), r, r, r, 12, [](int, int, float*) {}), std::invalid_argument);
}

}  // namespace
}  // namespace narval
