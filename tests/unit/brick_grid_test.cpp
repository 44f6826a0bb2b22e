// brick_grid_test.cpp: the sparse brick storage on the host (issue 6, item 6): building the index
// table and pool from a dense grid (host/volume/brick_grid.h) and grid_bricks_trilinear
// (kernels/shared/grid.h), which must return grid_trilinear's value bit for bit at every point: the
// same eight corner values (the apron carries each brick's + neighbours) and the same weights,
// summed by the same grid_trilinear_combine. Points: random over the grid and a voxel and a half
// around it, every brick face (x = 8k) and the planes either side of it, voxel centres and faces,
// the grid's border, far, infinite and NaN coordinates. tests/device/grid_storage_lookup_test.cpp
// compares the device's bricks with the host.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "shared/grid.h"
#include "volume/brick_grid.h"
#include "volume/dense_grid.h"

namespace narval {
namespace {

DenseGrid zeros(int nx, int ny, int nz) {
  DenseGrid g;
  g.nx = nx;
  g.ny = ny;
  g.nz = nz;
  g.data.assign(g.voxelCount(), 0.0f);
  return g;
}

DenseGrid randomGrid(int nx, int ny, int nz, unsigned seed, float zeroShare) {
  DenseGrid g = zeros(nx, ny, nz);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), v(0.0f, 5.0f);
  for (float& x : g.data) x = u(rng) < zeroShare ? 0.0f : v(rng);
  return g;
}

// The stored brick buffer read as the kernel reads it.
struct Bricks {
  std::vector<float> buffer;
  const uint* table() const { return reinterpret_cast<const uint*>(buffer.data()) + GRID_BRICKS_HEADER; }
  const float* pool() const {
    int32_t offset;
    std::memcpy(&offset, &buffer[3], sizeof offset);
    return buffer.data() + offset;
  }
};

float denseLookup(const DenseGrid& g, vec3 p) { return grid_trilinear(g.data.data(), g.nx, g.ny, g.nz, p); }
float brickLookup(const Bricks& b, const DenseGrid& g, vec3 p) {
  return grid_bricks_trilinear(b.table(), b.pool(), g.nx, g.ny, g.nz, p);
}

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Points that probe every way a lookup can fall (see the top of the file).
std::vector<vec3> probePoints(const DenseGrid& g, unsigned seed, int random) {
  std::vector<vec3> pts;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> ux(-1.5f, g.nx + 1.5f), uy(-1.5f, g.ny + 1.5f), uz(-1.5f, g.nz + 1.5f);
  for (int i = 0; i < random; ++i) pts.push_back(vec3_make(ux(rng), uy(rng), uz(rng)));
  // Brick faces and their neighbourhood on each axis: the lower corner's voxel index changes at
  // p = i + 0.5, so 8k + 0.5 is where a lookup moves to the next brick; 8k is the brick face.
  std::vector<float> planes;
  const int n = std::max({g.nx, g.ny, g.nz});
  for (int k = 0; k * 8 <= n + 8; ++k)
    for (float d : {-1.0f, -0.5f, -0.25f, -1e-3f, 0.0f, 1e-3f, 0.25f, 0.5f, 0.75f, 1.0f})
      planes.push_back(8.0f * k + d), planes.push_back(8.0f * k + 0.5f + d);
  std::uniform_real_distribution<float> any(-1.0f, float(n) + 1.0f);
  for (float a : planes)
    for (int r = 0; r < 6; ++r) {
      const float b = any(rng), c = any(rng);
      pts.push_back(vec3_make(a, b, c));
      pts.push_back(vec3_make(b, a, c));
      pts.push_back(vec3_make(c, b, a));
      pts.push_back(vec3_make(a, a, b));
      pts.push_back(vec3_make(a, a, a));
    }
  // Voxel centres and faces everywhere, one voxel beyond the grid.
  for (int z = -1; z <= g.nz; ++z)
    for (int y = -1; y <= g.ny; ++y)
      for (int x = -1; x <= g.nx; ++x) {
        pts.push_back(vec3_make(x + 0.5f, y + 0.5f, z + 0.5f));
        pts.push_back(vec3_make(float(x), y + 0.25f, z + 0.75f));
      }
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (float far : {1e30f, -1e30f, inf, -inf, nan, 1e7f, -1.0f, float(g.nx), float(g.nx) + 0.5f}) {
    pts.push_back(vec3_make(far, 1.0f, 1.0f));
    pts.push_back(vec3_make(1.0f, far, 1.0f));
    pts.push_back(vec3_make(0.5f, 0.5f, far));
    pts.push_back(vec3_make(far, far, far));
  }
  return pts;
}

// Bricks against the dense filter at every probe point: the same bits. Returns the non-zero count.
size_t expectSameLookups(const DenseGrid& g, const char* name, int random = 20000) {
  const BrickLayout layout = planBricks(g);
  const Bricks b{buildBrickBuffer(g, layout)};
  size_t differ = 0, nonZero = 0, checked = 0;
  for (const vec3& p : probePoints(g, 11, random)) {
    const float d = denseLookup(g, p), k = brickLookup(b, g, p);
    ++checked;
    nonZero += d != 0.0f;
    if (!sameBits(d, k) && differ++ < 5)
      ADD_FAILURE() << name << " at (" << p.x << ", " << p.y << ", " << p.z << "): dense " << d << ", bricks " << k;
  }
  EXPECT_EQ(differ, 0u) << name << ": " << differ << " of " << checked << " lookups differ";
  return nonZero;
}

TEST(BrickGrid, LayoutOfAGridThatIsNotAMultipleOfTheBrick) {
  const DenseGrid g = randomGrid(19, 9, 17, 1, 0.0f);
  const BrickLayout L = planBricks(g);
  EXPECT_EQ(L.bricksX, 3);
  EXPECT_EQ(L.bricksY, 2);
  EXPECT_EQ(L.bricksZ, 3);
  ASSERT_EQ(L.brickCount(), 18u);
  EXPECT_EQ(L.occupiedCount(), 18u);  // no zeros: every brick holds density
  for (uint32_t i = 0; i < 18; ++i) {
    EXPECT_EQ(L.table[i], i) << "slots in table order";
    EXPECT_EQ(L.occupied[i], i);
  }
  // Header (4 slots) + 18 table entries = 22, rounded up to 24 floats (16-byte aligned pool).
  EXPECT_EQ(L.poolOffsetFloats(), 24u);
  EXPECT_EQ(L.bufferFloats(), 24u + 18u * 729u);
  EXPECT_EQ(L.bufferBytes(), L.bufferFloats() * 4);
  EXPECT_EQ(L.poolBytes(), 18u * 729u * 4u);
  const std::vector<float> buf = buildBrickBuffer(g, L);
  int32_t header[4];
  std::memcpy(header, buf.data(), sizeof header);
  EXPECT_EQ(header[0], 19);
  EXPECT_EQ(header[1], 9);
  EXPECT_EQ(header[2], 17);
  EXPECT_EQ(header[3], 24);
  // Brick (2, 1, 2), the last: it owns voxels 16..18 x 8 x 16 only; its stored values beyond the
  // grid are 0, those inside are the grid's.
  const float* last = buf.data() + 24 + 17 * 729;
  for (int z = 0; z < 9; ++z)
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 9; ++x) {
        const int gx = 16 + x, gy = 8 + y, gz = 16 + z;
        const float expected = gx < 19 && gy < 9 && gz < 17 ? g.at(gx, gy, gz) : 0.0f;
        ASSERT_EQ(last[z * 81 + y * 9 + x], expected) << x << " " << y << " " << z;
      }
  // Brick (0, 0, 0) carries the first voxel layer of its + neighbours as its apron.
  for (int z = 0; z < 9; ++z)
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 9; ++x) ASSERT_EQ(buf[24 + z * 81 + y * 9 + x], y < 9 ? g.at(x, y, z) : 0.0f);
}

