// The light-transmittance cache's math on the host (kernels/shared/light_cache.h, the code the
// device runs): node values, lookups against analytic column densities, and the derived bounds.
//
// Scenes: a homogeneous medium of density 1 in the unit cube [-0.5, 0.5]³ (σt = 2 per channel for
// the optical depths). For constant density the midpoint rule is exact, so a node holds the length
// of its shadow ray inside the box up to float rounding, and the only error of a lookup is the
// trilinear interpolation between nodes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/device_light_cache.h"
#include "render/scene_upload.h"
#include "scene/scene.h"
#include "shared/light_cache.h"
#include "unit/host_context.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

std::string boxWithPointLight(const std::string& lightPos) {
  return R"({
    "materials": [
      {"name": "bulb", "type": "emitter", "albedo": [5, 5, 5]},
      {"name": "fog", "type": "volume", "scattering": [1.5, 1.5, 1.5], "absorption": [0.5, 0.5, 0.5], "density": 1}
    ],
    "primitives": [
      {"name": "point", "type": "point", "transform": {"position": )" + lightPos + R"(}, "materialName": "bulb"},
      {"name": "box", "type": "volume", "transform": {"scale": [1, 1, 1]}, "materialName": "fog"}
    ],
    "camera": {"position": [0, 0, -4], "lookAt": [0, 0, 0], "vfov": 30},
    "renderer": {"resolution": [4, 4], "algorithm": "raymarch"}
  })";
}

struct Cache {
  DeviceScene ds;
  grid_view grid{};
  march_params march{};
  node_grid_params layout{};
  std::vector<float> slabs;
};

// Shadow rays a frame reads per light: more than any cache here has nodes (lightCacheLayout).
constexpr double kManyRays = 1e12;

// The cache of `json`'s scene at `cells` cells per axis (a cube), built with `steps` samples per node.
Cache buildCache(const std::string& json, int cells, int steps = 16, const DenseGrid* density = nullptr) {
  Cache c;
  c.ds = buildDeviceScene(parseScene(json, "light_cache_test.json"), density);
  c.grid = grid_view{density ? density->data.data() : nullptr, density ? density->nx : 1, density ? density->ny : 1,
                     density ? density->nz : 1, c.ds.majorants.data()};
  c.march.shadow_steps = steps;
  c.layout = lightCacheLayout(c.ds, cells, kManyRays);
  c.slabs = buildLightCacheOnHost(c.ds, &c.grid, c.march, c.layout);
  return c;
}

// The cached column density from world point x to light 0.
double cachedColumn(const Cache& c, const double x[3], uint* status) {
  const vec3 p = vec3_make(float(x[0]), float(x[1]), float(x[2]));
  light_point_view v;
  EXPECT_TRUE(light_view_from(&c.ds.lights[0], p, &v));
  return light_cache_column(&c.ds.params.medium, &c.layout, c.slabs.data(), 0, p, v.dir, v.dist, status);
}

// Length of the segment a → b inside the unit cube [-0.5, 0.5]³ (slab method, double).
double lengthInside(const double a[3], const double b[3]) {
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    const double d = b[k] - a[k];
    if (d == 0) {
      if (a[k] < -0.5 || a[k] > 0.5) return 0;
      continue;
    }
    double u = (-0.5 - a[k]) / d, v = (0.5 - a[k]) / d;
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u);
    t1 = std::min(t1, v);
  }
  if (t1 <= t0) return 0;
  const double len = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
  return (t1 - t0) * len;
}

