// The path tracer with the majorant grid (the default) and with the global majorant
// (RenderOptions::majorant, --majorant), through the real device path:
//   - white furnace on real grids: exactly 1.0 with either majorant;
//   - grid and global agree on a lit heterogeneous chromatic scene within noise (derivation below);
//   - each mode is deterministic (runs, local sizes);
//   - counters (RenderOptions::counters, -DCOUNTERS): empty cells cost no lookup; counting does not
//     change a pixel; the grid needs fewer tentative collisions per real one;
//   - the majorant resolution override reaches the kernels.
// Host-side tests of the same code: tests/unit/tracking_majorant_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "render/majorant_options.h"
#include "render/scene_upload.h"
#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"
#include "volume/majorant_grid.h"

namespace narval::test {
namespace {

RenderResult renderMajorant(const Scene& scene, const DenseGrid* grid, const std::string& majorant,
                            bool counters = false, int resolution = 0, int lx = 8, int ly = 8) {
  RenderOptions o;
  o.majorant = majorant;
  o.counters = counters;
  o.majorantResolution = resolution;
  o.localSizeX = lx;
  o.localSizeY = ly;
  return renderPathtrace(runtime(), scene, grid, o);
}

const char* const kModes[] = {"grid", "global"};

// ---- white furnace ------------------------------------------------------------------------------

// Albedo 1 (σa = 0), grey, no lights, background 1: every path escapes with throughput exactly 1 (the
// analogue walk never reweights), so every pixel is exactly 1 whatever the majorant, as long as it
// bounds σt (a walk that meets σt > σ̄ would still return 1 here, but flags STATUS_NEGATIVE_PDF:
// status 0 is asserted too). The bounce cap (1000) matters only after 1000 real collisions in a
// medium of optical thickness ≲ 10: never. Generated cloud (32³) and the Disney cloud (real data,
// skipped when absent), the latter also at majorant resolution 64 (the override).
std::string furnaceScene() {
  return R"({
    "materials": [
      {"name": "white", "type": "volume", "scattering": [1, 1, 1], "absorption": [0, 0, 0],
       "phaseFunction": "hg", "g": 0.6, "density": 3}
    ],
    "primitives": [
      {"name": "box", "type": "volume", "transform": {"scale": [2, 1.5, 1], "rotation": [20, 30, 0]},
       "materialName": "white"}
    ],
    "camera": {"position": [0, 0, -4], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 40},
    "renderer": {"resolution": [24, 16], "spp": 32, "bounces": 1000},
    "background": [1, 1, 1]
  })";
}

void expectFurnaceOne(const DenseGrid& cloud, const std::string& majorant, int resolution = 0) {
  const RenderResult r = renderMajorant(sceneFromJson(furnaceScene()), &cloud, majorant, false, resolution);
  size_t wrong = 0;
  for (float v : r.image.rgb) wrong += v != 1.0f;
  EXPECT_EQ(wrong, 0u) << majorant << ", of " << r.image.rgb.size() << " values";
  EXPECT_EQ(r.stats.status, 0u) << majorant;
  EXPECT_EQ(r.stats.majorant, majorant);
}

TEST(MajorantRender, WhiteFurnaceOnGeneratedCloudIsExactlyOneWithEitherMajorant) {
  const DenseGrid cloud = makeCloud(32, 7);
  for (const char* m : kModes) expectFurnaceOne(cloud, m);
}