TEST(BrickGrid, LookupsMatchTheDenseFilterBitForBit) {
  expectSameLookups(randomGrid(19, 9, 17, 2, 0.0f), "random 19x9x17");
  expectSameLookups(randomGrid(16, 8, 24, 3, 0.0f), "random 16x8x24 (whole bricks)");
  expectSameLookups(randomGrid(33, 5, 3, 4, 0.7f), "sparse 33x5x3");
  expectSameLookups(randomGrid(1, 1, 1, 5, 0.0f), "one voxel");
  expectSameLookups(randomGrid(9, 1, 2, 6, 0.0f), "9x1x2");
  EXPECT_GT(expectSameLookups(makeCloud(40, 3), "cloud 40^3"), 1000u);
}

// Sparse data: most bricks empty, and lookups still the same bits (+0 from an empty brick, as
// the dense filter sums eight zeros to +0).
TEST(BrickGrid, SparseGridSkipsEmptyBricks) {
  const DenseGrid cloud = makeCloud(64, 2);
  const BrickLayout L = planBricks(cloud);
  EXPECT_EQ(L.brickCount(), 512u);
  EXPECT_LT(L.occupiedCount(), L.brickCount());
  EXPECT_GT(L.occupiedCount(), 0u);
  // The cloud leaves kCloudMargin of every face at 0: the outer layer of bricks (0.08 · 64 = 5
  // voxels of zeros, plus the apron's one) is empty.
  for (int b = 0; b < 8; ++b) EXPECT_EQ(L.table[size_t(b)], GRID_BRICK_EMPTY) << "brick (" << b << ", 0, 0)";
  expectSameLookups(cloud, "cloud 64^3", 5000);
}

