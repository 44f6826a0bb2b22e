// Grids the device cannot hold as one 3D image get a clear error naming the file and the limit
// (bricked storage for larger grids comes later: issue 6).
#include <gtest/gtest.h>

#include <sstream>

#include "render/device_grid.h"
#include "render_fixture.h"
#include "scene/input_error.h"

namespace narval::test {
namespace {

TEST(DeviceLimits, GridWiderThanTheImageLimitIsAClearError) {
  const DeviceInfo& d = runtime().selected.info;
  DenseGrid grid;
  grid.nx = int(d.image3dMax[0]) + 1;
  grid.ny = 1;
  grid.nz = 1;
  grid.data.assign(size_t(grid.nx), 0.5f);
  grid.maxValue = 0.5f;
  grid.source = "wide.vdb";
  std::ostringstream expected;
  expected << "wide.vdb: grid: grid " << grid.nx << "x1x1 exceeds the device's 3D image limit " << d.image3dMax[0]
           << "x" << d.image3dMax[1] << "x" << d.image3dMax[2];
  try {
    uploadGrid(runtime(), grid);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), expected.str());
  }
}

}  // namespace
}  // namespace narval::test
