// brick_storage_test.cpp: renderer.storage "bricks" (sparse 8³ bricks with a one-voxel apron,
// kernels/shared/grid.h; issue 6, item 6) on the device, and "auto"'s fall-back to it.
//
// Expected values. A bricks lookup returns the buffer lookup's bits at every point
// (tests/unit/brick_grid_test.cpp on the host, tests/device/grid_storage_lookup_test.cpp on the
// device), and everything else in the kernels is the same code built with the same options but
// one -D, with FP_CONTRACT off (compat.h): so every algorithm renders the same pixels from bricks
// as from the buffer, bit for bit, not merely within a tolerance. White furnaces stay exactly 1
// (tests/render/analytic_scenes_test.cpp).
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "cl/device_allocation.h"
#include "core/input_error.h"
#include "render/device_grid.h"
#include "render/device_scene.h"
#include "render/kernel_features.h"
#include "render/render_common.h"
#include "render_fixture.h"
#include "volume/brick_grid.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

// grid_storage_test.cpp's scene, smaller: an area light behind the cloud, a point light beside
// it, a rotated box, background.
std::string cloudScene(const std::string& algorithm) {
  return R"({
  "materials": [
    {"name": "light", "type": "emitter", "albedo": [8, 8, 8]},
    {"name": "bulb", "type": "emitter", "albedo": [3, 2, 1]},
    {"name": "cloud", "type": "volume", "scattering": [1.0, 1.1, 1.2], "absorption": [0.02, 0.02, 0.02],
     "phaseFunction": "hg", "g": 0.7, "density": 4}
  ],
  "primitives": [
    {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 6], "scale": [8, 6, 1]}, "materialName": "light"},
    {"name": "point", "type": "point", "transform": {"position": [-2, 2, -1]}, "materialName": "bulb"},
    {"name": "box", "type": "volume", "transform": {"scale": [3, 3, 3], "rotation": [0, 15, 0]}, "materialName": "cloud"}
  ],
  "camera": {"position": [0, 0, -7], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 35},
  "renderer": {"resolution": [24, 18], "spp": 8, "bounces": 4, "seed": 5, "algorithm": ")" + algorithm +
         (algorithm == "raymarch" ? R"(", "raymarch": {"multipleScattering": "none"}},)" : R"("},)") + R"(
  "background": [0.1, 0.1, 0.2]
})";
}

DeviceInfo deviceOfType(const char* type, size_t maxAlloc) {
  DeviceInfo d;
  d.name = std::string("test ") + type;
  d.type = type;
  d.imageSupport = true;
  d.image3dMax[0] = d.image3dMax[1] = d.image3dMax[2] = 2048;
  d.maxAllocBytes = maxAlloc;
  return d;
}

DenseGrid cube(int n, float v) {
  DenseGrid g;
  g.nx = g.ny = g.nz = n;
  g.data.assign(g.voxelCount(), v);
  g.maxValue = v;
  g.source = "cube.vdb";
  return g;
}

TEST(BrickStorage, AutoKeepsTheDevicesChoiceWhenItHoldsTheGrid) {
  const DenseGrid g = cube(4, 1.0f);
  const DeviceInfo cpu = deviceOfType("CPU", 1 << 20), gpu = deviceOfType("GPU", 1 << 20);
  std::string why = "untouched";
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, cpu, &g, &why), GridStorage::Buffer);
  EXPECT_EQ(why, "untouched");
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, gpu, &g, &why), GridStorage::Image);
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, cpu, nullptr, &why), GridStorage::Buffer);
  EXPECT_EQ(why, "untouched");
  for (const GridStorage s : {GridStorage::Image, GridStorage::Buffer, GridStorage::Bricks}) {
    EXPECT_EQ(resolveGridStorage(s, cpu), s);
    EXPECT_EQ(chooseGridStorage(s, cpu, &g), s);
  }
  EXPECT_EQ(gridStorageBuildOption(GridStorage::Bricks), "-DGRID_STORAGE_BRICKS");
}