// Empty exactly when every stored value is 0: compare with a direct check of each brick's 9³.
TEST(BrickGrid, OccupancyIsExactlyTheBricksHoldingANonZeroValue) {
  const DenseGrid g = randomGrid(27, 20, 13, 8, 0.995f);
  const BrickLayout L = planBricks(g);
  size_t occupied = 0;
  for (int bz = 0; bz < L.bricksZ; ++bz)
    for (int by = 0; by < L.bricksY; ++by)
      for (int bx = 0; bx < L.bricksX; ++bx) {
        bool any = false;
        for (int z = 8 * bz; z <= 8 * bz + 8 && z < g.nz; ++z)
          for (int y = 8 * by; y <= 8 * by + 8 && y < g.ny; ++y)
            for (int x = 8 * bx; x <= 8 * bx + 8 && x < g.nx; ++x) any = any || g.at(x, y, z) != 0.0f;
        const uint32_t slot = L.table[size_t(bx + L.bricksX * (by + L.bricksY * bz))];
        EXPECT_EQ(slot != GRID_BRICK_EMPTY, any) << bx << " " << by << " " << bz;
        occupied += any;
      }
  EXPECT_EQ(L.occupiedCount(), occupied);
  EXPECT_GT(occupied, 0u);
  EXPECT_LT(occupied, L.brickCount());
  expectSameLookups(g, "random 27x20x13, 0.5% non-zero", 5000);
}

TEST(BrickGrid, AllZeroGridHasNoPoolAndReadsZero) {
  const DenseGrid g = zeros(20, 17, 9);
  const BrickLayout L = planBricks(g);
  EXPECT_EQ(L.brickCount(), 3u * 3u * 2u);
  EXPECT_EQ(L.occupiedCount(), 0u);
  EXPECT_EQ(L.poolBytes(), 0u);
  for (uint32_t slot : L.table) EXPECT_EQ(slot, GRID_BRICK_EMPTY);
  const Bricks b{buildBrickBuffer(g, L)};
  EXPECT_EQ(b.buffer.size(), L.poolOffsetFloats());
  for (const vec3& p : probePoints(g, 3, 2000)) {
    const float v = brickLookup(b, g, p);
    ASSERT_TRUE(sameBits(v, 0.0f)) << p.x << " " << p.y << " " << p.z;
  }
}

