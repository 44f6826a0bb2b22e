// Grids the device cannot hold: a storage asked for by name (image, buffer, bricks) gives a clear
// error naming the file, the limit and the storage that would hold the grid; renderer.storage
// "auto" falls back to sparse bricks with a warning (issue 6, item 6) when its choice cannot hold
// the grid. Lowered limits come from a copy of the runtime (same context and queue) whose
// advertised DeviceInfo is changed.
#include <gtest/gtest.h>

#include <sstream>

#include "cl/device_allocation.h"
#include "core/input_error.h"
#include "render/device_grid.h"
#include "render/pathtrace_renderer.h"
#include "render/realtime_renderer.h"
#include "render_fixture.h"

namespace narval::test {
namespace {

DenseGrid wideGrid() {
  const DeviceInfo& d = runtime().selected.info;
  DenseGrid grid;
  grid.nx = int(d.image3dMax[0]) + 1;
  grid.ny = 1;
  grid.nz = 1;
  grid.data.assign(size_t(grid.nx), 0.5f);
  grid.maxValue = 0.5f;
  grid.source = "wide.vdb";
  return grid;
}

TEST(DeviceLimits, GridWiderThanTheImageLimitIsAClearError) {
  const DeviceInfo& d = runtime().selected.info;
  const DenseGrid grid = wideGrid();
  std::ostringstream expected;
  expected << "wide.vdb: grid: grid " << grid.nx << "x1x1 exceeds the device's 3D image limit " << d.image3dMax[0]
           << "x" << d.image3dMax[1] << "x" << d.image3dMax[2]
           << "; renderer.storage \"buffer\" (--storage buffer) holds it in one buffer";
  try {
    uploadGridImage(runtime(), grid);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), expected.str());
  }
}

// The same grid in the buffer storage: uploaded and rendered (a thin slab of density 0.5 seen
// face on by the ray marcher), where the image storage refuses it.
TEST(DeviceLimits, GridWiderThanTheImageLimitRendersFromABuffer) {
  const DenseGrid grid = wideGrid();
  EXPECT_NO_THROW(uploadGridBuffer(runtime(), grid));
  Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [4, 4], "algorithm": "raymarch",
                                                    "storage": "buffer"})"));
  const RenderResult r = renderRealtime(runtime(), scene, &grid, 1, RenderOptions{});
  EXPECT_EQ(r.stats.storage, "buffer");
  EXPECT_EQ(r.stats.status, 0u);
  EXPECT_EQ(r.stats.nanPixels, 0);
}

// On a device that prefers images (advertised as a GPU), the grid wider than the 3D image limit
// was an error; with renderer.storage "auto" it now renders from bricks, says so in a warning, and
// gives the pixels of the buffer storage. With "image" asked for by name it is still the error.
TEST(DeviceLimits, AutoFallsBackToBricksForAGridWiderThanTheImageLimit) {
  ClRuntime gpu = runtime();
  gpu.selected.info.type = "GPU";
  gpu.selected.info.imageSupport = true;
  const DenseGrid grid = wideGrid();
  ASSERT_EQ(resolveGridStorage(GridStorage::Auto, gpu.selected.info), GridStorage::Image);
  std::string why;
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, gpu.selected.info, &grid, &why), GridStorage::Bricks);
  std::ostringstream limit;
  limit << "wide.vdb: grid " << grid.nx << "x1x1 exceeds the device's 3D image limit " << gpu.selected.info.image3dMax[0]
        << "x" << gpu.selected.info.image3dMax[1] << "x" << gpu.selected.info.image3dMax[2]
        << ": renderer.storage \"auto\" stores it as sparse 8^3 bricks (\"bricks\") instead of a 3D image";
  EXPECT_EQ(why, limit.str());

  Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [4, 4], "algorithm": "raymarch"})"));
  const RenderResult r = renderRealtime(gpu, scene, &grid, 1, RenderOptions{});
  EXPECT_EQ(r.stats.storage, "bricks");
  const size_t bricks = size_t(grid.nx + 7) / 8;  // x 1 x 1, all holding density
  EXPECT_EQ(r.stats.bricks, bricks);
  EXPECT_EQ(r.stats.bricksOccupied, bricks);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], limit.str() + ": " + std::to_string(bricks) + " of " + std::to_string(bricks) +
                               " bricks occupied (100.0%), " + byteCount(r.stats.gridBytes));
  EXPECT_EQ(r.stats.status, 0u);
  scene.renderer.storage = GridStorage::Buffer;
  const RenderResult b = renderRealtime(gpu, scene, &grid, 1, RenderOptions{});
  EXPECT_EQ(b.stats.storage, "buffer");
  EXPECT_TRUE(b.warnings.empty());
  EXPECT_EQ(r.image.rgb, b.image.rgb);

  scene.renderer.storage = GridStorage::Image;
  EXPECT_THROW(renderRealtime(gpu, scene, &grid, 1, RenderOptions{}), InputError);
}