// Auto falls back to bricks when one buffer (CPU) or one image (GPU) cannot hold the grid, and
// says why; a storage asked for by name is never changed.
TEST(BrickStorage, AutoFallsBackToBricksWhenTheGridExceedsTheDevicesLimits) {
  const DenseGrid g = cube(20, 1.0f);  // 32000 bytes dense, 32016 as a buffer
  std::string why;
  const DeviceInfo cpu = deviceOfType("CPU", 32015);
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, cpu, &g, &why), GridStorage::Bricks);
  EXPECT_EQ(why, "cube.vdb: grid 20x20x20 as a float buffer needs 32016 bytes (31.27 KiB), over device 'test "
                 "CPU''s largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE) of 32015 bytes (31.26 KiB): "
                 "renderer.storage \"auto\" stores it as sparse 8^3 bricks (\"bricks\") instead of one buffer");
  EXPECT_EQ(chooseGridStorage(GridStorage::Buffer, cpu, &g), GridStorage::Buffer);
  DeviceInfo gpu = deviceOfType("GPU", 1 << 20);
  gpu.image3dMax[1] = 19;
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, gpu, &g, &why), GridStorage::Bricks);
  EXPECT_EQ(why, "cube.vdb: grid 20x20x20 exceeds the device's 3D image limit 2048x19x2048: renderer.storage "
                 "\"auto\" stores it as sparse 8^3 bricks (\"bricks\") instead of a 3D image");
  gpu = deviceOfType("GPU", 31999);
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, gpu, &g, &why), GridStorage::Bricks);
  EXPECT_EQ(why, "cube.vdb: grid 20x20x20 needs 32000 bytes, over the device's largest allocation of 31999 bytes: "
                 "renderer.storage \"auto\" stores it as sparse 8^3 bricks (\"bricks\") instead of a 3D image");
  gpu = deviceOfType("GPU", 1 << 20);
  gpu.imageSupport = false;  // no images: the buffer is auto's choice, and it fits
  EXPECT_EQ(chooseGridStorage(GridStorage::Auto, gpu, &g), GridStorage::Buffer);
}

// Every algorithm: the same bits from bricks as from the buffer, on a cloud whose outer bricks
// are empty (the cloud keeps kCloudMargin of each face at 0).
void expectBricksRenderTheBuffersPixels(const std::string& algorithm) {
  const DenseGrid cloud = makeCloud(40, 7);
  const BrickLayout layout = planBricks(cloud);
  ASSERT_LT(layout.occupiedCount(), layout.brickCount()) << "some bricks must be empty";
  Scene scene = sceneFromJson(cloudScene(algorithm));
  scene.renderer.storage = GridStorage::Buffer;
  const RenderResult buffer = renderAlgorithm(scene, &cloud);
  scene.renderer.storage = GridStorage::Bricks;
  const RenderResult bricks = renderAlgorithm(scene, &cloud);
  EXPECT_EQ(buffer.stats.storage, "buffer");
  EXPECT_EQ(bricks.stats.storage, "bricks");
  EXPECT_EQ(bricks.stats.status, 0u);
  EXPECT_EQ(bricks.stats.nanPixels, 0);
  EXPECT_TRUE(bricks.warnings.empty()) << "bricks asked for by name: nothing to warn about";
  ASSERT_EQ(bricks.image.rgb.size(), buffer.image.rgb.size());
  size_t differ = 0;
  double sum = 0;
  for (size_t i = 0; i < bricks.image.rgb.size(); ++i) {
    differ += bricks.image.rgb[i] != buffer.image.rgb[i];
    sum += buffer.image.rgb[i];
  }
  EXPECT_GT(sum, 0.0) << "a black image proves nothing";
  EXPECT_EQ(differ, 0u) << algorithm << ": values that differ from the buffer storage's";
}

TEST(BrickStorage, PathtraceRendersTheBuffersPixels) { expectBricksRenderTheBuffersPixels("pathtrace"); }
TEST(BrickStorage, RaymarchRendersTheBuffersPixels) { expectBricksRenderTheBuffersPixels("raymarch"); }
TEST(BrickStorage, LobeRendersTheBuffersPixels) { expectBricksRenderTheBuffersPixels("lobe"); }