// One non-zero voxel on a brick corner, (8, 8, 8): brick (1, 1, 1) owns it and the seven bricks
// below it on some axis store it in their apron, so exactly those eight are occupied, and lookups
// all around it (its support is (7.5, 9.5)³) read it through whichever brick they land in.
TEST(BrickGrid, AVoxelOnABrickCornerReachesAllEightBricksThroughTheApron) {
  DenseGrid g = zeros(24, 24, 24);
  g.data[size_t(8 + 24 * (8 + 24 * 8))] = 3.0f;
  const BrickLayout L = planBricks(g);
  std::set<size_t> occupied;
  for (size_t i = 0; i < L.table.size(); ++i)
    if (L.table[i] != GRID_BRICK_EMPTY) occupied.insert(i);
  std::set<size_t> expected;
  for (int bz : {0, 1})
    for (int by : {0, 1})
      for (int bx : {0, 1}) expected.insert(size_t(bx + 3 * (by + 3 * bz)));
  EXPECT_EQ(occupied, expected);
  const Bricks b{buildBrickBuffer(g, L)};
  // Every point of the support on a 1/16 lattice, and its peak.
  size_t nonZero = 0;
  for (float z = 7.25f; z <= 9.75f; z += 0.0625f)
    for (float y = 7.25f; y <= 9.75f; y += 0.0625f)
      for (float x = 7.25f; x <= 9.75f; x += 0.0625f) {
        const vec3 p = vec3_make(x, y, z);
        const float d = denseLookup(g, p), k = brickLookup(b, g, p);
        ASSERT_TRUE(sameBits(d, k)) << x << " " << y << " " << z << ": dense " << d << ", bricks " << k;
        nonZero += d > 0.0f;
      }
  EXPECT_EQ(nonZero, 31u * 31u * 31u);  // the open support (7.5, 9.5)³ on the lattice
  EXPECT_EQ(brickLookup(b, g, vec3_make(8.5f, 8.5f, 8.5f)), 3.0f);
  expectSameLookups(g, "corner voxel", 2000);
}

// The last voxel of a grid that ends inside a brick, and the first of a grid: the clamped corners
// of lookups beyond the grid stay in the brick that holds them.
TEST(BrickGrid, VoxelsOnTheGridBorderFadeAsInTheDenseFilter) {
  DenseGrid g = zeros(11, 10, 9);
  g.data[0] = 2.0f;
  g.data[g.data.size() - 1] = 4.0f;
  const BrickLayout L = planBricks(g);
  // (0, 0, 0) lives in brick (0, 0, 0) only; (10, 9, 8) in brick (1, 1, 1) and, z = 8 being the
  // first layer of brick z 1, in the apron of brick (1, 1, 0).
  EXPECT_EQ(L.occupiedCount(), 3u);
  const Bricks b{buildBrickBuffer(g, L)};
  EXPECT_EQ(brickLookup(b, g, vec3_make(0.0f, 0.5f, 0.5f)), 1.0f);     // half way to the border
  EXPECT_EQ(brickLookup(b, g, vec3_make(11.0f, 9.5f, 8.5f)), 2.0f);    // the far face
  EXPECT_EQ(brickLookup(b, g, vec3_make(11.5f, 9.5f, 8.5f)), 0.0f);    // half a voxel outside
  expectSameLookups(g, "border voxels", 2000);
}

// The pool written in slices (the upload's chunks) is the pool written at once.
TEST(BrickGrid, PoolWrittenInChunksEqualsThePoolWrittenAtOnce) {
  const DenseGrid g = randomGrid(30, 22, 17, 9, 0.9f);
  const BrickLayout L = planBricks(g);
  const std::vector<float> whole = buildBrickBuffer(g, L);
  std::vector<float> chunked(L.bufferFloats(), -1.0f);
  writeBrickHeader(L, chunked.data());
  for (size_t first = 0; first < L.occupiedCount(); first += 5)
    writeBricks(g, L, first, std::min<size_t>(5, L.occupiedCount() - first),
                chunked.data() + L.poolOffsetFloats() + first * kBrickFloats);
  EXPECT_EQ(std::memcmp(whole.data(), chunked.data(), whole.size() * sizeof(float)), 0);
}

TEST(BrickGrid, MismatchedInputsAreRefused) {
  DenseGrid g = zeros(4, 4, 4);
  g.data.pop_back();
  EXPECT_THROW(planBricks(g), std::invalid_argument);
  const DenseGrid ok = zeros(4, 4, 4), other = zeros(5, 4, 4);
  const BrickLayout L = planBricks(ok);
  std::vector<float> out(729);
  EXPECT_THROW(writeBricks(other, L, 0, 0, out.data()), std::invalid_argument);
  EXPECT_THROW(writeBricks(ok, L, 0, 1, out.data()), std::invalid_argument);  // no occupied brick
}

}  // namespace
}  // namespace narval