// A buffer over CL_DEVICE_MAX_MEM_ALLOC_SIZE: refused before any allocation, naming the bytes.
TEST(DeviceLimits, GridOverTheLargestAllocationIsAClearBufferError) {
  const DeviceInfo& d = runtime().selected.info;
  DenseGrid grid;  // no data: the limit is checked first
  grid.nx = 1 << 20;
  grid.ny = 1 << 10;
  grid.nz = int(d.maxAllocBytes / (size_t(grid.nx) * size_t(grid.ny) * sizeof(float))) + 1;
  grid.source = "huge.vdb";
  const size_t bytes = (size_t(grid.nx) * size_t(grid.ny) * size_t(grid.nz) + 4) * sizeof(float);
  std::ostringstream expected;
  expected << "huge.vdb: grid: grid " << grid.nx << "x" << grid.ny << "x" << grid.nz
           << " as a float buffer needs " << byteCount(bytes) << ", over device '" << d.name
           << "''s largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE) of " << byteCount(d.maxAllocBytes)
           << "; renderer.storage \"bricks\" (--storage bricks) stores only its non-empty 8^3 bricks";
  try {
    uploadGridBuffer(runtime(), grid);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), expected.str());
  }
}

TEST(DeviceLimits, ByteCountsAreExactWithAReadableScale) {
  EXPECT_EQ(byteCount(0), "0 bytes");
  EXPECT_EQ(byteCount(1023), "1023 bytes");
  EXPECT_EQ(byteCount(1024), "1024 bytes (1.00 KiB)");
  EXPECT_EQ(byteCount(size_t(3) << 29), "1610612736 bytes (1.50 GiB)");
  EXPECT_EQ(byteCount(size_t(5) << 40), "5497558138880 bytes (5.00 TiB)");
}

// Asking for more than CL_DEVICE_MAX_MEM_ALLOC_SIZE is refused before the driver is asked, with
// the file and key that decided the size, both sizes and the device.
TEST(DeviceLimits, AnAllocationOverTheDeviceLimitNamesTheSizeAskedFor) {
  ClRuntime& rt = runtime();
  const size_t limit = rt.selected.info.maxAllocBytes;
  try {
    allocateBuffer(rt, CL_MEM_READ_WRITE, limit + 1, {"big.json", "renderer.resolution", "an accumulator"});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "big.json: renderer.resolution: an accumulator needs " + byteCount(limit + 1) +
                                         ", over the largest allocation of device '" + rt.selected.info.name +
                                         "', " + byteCount(limit));
  }
}

// Every renderer sizes its image buffers through allocateBuffer: on a device whose largest
// allocation is 1000 bytes, a 16x16 image (16x16 pixels x 4 floats x 4 bytes = 4096 bytes) is a
// clear error naming renderer.resolution, for the path tracer and the real-time kernels alike.
TEST(DeviceLimits, RenderersReportAnImageTooLargeForTheDevice) {
  ClRuntime small = runtime();  // same context and queue, smaller advertised limit
  small.selected.info.maxAllocBytes = 1000;
  Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [16, 16], "spp": 1})"));
  scene.sourcePath = "box.json";
  const std::string device = "over the largest allocation of device '" + small.selected.info.name + "', 1000 bytes";
  // The path tracer's accumulator: 8 64-bit words per pixel (accum.h), 16x16x64 = 16384 bytes.
  const std::string tail = " RGBA floats needs 4096 bytes (4.00 KiB), " + device;
  try {
    renderPathtrace(small, scene, nullptr, {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "box.json: renderer.resolution: an accumulator of 16x16 pixels needs 16384 bytes (16.00 KiB), " + device);
  }
  scene.renderer.algorithm = Algorithm::Raymarch;
  try {
    renderRealtime(small, scene, nullptr, 1, {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "box.json: renderer.resolution: an image of 16x16" + tail);
  }
}

// What the driver refuses at launch time (out of memory or resources) names the device, the
// kernel and the memory the render holds; other OpenCL errors pass through unchanged.
TEST(DeviceLimits, LaunchResourceErrorsNameTheMemoryHeld) {
  DeviceInfo d;
  d.name = "Test GPU";
  try {
    rethrowLaunchError(cl::Error(CL_OUT_OF_RESOURCES, "clEnqueueNDRangeKernel"), d, "pathtrace", size_t(3) << 30);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_EQ(std::string(e.what()),
              "device 'Test GPU' ran out of memory or resources running pathtrace (this render holds 3221225472 bytes "
              "(3.00 GiB) of device memory): CL_OUT_OF_RESOURCES (-5)");
  }
  try {
    rethrowLaunchError(cl::Error(CL_INVALID_KERNEL_ARGS, "clEnqueueNDRangeKernel"), d, "pathtrace", 0);
    FAIL() << "expected cl::Error";
  } catch (const cl::Error& e) {
    EXPECT_EQ(e.err(), CL_INVALID_KERNEL_ARGS);
  }
}

}  // namespace
}  // namespace narval::test
