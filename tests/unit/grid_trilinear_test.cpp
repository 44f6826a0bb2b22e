// grid_trilinear (kernels/shared/grid.h): the filter both grid storages share, the buffer storage
// on the device and every host caller (grid_density). Analytic values: a field linear in x, y, z is
// reproduced exactly between the voxel centres, the field fades linearly to 0 over the half voxel
// outside the outermost centres (CLK_ADDRESS_CLAMP, border colour 0), and points half a voxel or
// more outside the grid, far away or not numbers read 0. tests/unit/tracking_test.cpp checks
// grid_density by hand on a 2x2x2 grid; tests/device/grid_storage_lookup_test.cpp compares the
// device's image and buffer lookups with this function.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "shared/grid.h"
#include "unit/host_context.h"

namespace {

constexpr double kEps = 1.0 / (1 << 24);

struct Grid {
  int nx, ny, nz;
  std::vector<float> v;
  float at(int x, int y, int z) const {
    return x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz ? 0.0f : v[size_t(x + nx * (y + ny * z))];
  }
  float lookUp(float x, float y, float z) const { return grid_trilinear(v.data(), nx, ny, nz, vec3_make(x, y, z)); }
};

// v(i, j, k) = 3 + 2i + 5j + 7k: small integers, so the field and every lerp of it at points on a
// 1/8 lattice are exact in float.
Grid linearRamp(int nx, int ny, int nz) {
  Grid g{nx, ny, nz, {}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) g.v.push_back(3.0f + 2.0f * i + 5.0f * j + 7.0f * k);
  return g;
}
double ramp(double x, double y, double z) { return 3 + 2 * (x - 0.5) + 5 * (y - 0.5) + 7 * (z - 0.5); }

// Exact on the 1/8 lattice inside the hull of the centres [0.5, n - 0.5]: weights are multiples of
// 1/8, values integers below 2^10, so no product or sum rounds.
TEST(GridTrilinear, LinearRampIsReproducedExactlyBetweenTheCentres) {
  const Grid g = linearRamp(6, 5, 4);
  int n = 0;
  for (float z = 0.5f; z <= g.nz - 0.5f; z += 0.375f)
    for (float y = 0.5f; y <= g.ny - 0.5f; y += 0.625f)
      for (float x = 0.5f; x <= g.nx - 0.5f; x += 0.125f, ++n)
        ASSERT_EQ(g.lookUp(x, y, z), float(ramp(x, y, z))) << x << ", " << y << ", " << z;
  EXPECT_GT(n, 1000);
}

// At arbitrary points the nested lerps round at most twice per level: within 6 ε of the exact
// value (all terms non-negative); 8 ε allowed.
TEST(GridTrilinear, LinearRampAtRandomPointsWithinRounding) {
  const Grid g = linearRamp(9, 3, 5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> ux(0.5f, g.nx - 0.5f), uy(0.5f, g.ny - 0.5f), uz(0.5f, g.nz - 0.5f);
  for (int n = 0; n < 20000; ++n) {
    const float x = ux(rng), y = uy(rng), z = uz(rng);
    const double exact = ramp(x, y, z);
    ASSERT_NEAR(g.lookUp(x, y, z), exact, 8 * kEps * exact) << x << ", " << y << ", " << z;
  }
}

// Border colour 0: between the grid's face and the outermost centre the field is the lerp between
// 0 (the voxel outside) and the edge voxel, so along x at the centre of row (j, k):
// density(x) = (x + 0.5)·v(0, j, k) for x in [-0.5, 0.5], (nx + 0.5 - x)·v(nx-1, j, k) for x in
// [nx - 0.5, nx + 0.5], and 0 beyond. (CLK_ADDRESS_CLAMP_TO_EDGE would hold v(0, j, k) instead.)
TEST(GridTrilinear, FadesLinearlyToZeroOverTheOuterHalfVoxel) {
  const Grid g = linearRamp(4, 3, 2);
  const float y = 1.5f, z = 0.5f;  // row j = 1, k = 0
  const float first = g.at(0, 1, 0), last = g.at(3, 1, 0);
  for (float t = 0.0f; t <= 1.0f; t += 0.125f) {
    EXPECT_EQ(g.lookUp(-0.5f + t, y, z), t * first) << "t = " << t;
    EXPECT_EQ(g.lookUp(g.nx + 0.5f - t, y, z), t * last) << "t = " << t;
  }
  for (float x : {-0.5f, -0.75f, -1.0f, -3.0f, g.nx + 0.5f, g.nx + 0.9f, g.nx + 40.0f})
    EXPECT_EQ(g.lookUp(x, y, z), 0.0f) << x;
  // The same on y and z, and at a corner of the box (one eighth of the corner voxel).
  EXPECT_EQ(g.lookUp(0.5f, -0.5f, 0.5f), 0.0f);
  EXPECT_EQ(g.lookUp(0.5f, 0.0f, 0.5f), 0.5f * g.at(0, 0, 0));
  EXPECT_EQ(g.lookUp(0.5f, 0.5f, g.nz + 0.0f), 0.5f * g.at(0, 0, g.nz - 1));
  EXPECT_EQ(g.lookUp(0.0f, 0.0f, 0.0f), 0.125f * g.at(0, 0, 0));
}

// A one-voxel grid is a tent: v at the centre, v/2 on each face, 0 half a voxel outside.
TEST(GridTrilinear, OneVoxelGridIsATent) {
  const Grid g{1, 1, 1, {4.0f}};
  EXPECT_EQ(g.lookUp(0.5f, 0.5f, 0.5f), 4.0f);
  EXPECT_EQ(g.lookUp(0.0f, 0.5f, 0.5f), 2.0f);
  EXPECT_EQ(g.lookUp(1.0f, 1.0f, 0.5f), 1.0f);
  EXPECT_EQ(g.lookUp(1.0f, 1.0f, 1.0f), 0.5f);
  EXPECT_EQ(g.lookUp(1.5f, 0.5f, 0.5f), 0.0f);
}

// The coordinates are clamped to [-1, 1e7] before anything else: huge, infinite and NaN
// coordinates read 0 (and never convert an out-of-range float to int).
TEST(GridTrilinear, FarInfiniteAndNanCoordinatesReadZero) {
  const Grid g = linearRamp(3, 3, 3);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (float far : {1e7f, 1e10f, 1e38f, inf, -1e10f, -inf, nan}) {
    EXPECT_EQ(g.lookUp(far, 1.5f, 1.5f), 0.0f) << far;
    EXPECT_EQ(g.lookUp(1.5f, far, 1.5f), 0.0f) << far;
    EXPECT_EQ(g.lookUp(1.5f, 1.5f, far), 0.0f) << far;
  }
}

// Against an independent reference: the eight corners summed in double with explicit bounds
// checks, at random points over the grid and 1.5 voxels around it, on a grid with non-zero faces.
TEST(GridTrilinear, MatchesADoublePrecisionReferenceEverywhere) {
  Grid g{7, 4, 3, {}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> value(0.0f, 10.0f);
  for (int i = 0; i < g.nx * g.ny * g.nz; ++i) g.v.push_back(value(rng));
  std::uniform_real_distribution<float> ux(-1.5f, g.nx + 1.5f), uy(-1.5f, g.ny + 1.5f), uz(-1.5f, g.nz + 1.5f);
  for (int n = 0; n < 20000; ++n) {
    const float x = ux(rng), y = uy(rng), z = uz(rng);
    // The shift to texel centres is float arithmetic in both storages (and in the OpenCL spec's
    // sampler): start from the same rounded u = p - 0.5, so the bound below is about the lerps.
    const double fx = x - 0.5f, fy = y - 0.5f, fz = z - 0.5f;
    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy)), z0 = int(std::floor(fz));
    const double ax = fx - x0, ay = fy - y0, az = fz - z0;
    double ref = 0;
    for (int k = 0; k < 8; ++k) {
      const int dx = k & 1, dy = k >> 1 & 1, dz = k >> 2;
      ref += (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay) * (dz ? az : 1 - az) * g.at(x0 + dx, y0 + dy, z0 + dz);
    }
    // 6 ε for the lerps plus the float weights' own rounding (1 - a: 1 ε per axis).
    ASSERT_NEAR(g.lookUp(x, y, z), ref, 10 * kEps * ref + 1e-30) << x << ", " << y << ", " << z;
  }
}

// grid_density on the host is grid_trilinear on the view's array, bit for bit.
TEST(GridTrilinear, HostGridDensityIsTheSharedFilter) {
  const Grid g = linearRamp(5, 4, 3);
  const grid_view view = {g.v.data(), g.nx, g.ny, g.nz, nullptr};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 6.0f);
  for (int n = 0; n < 1000; ++n) {
    const vec3 p = vec3_make(u(rng), u(rng), u(rng));
    ASSERT_EQ(grid_view_density(&view, p), grid_trilinear(g.v.data(), g.nx, g.ny, g.nz, p));
  }
}

}  // namespace