TEST(MajorantRender, WhiteFurnaceOnDisneyCloudIsExactlyOneWithTheMajorantGrid) {
  const std::string path = realDataPath("wdas_cloud_sixteenth.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  const DenseGrid cloud = loadGrid(path, "density");
  expectFurnaceOne(cloud, "grid");
  expectFurnaceOne(cloud, "grid", 64);
}

// ---- grid and global agree ----------------------------------------------------------------------

// A lit chromatic cloud (spectral tracking, NEE with ratio-tracked shadow rays to a rectangle and a
// point light, background), rendered with each majorant. Both estimate the same pixel values
// (unbiased), so the per-pixel difference D_i = grid_i − global_i has mean 0 for every pixel i, and
// the D_i are independent across pixels (each pixel has its own random streams). By the central limit
// theorem over P = 32·24 = 768 pixels (512 spp each), z = mean(D) / (sd(D)/√P) is standard normal: |z| < 4 per
// channel (false alarm 6.3e-5 each, 1.9e-4 for three). The two renders share their streams' keys,
// so their first draws (camera jitter) coincide: that correlation lowers var(D_i), and sd(D) is
// measured from the D_i themselves, so the bound stays exact. Control: the global render with the
// density multiplier 10% higher differs by |z| > 4 in every channel, so the test sees a change of
// that size. The same check is done for the image mean's level: both within 5% of each other.
const std::string kLitCloud = litCloudJson(R"({"resolution": [32, 24], "spp": 32, "bounces": 6, "seed": 5})",
                                           "[1.0, 1.3, 1.6]", "[0.05, 0.02, 0.02]");

// z of the mean per-pixel difference a − b, channel c.
double differenceZ(const ImageRGB& a, const ImageRGB& b, int c) {
  MeanAccumulator acc;
  for (size_t i = 0, n = size_t(a.width) * a.height; i < n; ++i) acc.add(double(a.rgb[i * 3 + c]) - b.rgb[i * 3 + c]);
  const MeanSe r = acc.result();
  return r.mean / r.se;
}

TEST(MajorantRender, GridAndGlobalAgreeWithinNoise) {
  const DenseGrid cloud = makeCloud(32, 5);
  Scene scene = sceneFromJson(kLitCloud);
  scene.renderer.spp = 512;
  const RenderResult grid = renderMajorant(scene, &cloud, "grid");
  const RenderResult global = renderMajorant(scene, &cloud, "global");
  Scene denser = scene;
  denser.materials[2].density *= 1.1f;
  const RenderResult control = renderMajorant(denser, &cloud, "global");
  EXPECT_EQ(grid.stats.status, 0u);
  EXPECT_EQ(global.stats.status, 0u);
  for (int c = 0; c < 3; ++c) {
    const double z = differenceZ(grid.image, global.image, c), zc = differenceZ(grid.image, control.image, c);
    std::printf("[ majorant ] channel %d: z(grid - global) = %.2f, control z(grid - global at 1.1 density) = %.2f\n",
                c, z, zc);
    EXPECT_LT(std::fabs(z), 4.0) << "channel " << c;
    EXPECT_GT(std::fabs(zc), 4.0) << "channel " << c << ": control";
    const double mg = channelStats(grid.image, c).mean, mo = channelStats(global.image, c).mean;
    EXPECT_NEAR(mg, mo, 0.05 * mo) << "channel " << c;
    // The same per 8x8 tile (the mean difference above would let a mirrored image pass): within 4.5
    // standard errors in each of the 12 tiles (a false alarm about 1 in 4000 over the tiles and
    // channels), plus 1e-5 of the tile's level: where the cloud is thin both renders draw the same
    // paths and differ only by float rounding (a tile's pixels then agree to ~1e-6, all of one
    // sign, and their spread says nothing about noise).
    for (int ty = 0; ty < grid.image.height / 8; ++ty)
      for (int tx = 0; tx < grid.image.width / 8; ++tx) {
        MeanAccumulator acc;
        double level = 0;
        for (int y = ty * 8; y < ty * 8 + 8; ++y)
          for (int x = tx * 8; x < tx * 8 + 8; ++x) {
            acc.add(double(grid.image.pixel(x, y)[c]) - global.image.pixel(x, y)[c]);
            level += global.image.pixel(x, y)[c] / 64.0;
          }
        const MeanSe t = acc.result();
        EXPECT_LE(std::fabs(t.mean), 4.5 * t.se + 1e-5 * level) << "channel " << c << " tile " << tx << "," << ty;
      }
  }
}

// Each mode is deterministic: bitwise the same image on a second run and at other work-group shapes.
TEST(MajorantRender, EachModeIsDeterministic) {
  const DenseGrid cloud = makeCloud(24, 3);
  const Scene scene = sceneFromJson(kLitCloud);
  for (const char* m : kModes) {
    const RenderResult a = renderMajorant(scene, &cloud, m);
    const RenderResult b = renderMajorant(scene, &cloud, m);
    const RenderResult c = renderMajorant(scene, &cloud, m, false, 0, 3, 5);
    EXPECT_EQ(a.image.rgb, b.image.rgb) << m;
    EXPECT_EQ(a.image.rgb, c.image.rgb) << m;
  }
}

// ---- counters -----------------------------------------------------------------------------------

// A 16³ grid with density only in voxels x >= 12 (the box's right quarter); majorant cells 16³
// (chooseMajorantResolution at 16): by the support rule the cells with x index <= 10 are empty.
// Camera aimed at the box's left part (x index 2.2–5.8 over the image: vfov 5° at distance 5 of a
// 2-unit box), no lights, background 1: every path crosses empty cells only. Grid: no tentative
// collision, no density lookup, image exactly 1. Global (control): σ̄ = σt·max ρ over the whole box,
// tentative collisions everywhere (each a lookup), all null: the same image, lookups > 0.
TEST(MajorantRender, EmptyCellsMakeNoLookups) {
  const DenseGrid grid = xSlabGrid(16, 12, 16);
  const Scene scene = sceneFromJson(R"({
    "materials": [{"name": "m", "type": "volume", "scattering": [2, 2, 2], "absorption": [1, 1, 1],
                   "phaseFunction": "isotropic", "density": 1}],
    "primitives": [{"name": "box", "type": "volume", "transform": {"scale": [2, 2, 2]}, "materialName": "m"}],
    "camera": {"position": [-0.5, 0, -5], "lookAt": [-0.5, 0, 0], "up": [0, 1, 0], "vfov": 5},
    "renderer": {"resolution": [8, 8], "spp": 16, "bounces": 4},
    "background": [1, 1, 1]
  })");
  const DeviceScene ds = buildDeviceScene(scene, &grid);
  ASSERT_EQ(ds.params.medium.majorant_grid.cells_x, 16);
  for (const char* m : kModes) {
    const RenderResult r = renderMajorant(scene, &grid, m, true, 16);
    size_t wrong = 0;
    for (float v : r.image.rgb) wrong += v != 1.0f;
    EXPECT_EQ(wrong, 0u) << m;
    EXPECT_TRUE(r.stats.counters.on);
    EXPECT_EQ(r.stats.counters.real, 0u) << m;
    if (std::string(m) == "grid") {
      EXPECT_EQ(r.stats.counters.tentative, 0u);
      EXPECT_EQ(r.stats.counters.densityLookups, 0u);
    } else {
      EXPECT_GT(r.stats.counters.tentative, 1000u);  // σ̄·2 = 6 per path on average, 1024 paths
      EXPECT_EQ(r.stats.counters.densityLookups, r.stats.counters.tentative);  // no lights: no shadow rays
    }
  }
}