TEST(LightCache, LayoutFollowsTheBoxsLongestWorldAxis) {
  // A 4 x 1 x 2 box: 32 cells along x, 8 along y, 16 along z; nodes = cells + 1.
  std::string json = boxWithPointLight("[0, 0, 3]");
  json.replace(json.find("\"scale\": [1, 1, 1]"), 18, "\"scale\": [4, 1, 2]");
  const DeviceScene ds = buildDeviceScene(parseScene(json, "layout.json"), nullptr);
  const node_grid_params c = lightCacheLayout(ds, 32, kManyRays);
  EXPECT_EQ(c.nx, 33);
  EXPECT_EQ(c.ny, 9);
  EXPECT_EQ(c.nz, 17);
  EXPECT_EQ(lightCacheLayout(ds, 0, kManyRays).nx, 0);  // off
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, kManyRays).nx, kLightCacheAutoResolution + 1);
  // auto halves its resolution until the slabs fit the device's largest allocation: at 64 cells
  // 65·17·33 nodes · 4 bytes = 145860 bytes for the one light; a 100000-byte device gets 32 cells
  // (33·9·17 nodes, 20196 bytes). An explicit resolution is kept (its allocation then fails with
  // a message naming the key).
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, kManyRays, 145860).nx, 65);
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, kManyRays, 100000).nx, 33);
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, kManyRays, 100000).ny, 9);
  EXPECT_EQ(lightCacheLayout(ds, 64, kManyRays, 100000).nx, 65);
  // auto is off where a frame reads fewer shadows per light than the cache has nodes (65·17·33 =
  // 36465 at 64 cells; 5049 at the 32 cells a 100000-byte device gets); an explicit one stays.
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, 36465).nx, 65);
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, 36464).nx, 0);
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, 5049, 100000).nx, 33);
  EXPECT_EQ(lightCacheLayout(ds, kLightCacheAuto, 5048, 100000).nx, 0);
  EXPECT_EQ(lightCacheLayout(ds, 64, 1).nx, 65);
  // The corner nodes sit on the box's corners in world space.
  const vec3 far = affine_point(c.index_to_world, node_grid_point(&c, vec3_from4(ds.params.medium.dims),
                                                                         node_grid_count(&c) - 1));
  EXPECT_NEAR(far.x, 2.0f, 1e-6f);
  EXPECT_NEAR(far.y, 0.5f, 1e-6f);
  EXPECT_NEAR(far.z, 1.0f, 1e-6f);
}

// Light outside, above the box's top face at (0, 0, L), L = 3: every shadow ray leaves through the
// top face (the light is over the face's footprint and the box is convex), so by similar triangles
//   C(x) = (0.5 − z)·|light − x|/(L − z) = u·sqrt(1 + ρ²/b²),  u = 0.5 − z ∈ [0, 1], b = L − z ≥ 2.5,
// ρ² = x² + y² ≤ 0.5, one smooth formula over the whole box. Its second derivatives:
//   C_xx = u·(1 + y²/b²)/(b²(1 + ρ²/b²)^{3/2}) ≤ 1/b² ≤ 0.16, likewise C_yy;
//   C_zz = 2f' + u·f'' with f = sqrt(1 + ρ²/b²) as a function of b: |f'| ≤ ρ²/b³, |f''| ≤ 3ρ²/b⁴,
//   so |C_zz| ≤ 2·0.5/2.5³ + 3·0.5/2.5⁴ = 0.0640 + 0.0384 = 0.1024.
// Trilinear interpolation of a C² field errs by at most (h²/8)·(max|C_xx| + max|C_yy| + max|C_zz|)
// with h the node spacing (1/cells here): τ = σt·C, σt = 2. Plus float rounding of the node sums
// (16 terms) and of the lookup: 1e-5 absolute.
TEST(LightCache, PointLightOutsideMatchesTheChordInsideTheBoxWithinTheTrilinearBound) {
  const double light[3] = {0, 0, 3};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  double previous = 1e9;
  for (int cells : {4, 8, 16}) {
    const Cache c = buildCache(boxWithPointLight("[0, 0, 3]"), cells);
    const double h = 1.0 / cells, bound = 2.0 * h * h / 8 * (0.16 + 0.16 + 0.1024) + 1e-5;
    // The nodes themselves hold the chord, to float rounding.
    const vec3 dims = vec3_from4(c.ds.params.medium.dims);
    for (int n = 0; n < node_grid_count(&c.layout); ++n) {
      const vec3 w = affine_point(c.layout.index_to_world,
                                  node_grid_point(&c.layout, dims, n));
      const double x[3] = {w.x, w.y, w.z};
      ASSERT_NEAR(c.slabs[size_t(n)], lengthInside(x, light), 2e-6) << "node " << n;
    }
    double worst = 0;
    uint status = 0;
    for (int i = 0; i < 2000; ++i) {
      const double x[3] = {u(rng), u(rng), u(rng)};
      const double err = 2.0 * std::fabs(cachedColumn(c, x, &status) - lengthInside(x, light));
      worst = std::max(worst, err);
      ASSERT_LE(err, bound) << cells << " cells at " << x[0] << "," << x[1] << "," << x[2];
    }
    EXPECT_EQ(status, 0u);
    std::printf("[ light cache ] light outside, %d cells: max |dtau| %.3g (bound %.3g)\n", cells, worst, bound);
    EXPECT_LT(worst, previous);  // falls with the resolution
    previous = worst;
  }
}