// The render path of the fall-back: a device whose largest allocation holds the cloud's bricks but
// neither its buffer nor its image. Auto picks bricks, warns with the occupancy and size, reports them in the stats
// and renders the buffer storage's pixels.
TEST(BrickStorage, AutoRendersFromBricksOnADeviceTooSmallForTheBuffer) {
  const DenseGrid cloud = makeCloud(40, 7);
  const BrickLayout layout = planBricks(cloud);
  ASSERT_LT(layout.bufferBytes(), gridBufferBytes(cloud));
  ClRuntime small = runtime();
  small.selected.info.maxAllocBytes = layout.bufferBytes();  // under the dense bytes: no image, no buffer
  ASSERT_LT(layout.bufferBytes(), cloud.voxelCount() * sizeof(float));
  for (const char* algorithm : {"raymarch", "pathtrace"}) {
    SCOPED_TRACE(algorithm);
    Scene scene = sceneFromJson(cloudScene(algorithm));
    scene.renderer.spp = 2;
    scene.renderer.lightCache.resolution = 8;  // the same cache on both devices (auto would shrink it to fit)
    const RenderOptions o;  // the same options for both renders: the same majorant choices
    const RenderResult r = std::string(algorithm) == "pathtrace" ? renderPathtrace(small, scene, &cloud, o)
                                                                  : renderRealtime(small, scene, &cloud, 1, o);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("renderer.storage \"auto\" stores it as sparse 8^3 bricks"), std::string::npos)
        << r.warnings[0];
    EXPECT_NE(r.warnings[0].find(std::to_string(layout.occupiedCount()) + " of " +
                                 std::to_string(layout.brickCount()) + " bricks occupied"),
              std::string::npos)
        << r.warnings[0];
    EXPECT_NE(r.warnings[0].find(byteCount(layout.bufferBytes())), std::string::npos) << r.warnings[0];
    scene.renderer.storage = GridStorage::Buffer;
    const RenderResult b = std::string(algorithm) == "pathtrace" ? renderPathtrace(runtime(), scene, &cloud, o)
                                                                  : renderRealtime(runtime(), scene, &cloud, 1, o);
    EXPECT_EQ(r.image.rgb, b.image.rgb);
    if (std::string(algorithm) == "raymarch") {  // the path tracer's stats: see pathtrace_renderer.cpp
      EXPECT_EQ(r.stats.storage, "bricks");
      EXPECT_EQ(r.stats.bricks, layout.brickCount());
      EXPECT_EQ(r.stats.bricksOccupied, layout.occupiedCount());
      EXPECT_EQ(r.stats.gridBytes, layout.bufferBytes());
    }
  }
  // The same device asked for the buffer by name: the error names bricks as the way out.
  Scene scene = sceneFromJson(cloudScene("raymarch"));
  scene.renderer.storage = GridStorage::Buffer;
  try {
    renderRealtime(small, scene, &cloud, 1, {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("renderer.storage \"bricks\" (--storage bricks)"), std::string::npos)
        << e.what();
  }
}

// Bricks that do not fit either: refused before any allocation, naming the bytes, the occupancy,
// the grid's dense size and the device's limit.
TEST(BrickStorage, BricksOverTheLargestAllocationAreAClearError) {
  const DenseGrid g = cube(16, 0.5f);  // 8 bricks, all occupied
  const BrickLayout layout = planBricks(g);
  ClRuntime small = runtime();
  small.selected.info.maxAllocBytes = layout.bufferBytes() - 1;
  try {
    uploadGridBricks(small, g, layout);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "cube.vdb: grid: grid 16x16x16 as sparse bricks (8 of 8 8^3 bricks occupied; "
                                     "dense 16384 bytes (16.00 KiB)) needs " +
                                         byteCount(layout.bufferBytes()) + ", over the largest allocation of device '" +
                                         small.selected.info.name + "', " + byteCount(layout.bufferBytes() - 1));
  }
}

// The device memory a render reports (rethrowLaunchError's message) counts the bricks, not the
// dense grid.
TEST(BrickStorage, DeviceBytesCountTheBricks) {
  DenseGrid g = cube(32, 0.0f);
  g.data[0] = 1.0f;  // one brick of 64
  g.maxValue = 1.0f;
  Scene scene = sceneFromJson(cloudScene("raymarch"));
  scene.renderer.storage = GridStorage::Bricks;
  const DeviceSceneBuffers dev(runtime(), scene, &g);
  EXPECT_EQ(dev.storage, GridStorage::Bricks);
  EXPECT_EQ(dev.bricks, 64u);
  EXPECT_EQ(dev.bricksOccupied, 1u);
  EXPECT_EQ(dev.scene.gridBytes, planBricks(g).bufferBytes());
  EXPECT_NE(dev.buildOptions().find("-DGRID_STORAGE_BRICKS"), std::string::npos);
  EXPECT_LT(deviceSceneBytes(dev.scene), g.voxelCount() * sizeof(float));
}

}  // namespace
}  // namespace narval::test