// Counting changes no pixel (the counts are side effects in private integers), and on a cloud the
// grid makes fewer tentative collisions per real one than the global majorant, with the same
// real-collision count up to noise. Without counters the stats say so and hold zeros.
TEST(MajorantRender, CountersChangeNoPixelAndShowTheGridsSaving) {
  const DenseGrid cloud = makeCloud(32, 5);
  const Scene scene = sceneFromJson(kLitCloud);
  double perReal[2] = {0, 0};
  for (int i = 0; i < 2; ++i) {
    const RenderResult plain = renderMajorant(scene, &cloud, kModes[i]);
    const RenderResult counted = renderMajorant(scene, &cloud, kModes[i], true);
    EXPECT_EQ(plain.image.rgb, counted.image.rgb) << kModes[i];
    EXPECT_FALSE(plain.stats.counters.on);
    EXPECT_EQ(plain.stats.counters.tentative + plain.stats.counters.real + plain.stats.counters.densityLookups, 0u);
    const RenderStats& s = counted.stats;
    ASSERT_GT(s.counters.real, 0u);
    EXPECT_GE(s.counters.tentative, s.counters.real);
    EXPECT_GT(s.counters.densityLookups, s.counters.tentative);  // shadow rays look up density too
    perReal[i] = double(s.counters.tentative) / double(s.counters.real);
    std::printf("[ majorant ] %s: %llu tentative, %llu real (%.2f per real), %llu lookups\n", kModes[i],
                (unsigned long long)s.counters.tentative, (unsigned long long)s.counters.real, perReal[i],
                (unsigned long long)s.counters.densityLookups);
  }
  EXPECT_LT(perReal[0], perReal[1]);
}

// RenderOptions::majorantResolution reaches the kernels: the stats report the cells
// chooseMajorantResolution gives for it (0: the path tracer's automatic choice for the device,
// pathtraceMajorantResolution), and the pixels stay exact in the furnace (above). Here on the
// generated cloud (32³): 8 and 24 besides the automatic one. "auto" resolves by device type.
TEST(MajorantRender, ResolutionOverride) {
  const DenseGrid cloud = makeCloud(32, 5);
  Scene scene = sceneFromJson(kLitCloud);
  scene.renderer.spp = 1;
  const DeviceInfo& device = runtime().selected.info;
  for (const int res : {0, 8, 24}) {
    const RenderResult r = renderMajorant(scene, &cloud, "grid", false, res);
    const int target = res == 0 ? pathtraceMajorantResolution(device) : res;
    const std::array<int, 3> want = chooseMajorantResolution(32, 32, 32, target);
    EXPECT_EQ(r.stats.majorantCells[0], want[0]) << res;
    EXPECT_EQ(r.stats.majorantCells[1], want[1]) << res;
    EXPECT_EQ(r.stats.majorantCells[2], want[2]) << res;
  }
  EXPECT_EQ(renderMajorant(scene, &cloud, "auto").stats.majorant, device.type == "GPU" ? "global" : "grid");
}

}  // namespace
}  // namespace narval::test