// Points outside the box read the face where their shadow ray enters it (density is 0 outside),
// and a shadow ray that misses the box has column 0 exactly: no extrapolation.
TEST(LightCache, PointsOutsideTheBoxReadWhereTheirShadowRayEntersIt) {
  const double light[3] = {0, 0, 3};
  const Cache c = buildCache(boxWithPointLight("[0, 0, 3]"), 8);
  const double below[3] = {0.1, -0.2, -2.0};  // the ray to the light crosses the whole box
  uint status = 0;
  EXPECT_NEAR(cachedColumn(c, below, &status), lengthInside(below, light), 2.0 * (1.0 / 64) / 8 * 0.4224 + 1e-5);
  EXPECT_GT(lengthInside(below, light), 0.99);
  const double beside[3] = {3.0, 0.0, 0.0};  // its ray to the light misses the box
  EXPECT_EQ(cachedColumn(c, beside, &status), 0.0);
  EXPECT_EQ(status, 0u);
}

// Light inside the medium: C(x) = |x − light| has a kink at the light, so the C² bound does not
// apply; C is 1-Lipschitz and the interpolant is a convex combination of corner values, each within
// |corner − x| ≤ the cell diagonal √3·h of C(x): |error| ≤ √3·h (+ rounding).
TEST(LightCache, LightInsideTheMediumStaysWithinTheLipschitzBound) {
  const double light[3] = {0.05, -0.1, 0.13};
  const Cache c = buildCache(boxWithPointLight("[0.05, -0.1, 0.13]"), 8);
  const double h = 1.0 / 8, bound = std::sqrt(3.0) * h + 1e-5;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  double worst = 0, worstNear = 0;
  uint status = 0;
  for (int i = 0; i < 2000; ++i) {
    const double x[3] = {u(rng), u(rng), u(rng)};
    const double d = std::sqrt((x[0] - light[0]) * (x[0] - light[0]) + (x[1] - light[1]) * (x[1] - light[1]) +
                               (x[2] - light[2]) * (x[2] - light[2]));
    const double err = std::fabs(cachedColumn(c, x, &status) - d);
    ASSERT_LE(err, bound) << x[0] << "," << x[1] << "," << x[2];
    worst = std::max(worst, err);
    if (d < 2 * h) worstNear = std::max(worstNear, err);
  }
  EXPECT_EQ(status, 0u);
  std::printf("[ light cache ] light inside, 8 cells: max |dC| %.3g (bound %.3g), within 2h of it %.3g\n", worst,
              bound, worstNear);
}

// A light exactly on a node: that node holds 0 (nothing lies between) and a lookup there reads ~0;
// its neighbours hold their distance h.
TEST(LightCache, LightOnANodeGivesZeroThere) {
  // 8 cells over [-0.5, 0.5]: node (4, 4, 4) is the centre, (0, 0, 0) the corner.
  for (const char* pos : {"[0, 0, 0]", "[-0.5, -0.5, -0.5]"}) {
    SCOPED_TRACE(pos);
    const Cache c = buildCache(boxWithPointLight(pos), 8);
    const node_grid_params& lc = c.layout;
    const int centre = std::string(pos) == "[0, 0, 0]" ? 4 : 0;
    const int node = centre + lc.nx * (centre + lc.ny * centre);
    EXPECT_EQ(c.slabs[size_t(node)], 0.0f);
    if (centre == 4) EXPECT_NEAR(c.slabs[size_t(node + 1)], 1.0 / 8, 1e-6);  // (the corner's run along edges)
    const vec3 dims = vec3_from4(c.ds.params.medium.dims);
    const float at = light_cache_column_at(&lc, c.slabs.data(), 0, dims, node_grid_point(&lc, dims, node));
    EXPECT_NEAR(at, 0.0f, 1e-6f);
  }
}

// An empty grid: every node holds 0 exactly, so every cached transmittance is exp(−0) = 1 exactly.
TEST(LightCache, EmptyGridGivesTransmittanceOneExactly) {
  DenseGrid zeros;
  zeros.nx = zeros.ny = zeros.nz = 8;
  zeros.data.assign(512, 0.0f);
  const Cache c = buildCache(boxWithPointLight("[0.2, 0.3, 2]"), 16, 10, &zeros);
  for (float v : c.slabs) ASSERT_EQ(v, 0.0f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  for (int i = 0; i < 200; ++i) {
    const vec3 p = vec3_make(float(u(rng)), float(u(rng)), float(u(rng)));
    light_point_view v;
    uint status = 0;
    ASSERT_TRUE(light_view_from(&c.ds.lights[0], p, &v));
    const vec3 tr = vec3_exp_neg(
        light_cache_optical_depth(narval::test::sceneContext(&c.ds.params, c.ds.lights.data(), &c.grid, &status),
                                  &c.march, &c.layout, c.slabs.data(), 0, p, v.dir, v.dist, vec3_make(0, 0, 1)));
    ASSERT_EQ(tr.x, 1.0f);
    ASSERT_EQ(tr.y, 1.0f);
    ASSERT_EQ(tr.z, 1.0f);
  }
}

}  // namespace
}  // namespace narval::test
