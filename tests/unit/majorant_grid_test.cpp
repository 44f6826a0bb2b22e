// majorant_grid_test.cpp: the majorant grid (host/volume/majorant_grid.*) and its DDA
// (kernels/shared/majorant_dda.h, the very code the device compiles): the cell values bound the
// trilinear density (kernels/shared/grid.h, host branch, the device's reconstruction) and are the
// least such bound made from voxel values; the DDA walks exactly the cells a ray passes through,
// in order, with contiguous t; the length a kernel may skip is what geometry says. Every expected
// value is derived in a comment.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "shared/grid.h"
#include "shared/intersect.h"
#include "shared/majorant_dda.h"
#include "test_support.h"
#include "unit/host_context.h"
#include "volume/dense_grid.h"
#include "volume/majorant_grid.h"

namespace {

using narval::DenseGrid;
using narval::MajorantGrid;

// ---- helpers ----

DenseGrid makeGrid(int nx, int ny, int nz, float value = 0.0f) {
  DenseGrid g;
  g.nx = nx;
  g.ny = ny;
  g.nz = nz;
  g.data.assign(g.voxelCount(), value);
  return g;
}
void setVoxel(DenseGrid& g, int x, int y, int z, float v) {
  g.data[size_t(x) + size_t(g.nx) * (size_t(y) + size_t(g.ny) * size_t(z))] = v;
}
float density(const DenseGrid& g, float x, float y, float z) {
  const grid_view view{g.data.data(), g.nx, g.ny, g.nz};
  return grid_view_density(&view, vec3_make(x, y, z));
}

// A random grid: about `fillFraction` of the voxels nonzero (uniform in (0, 1]), the rest exactly 0.
DenseGrid randomGrid(std::mt19937& rng, int nx, int ny, int nz, double fillFraction) {
  DenseGrid g = makeGrid(nx, ny, nz);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& v : g.data)
    if (u(rng) < fillFraction) v = std::max(u(rng), 1e-3f);
  return g;
}

int dimOf(const DenseGrid& g, int a) { return a == 0 ? g.nx : (a == 1 ? g.ny : g.nz); }
int cellsOf(const MajorantGrid& m, int a) { return a == 0 ? m.cellsX : (a == 1 ? m.cellsY : m.cellsZ); }
float comp(vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

// Cell k of an axis covers [face(k), face(k+1)], faces as the DDA forms them (float k·size), the last
// cell reaching the box's far face n.
double face(const MajorantGrid& m, int a, int k) { return double(float(k) * m.cellSize[size_t(a)]); }
double cellLo(const MajorantGrid& m, int a, int k) { return k == 0 ? 0.0 : face(m, a, k); }
double cellHi(const MajorantGrid& m, const DenseGrid& g, int a, int k) {
  const double hi = face(m, a, k + 1);
  return k == cellsOf(m, a) - 1 ? std::max(hi, double(dimOf(g, a))) : hi;
}

// The cell value by brute force over every voxel, in double: the largest voxel whose open support
// (j - 0.5, j + 1.5) meets the cell grown by MAJORANT_SLACK on every axis, and 0 (out-of-grid
// voxels read 0). Independent of the build's range arithmetic and separable max.
float bruteCellMax(const DenseGrid& g, const MajorantGrid& m, int i, int j, int k) {
  const int c[3] = {i, j, k};
  const double s = MAJORANT_SLACK;
  auto reaches = [&](int a, int v) {
    return double(v) - 0.5 < cellHi(m, g, a, c[a]) + s && double(v) + 1.5 > cellLo(m, a, c[a]) - s;
  };
  float best = 0.0f;
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x)
        if (reaches(0, x) && reaches(1, y) && reaches(2, z)) best = std::max(best, g.at(x, y, z));
  return best;
}

struct Seg {
  float t0, t1, max;
  int cell;
};
struct Walk {
  std::vector<Seg> segs;
  int calls = 0;  // calls to majorant_iter_next, the last one returning 0
  majorant_iter end;
};
Walk walk(const MajorantGrid& m, vec3 o, vec3 d, float t0, float t1) {
  Walk w;
  majorant_iter it = majorant_iter_begin(m.params(), o, d, t0, t1);
  float a = 0.0f, b = 0.0f, mx = 0.0f;
  while (w.calls < 100000) {
    ++w.calls;
    if (!majorant_iter_next(&it, m.maxDensity.data(), &a, &b, &mx)) break;
    w.segs.push_back({a, b, mx, it.seg_cell});
  }
  w.end = it;
  return w;
}
int cellIndex(const MajorantGrid& m, int i, int j, int k) { return i + m.cellsX * (j + m.cellsY * k); }
void cellCoords(const MajorantGrid& m, int cell, int c[3]) {
  c[0] = cell % m.cellsX;
  c[1] = (cell / m.cellsX) % m.cellsY;
  c[2] = cell / (m.cellsX * m.cellsY);
}
std::string describe(vec3 o, vec3 d, float t0, float t1) {
  std::ostringstream s;
  s.precision(9);
  s << "o=(" << o.x << "," << o.y << "," << o.z << ") d=(" << d.x << "," << d.y << "," << d.z << ") t=[" << t0
    << "," << t1 << "]";
  return s.str();
}

// The cell (by faces, clamped) containing coordinate p on axis a: the number of interior faces <= p.
int cellOfCoord(const MajorantGrid& m, int a, double p) {
  int c = 0;
  for (int k = 1; k < cellsOf(m, a); ++k)
    if (face(m, a, k) <= p) c = k;
  return c;
}

// ---- MajorantGrid: resolution, layout ----

// round(target · n_i / max n), clamped to [1, n_i]. Disney cloud 126×86×154, target 16:
// 16·126/154 = 13.09 → 13, 16·86/154 = 8.94 → 9, 16 → 16. Target 32: 26.18 → 26, 17.87 → 18, 32.
// A cube takes target on every axis; a 100×1×3 slab: 16, round(0.16) = 0 → 1, round(0.48) = 0 → 1;
// 8×4×2 with 16: round(16), round(8), round(4) capped at the voxel counts 8, 4, 2.
TEST(MajorantGridResolution, ProportionalToTheLongestAxis) {
  EXPECT_EQ(narval::chooseMajorantResolution(126, 86, 154), (std::array<int, 3>{13, 9, 16}));
  EXPECT_EQ(narval::chooseMajorantResolution(126, 86, 154, 32), (std::array<int, 3>{26, 18, 32}));
  EXPECT_EQ(narval::chooseMajorantResolution(64, 64, 64), (std::array<int, 3>{16, 16, 16}));
  EXPECT_EQ(narval::chooseMajorantResolution(100, 1, 3), (std::array<int, 3>{16, 1, 1}));
  EXPECT_EQ(narval::chooseMajorantResolution(8, 4, 2), (std::array<int, 3>{8, 4, 2}));
  EXPECT_EQ(narval::chooseMajorantResolution(1, 1, 1, 64), (std::array<int, 3>{1, 1, 1}));
  EXPECT_THROW(narval::chooseMajorantResolution(0, 4, 4), std::invalid_argument);
  EXPECT_THROW(narval::chooseMajorantResolution(4, 4, 4, 0), std::invalid_argument);
}

// The params struct crosses to the device: nv_float4 (16 bytes) then four ints, 32 bytes, no
// implicit padding. Cell size = dims / cells: 10/3, 20/4 = 5, 30/5 = 6.
TEST(MajorantGrid, LayoutAndParams) {
  EXPECT_EQ(sizeof(majorant_grid_params), 32u);
  EXPECT_EQ(offsetof(majorant_grid_params, cell_size), 0u);
  EXPECT_EQ(offsetof(majorant_grid_params, cells_x), 16u);
  EXPECT_EQ(offsetof(majorant_grid_params, cells_y), 20u);
  EXPECT_EQ(offsetof(majorant_grid_params, cells_z), 24u);
  EXPECT_EQ(offsetof(majorant_grid_params, pad0), 28u);
  const MajorantGrid m = narval::buildMajorantGrid(makeGrid(10, 20, 30, 1.0f), 3, 4, 5);
  const majorant_grid_params p = m.params();
  EXPECT_EQ(p.cells_x, 3);
  EXPECT_EQ(p.cells_y, 4);
  EXPECT_EQ(p.cells_z, 5);
  EXPECT_EQ(p.cell_size.x, 10.0f / 3.0f);
  EXPECT_EQ(p.cell_size.y, 5.0f);
  EXPECT_EQ(p.cell_size.z, 6.0f);
  EXPECT_EQ(m.cellCount(), 60u);
  ASSERT_EQ(m.maxDensity.size(), 60u);
  // A constant grid bounds every cell by that constant.
  for (float v : m.maxDensity) EXPECT_EQ(v, 1.0f);
}

TEST(MajorantGrid, RejectsBadInput) {
  EXPECT_THROW(narval::buildMajorantGrid(makeGrid(4, 4, 4), 0, 1, 1), std::invalid_argument);
  EXPECT_THROW(narval::buildMajorantGrid(DenseGrid{}, 1, 1, 1), std::invalid_argument);
  DenseGrid bad = makeGrid(4, 4, 4);
  bad.data.pop_back();
  EXPECT_THROW(narval::buildMajorantGrid(bad, 1, 1, 1), std::invalid_argument);
}

// ---- MajorantGrid: the bound ----

// Voxel j reaches (j - 0.5, j + 1.5). 16³ voxels, 4³ cells of 4: voxel (5, 9, 14) reaches
// x (4.5, 6.5) ⊂ cell 1 = [4, 8], y (8.5, 10.5) ⊂ cell 2 = [8, 12], z (13.5, 15.5) ⊂ cell 3: one
// cell holds 2.5, every other is exactly 0. Voxel (3, 8, 0) reaches x (2.5, 4.5): cells 0 and 1;
// y (7.5, 9.5): cells 1 and 2; z (-0.5, 1.5): cell 0: four cells hold its 0.75.
TEST(MajorantGrid, SingleVoxelLightsOnlyTheCellsItsSupportReaches) {
  DenseGrid g = makeGrid(16, 16, 16);
  setVoxel(g, 5, 9, 14, 2.5f);
  MajorantGrid m = narval::buildMajorantGrid(g, 4, 4, 4);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        EXPECT_EQ(m.at(i, j, k), (i == 1 && j == 2 && k == 3) ? 2.5f : 0.0f) << i << " " << j << " " << k;

  g = makeGrid(16, 16, 16);
  setVoxel(g, 3, 8, 0, 0.75f);
  m = narval::buildMajorantGrid(g, 4, 4, 4);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const bool lit = (i == 0 || i == 1) && (j == 1 || j == 2) && k == 0;
        EXPECT_EQ(m.at(i, j, k), lit ? 0.75f : 0.0f) << i << " " << j << " " << k;
      }
}

// A face on a plane of voxel centres: 7 voxels in 2 cells of 3.5, the face at 3.5 = centre of voxel
// 3. Voxel 2 reaches (1.5, 3.5), open at 3.5: in exact arithmetic it never weighs on cell 1 =
// [3.5, 7] (floor(3.5 - 0.5) = 3), but a point that float rounding puts a hair past the face does;
// with the cell grown by MAJORANT_SLACK, floor(3 - 1/256) = 2 takes it in (deliberately). Voxel 1
// reaches (0.5, 2.5): only cell 0, slack or not. Symmetrically voxel 4 (3.5, 5.5) reaches cell 0
// through ceil(3.5 + 1/256 - 0.5) = 4; voxel 5 (4.5, 6.5) does not.
TEST(MajorantGrid, FaceOnAVoxelCentrePlaneTakesTheTouchingVoxel) {
  auto oneVoxel = [](int x) {
    DenseGrid g = makeGrid(7, 1, 1);
    g.data[size_t(x)] = 1.0f;
    return narval::buildMajorantGrid(g, 2, 1, 1);
  };
  EXPECT_EQ(oneVoxel(1).maxDensity, (std::vector<float>{1.0f, 0.0f}));
  EXPECT_EQ(oneVoxel(2).maxDensity, (std::vector<float>{1.0f, 1.0f}));
  EXPECT_EQ(oneVoxel(4).maxDensity, (std::vector<float>{1.0f, 1.0f}));
  EXPECT_EQ(oneVoxel(5).maxDensity, (std::vector<float>{0.0f, 1.0f}));
  // The field itself: voxel 2's weight at x is 1 - (x - 2.5) on [2.5, 3.5), so 1e-3 at x = 3.499
  // (inside cell 0), and 0 from the face x = 3.5 on (voxel 3 takes weight 1 there).
  DenseGrid g = makeGrid(7, 1, 1);
  g.data[2] = 1.0f;
  EXPECT_NEAR(density(g, 3.499f, 0.5f, 0.5f), 1e-3f, 1e-5f);
  EXPECT_EQ(density(g, 3.5f, 0.5f, 0.5f), 0.0f);
}

// An all-zero grid bounds every cell by exactly 0; a grid whose x >= 16 half is zero has exactly 0
// in every cell whose grown x range starts past voxel 15's support (15.5 ± 1 → x < 16.5): with
// cells of 4, cell 4 = [16, 20] still reaches voxel 15 (floor(16 - 1/256 - 0.5) = 15), cells 5..7
// (from x = 20: floor(19.5 - 1/256) = 19) do not.
TEST(MajorantGrid, EmptyRegionsAreExactlyZero) {
  const MajorantGrid empty = narval::buildMajorantGrid(makeGrid(9, 10, 11), 3, 4, 5);
  for (float v : empty.maxDensity) EXPECT_EQ(v, 0.0f);

  std::mt19937 rng(7);
  DenseGrid g = randomGrid(rng, 32, 8, 8, 1.0);
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 16; x < 32; ++x) setVoxel(g, x, y, z, 0.0f);
  const MajorantGrid m = narval::buildMajorantGrid(g, 8, 2, 2);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 8; ++i) {
        if (i >= 5)
          EXPECT_EQ(m.at(i, j, k), 0.0f) << i;
        else
          EXPECT_GT(m.at(i, j, k), 0.0f) << i;
      }
}

// On random grids (odd sizes, cell counts that do not divide them, half the voxels 0): (1) every
// cell equals the brute-force max over the voxels whose support reaches it (the least bound made
// from voxel values); (2) grid_density at random points of each closed cell, its corners and up to
// 0.9·MAJORANT_SLACK outside it never exceeds the cell value beyond float rounding of the lerps
// (relative 1e-6, ~8 ulps; the kernel's MAJORANT_MARGIN is 1e-5), and is exactly 0 in zero cells;
// (3) when the largest relevant voxel has its centre inside the cell, the density at that centre
// equals the cell value exactly (weight 1 at a centre): the bound is attained, i.e. tight.
TEST(MajorantGrid, ConservativeAndTightOnRandomGrids) {
  std::mt19937 rng(20240611);
  long samples = 0, strictExceedances = 0, attained = 0;
  for (int trial = 0; trial < 12; ++trial) {
    std::uniform_int_distribution<int> dim(3, 21), cells(1, 7);
    const DenseGrid g = randomGrid(rng, dim(rng), dim(rng), dim(rng), trial % 3 == 0 ? 0.05 : 0.5);
    const MajorantGrid m = narval::buildMajorantGrid(g, cells(rng), cells(rng), cells(rng));
    for (int k = 0; k < m.cellsZ; ++k)
      for (int j = 0; j < m.cellsY; ++j)
        for (int i = 0; i < m.cellsX; ++i) {
          const float bound = m.at(i, j, k);
          ASSERT_EQ(bound, bruteCellMax(g, m, i, j, k)) << "trial " << trial << " cell " << i << " " << j << " " << k;
          const int c[3] = {i, j, k};
          double lo[3], hi[3];
          for (int a = 0; a < 3; ++a) {
            lo[a] = cellLo(m, a, c[a]);
            hi[a] = cellHi(m, g, a, c[a]);
          }
          const double out = 0.9 * MAJORANT_SLACK;
          for (int s = 0; s < 300; ++s) {
            double p[3];
            for (int a = 0; a < 3; ++a) {
              const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
              if (s < 8)
                p[a] = (s >> a) & 1 ? hi[a] : lo[a];  // the corners
              else if (s < 16)
                p[a] = (s >> a) & 1 ? hi[a] + out : lo[a] - out;  // just outside the corners
              else
                p[a] = lo[a] + u * (hi[a] - lo[a]);
            }
            const float rho = density(g, float(p[0]), float(p[1]), float(p[2]));
            ++samples;
            if (rho > bound) ++strictExceedances;
            ASSERT_LE(rho, bound * (1.0f + 1e-6f)) << "trial " << trial << " at " << p[0] << " " << p[1] << " " << p[2];
          }
          // Tightness: the largest voxel with its centre in the cell.
          float inside = 0.0f;
          int arg[3] = {-1, -1, -1};
          for (int z = 0; z < g.nz; ++z)
            for (int y = 0; y < g.ny; ++y)
              for (int x = 0; x < g.nx; ++x) {
                const int v[3] = {x, y, z};
                bool in = true;
                for (int a = 0; a < 3; ++a) in = in && v[a] + 0.5 >= lo[a] && v[a] + 0.5 <= hi[a];
                if (in && g.at(x, y, z) > inside) {
                  inside = g.at(x, y, z);
                  arg[0] = x, arg[1] = y, arg[2] = z;
                }
              }
          if (inside == bound && arg[0] >= 0) {
            ++attained;
            EXPECT_EQ(density(g, arg[0] + 0.5f, arg[1] + 0.5f, arg[2] + 0.5f), bound);
          }
        }
  }
  EXPECT_GT(attained, 50);  // the tightness check did run
  RecordProperty("density_samples", std::to_string(samples));
  RecordProperty("strict_exceedances_within_1e-6", std::to_string(strictExceedances));
  RecordProperty("cells_where_bound_attained", std::to_string(attained));
}

// ---- MajorantDda: hand-derived walks ----

// 16³ voxels, 8³ cells of 2. o = (0, 3, 5), d = +x, t ∈ [0, 16]: y = 3 → cell 1, z = 5 → cell 2;
// x faces at 2, 4, ..., 14 give 8 segments [2k, 2k + 2] in cells (k, 1, 2), bit-exact. Back along
// −x from x = 16 (on the box face, d < 0 → ceil(8) − 1 = cell 7): cells 7, 6, ..., 0 over
// [2k', 2k' + 2]. A −0 component steps like +0: not at all.
TEST(MajorantDda, AxisParallelRays) {
  const MajorantGrid m = narval::buildMajorantGrid(makeGrid(16, 16, 16, 1.0f), 8, 8, 8);
  Walk w = walk(m, vec3_make(0, 3, 5), vec3_make(1, 0, -0.0f), 0.0f, 16.0f);
  ASSERT_EQ(w.segs.size(), 8u);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(w.segs[size_t(k)].t0, 2.0f * k);
    EXPECT_EQ(w.segs[size_t(k)].t1, 2.0f * k + 2.0f);
    EXPECT_EQ(w.segs[size_t(k)].cell, cellIndex(m, k, 1, 2));
    EXPECT_EQ(w.segs[size_t(k)].max, 1.0f);
  }
  EXPECT_EQ(w.calls, 9);

  w = walk(m, vec3_make(16, 3, 5), vec3_make(-1, -0.0f, 0), 0.0f, 16.0f);
  ASSERT_EQ(w.segs.size(), 8u);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(w.segs[size_t(k)].t0, 2.0f * k);
    EXPECT_EQ(w.segs[size_t(k)].cell, cellIndex(m, 7 - k, 1, 2));
  }
}

// Starting on an interior face: x = 4 is the face between cells 1 and 2. Along −x the ray enters
// cell 1 ([2, 4]) at once: t ∈ [0, 2] in cell 1, [2, 4] in cell 0 — no zero-length segment for
// cell 2. Along +x it starts in cell 2. Running inside the face y = 4 (d.y = 0) it walks the upper
// cells, y-cell 2 (the contract's choice; both closed cells bound the density on the face).
TEST(MajorantDda, StartOnAFaceAndRunAlongAFace) {
  const MajorantGrid m = narval::buildMajorantGrid(makeGrid(16, 16, 16, 1.0f), 8, 8, 8);
  Walk w = walk(m, vec3_make(4, 3, 5), vec3_make(-1, 0, 0), 0.0f, 4.0f);
  ASSERT_EQ(w.segs.size(), 2u);
  EXPECT_EQ(w.segs[0].cell, cellIndex(m, 1, 1, 2));
  EXPECT_EQ(w.segs[0].t0, 0.0f);
  EXPECT_EQ(w.segs[0].t1, 2.0f);
  EXPECT_EQ(w.segs[1].cell, cellIndex(m, 0, 1, 2));
  EXPECT_EQ(w.segs[1].t1, 4.0f);
  w = walk(m, vec3_make(4, 3, 5), vec3_make(1, 0, 0), 0.0f, 3.0f);
  ASSERT_EQ(w.segs.size(), 2u);
  EXPECT_EQ(w.segs[0].cell, cellIndex(m, 2, 1, 2));
  EXPECT_EQ(w.segs[0].t1, 2.0f);
  EXPECT_EQ(w.segs[1].cell, cellIndex(m, 3, 1, 2));
  EXPECT_EQ(w.segs[1].t1, 3.0f);
  w = walk(m, vec3_make(0, 4, 5), vec3_make(1, 0, 0), 0.0f, 16.0f);
  ASSERT_EQ(w.segs.size(), 8u);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(w.segs[size_t(k)].cell, cellIndex(m, k, 2, 2));
}

// Through corners: o = 0, d = (1, 1, 1) over [0, 16] crosses the three faces at once at t = 2k
// (all exact in float), so it steps diagonally: 8 segments in cells (k, k, k), none in the 6·7
// cells it only touches at a corner. In the plane z = 5, o = (1, 3, 5), d = (1, −1, 0) meets the
// edge x = y = 2 at t = 1 (x: (2 − 1)/1, y: (2 − 3)/−1): cell (0, 1) → (1, 0) directly, then x = 4
// at t = 3 (y stays in cell 0, the last one downwards).
TEST(MajorantDda, ThroughCornersAndEdgesStepsDiagonally) {
  const MajorantGrid m = narval::buildMajorantGrid(makeGrid(16, 16, 16, 1.0f), 8, 8, 8);
  Walk w = walk(m, vec3_make(0, 0, 0), vec3_make(1, 1, 1), 0.0f, 16.0f);
  ASSERT_EQ(w.segs.size(), 8u);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(w.segs[size_t(k)].cell, cellIndex(m, k, k, k));
    EXPECT_EQ(w.segs[size_t(k)].t0, 2.0f * k);
    EXPECT_EQ(w.segs[size_t(k)].t1, 2.0f * k + 2.0f);
  }
  w = walk(m, vec3_make(1, 3, 5), vec3_make(1, -1, 0), 0.0f, 4.0f);
  ASSERT_EQ(w.segs.size(), 3u);
  EXPECT_EQ(w.segs[0].cell, cellIndex(m, 0, 1, 2));
  EXPECT_EQ(w.segs[0].t1, 1.0f);
  EXPECT_EQ(w.segs[1].cell, cellIndex(m, 1, 0, 2));
  EXPECT_EQ(w.segs[1].t1, 3.0f);
  EXPECT_EQ(w.segs[2].cell, cellIndex(m, 2, 0, 2));
  EXPECT_EQ(w.segs[2].t1, 4.0f);
}

// Degenerate input: t0 == t1 (an empty segment: nothing to cover), t0 > t1, NaN or infinite t, a
// non-finite origin: nothing, and next() keeps returning 0. A zero direction stays in the origin's
// cell: one segment [t0, t1]. Outside the box the ray belongs to the nearest boundary cell:
// o = (−5, 3, 5) along +x over [0, 5] is all in cell (0, 1, 2).
TEST(MajorantDda, DegenerateInput) {
  const MajorantGrid m = narval::buildMajorantGrid(makeGrid(16, 16, 16, 1.0f), 8, 8, 8);
  const vec3 o = vec3_make(3, 3, 3), d = vec3_make(1, 0.5f, 0.25f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  EXPECT_TRUE(walk(m, o, d, 2.0f, 2.0f).segs.empty());
  EXPECT_TRUE(walk(m, o, d, 3.0f, 2.0f).segs.empty());
  EXPECT_TRUE(walk(m, o, d, nan, 2.0f).segs.empty());
  EXPECT_TRUE(walk(m, o, d, 0.0f, nan).segs.empty());
  EXPECT_TRUE(walk(m, o, d, 0.0f, inf).segs.empty());
  EXPECT_TRUE(walk(m, vec3_make(nan, 1, 1), d, 0.0f, 1.0f).segs.empty());
  EXPECT_TRUE(walk(m, o, vec3_make(inf, 0, 0), 0.0f, 1.0f).segs.empty());
  const Walk w0 = walk(m, o, d, 2.0f, 2.0f);
  EXPECT_EQ(w0.calls, 1);
  majorant_iter it = w0.end;
  float a, b, mx;
  EXPECT_EQ(majorant_iter_next(&it, m.maxDensity.data(), &a, &b, &mx), 0);

  Walk w = walk(m, vec3_make(3, 5, 9), vec3_make(0, 0, 0), -1.0f, 7.0f);
  ASSERT_EQ(w.segs.size(), 1u);
  EXPECT_EQ(w.segs[0].t0, -1.0f);
  EXPECT_EQ(w.segs[0].t1, 7.0f);
  EXPECT_EQ(w.segs[0].cell, cellIndex(m, 1, 2, 4));

  w = walk(m, vec3_make(-5, 3, 5), vec3_make(1, 0, 0), 0.0f, 5.0f);
  ASSERT_EQ(w.segs.size(), 1u);
  EXPECT_EQ(w.segs[0].cell, cellIndex(m, 0, 1, 2));
  // ... and past the far face, the last cell: o = (14, 3, 5) over [0, 10] → [0, 2] in x-cell 7 up
  // to x = 16, then x-cell 7 still (no further face): one segment [0, 10].
  w = walk(m, vec3_make(14, 3, 5), vec3_make(1, 0, 0), 0.0f, 10.0f);
  ASSERT_EQ(w.segs.size(), 1u);
  EXPECT_EQ(w.segs[0].cell, cellIndex(m, 7, 1, 2));
  EXPECT_EQ(w.segs[0].t1, 10.0f);
}

// ---- MajorantDda: random rays against brute force ----

// kFarOrigin: a camera far outside the box (1000 to 3000 index units, ~10× the Listing 4.1 camera's
// distance in index units), the segment from intersect_box as the kernels get it: positions then
// carry rounding errors of ~1e-4 index units.
enum RayKind { kGeneric, kAxisParallel, kThroughCorner, kThroughEdge, kStartOnFace, kSubSegment, kFarOrigin, kKinds };

struct TestRay {
  vec3 o, d;
  float t0, t1;
};

// A random ray of the given kind and its segment inside the box (false: it misses the box).
bool makeRay(std::mt19937& rng, const DenseGrid& g, const MajorantGrid& m, int kind, TestRay* r) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> n(0.0f, 1.0f);
  const float dims[3] = {float(g.nx), float(g.ny), float(g.nz)};
  float o[3], d[3] = {n(rng), n(rng), n(rng)};
  for (int a = 0; a < 3; ++a) o[a] = (1.5f * u(rng) - 0.25f) * dims[a];
  auto latticePoint = [&](int a) {
    const int k = std::uniform_int_distribution<int>(0, cellsOf(m, a))(rng);
    return k == cellsOf(m, a) ? dims[a] : float(k) * m.cellSize[size_t(a)];
  };
  if (kind == kAxisParallel) {
    const int zeroed = std::uniform_int_distribution<int>(1, 2)(rng);
    for (int i = 0; i < zeroed; ++i) d[std::uniform_int_distribution<int>(0, 2)(rng)] = u(rng) < 0.5f ? 0.0f : -0.0f;
    if (u(rng) < 0.5f)  // and sometimes running inside a face plane
      for (int a = 0; a < 3; ++a)
        if (d[a] == 0.0f) o[a] = latticePoint(a);
  }
  if (kind == kThroughCorner || kind == kThroughEdge) {
    // A lattice point P (all three coordinates on faces, or two for an edge), reached at t = s.
    float p[3];
    for (int a = 0; a < 3; ++a) p[a] = latticePoint(a);
    if (kind == kThroughEdge) {
      const int free = std::uniform_int_distribution<int>(0, 2)(rng);
      p[free] = u(rng) * dims[free];
    }
    if (u(rng) < 0.3f) {  // exactly diagonal through the cells
      for (int a = 0; a < 3; ++a) d[a] = (u(rng) < 0.5f ? -1.0f : 1.0f) * m.cellSize[size_t(a)];
    }
    const float s = 10.0f * u(rng);
    for (int a = 0; a < 3; ++a) o[a] = p[a] - d[a] * s;
  }
  if (kind == kFarOrigin) {
    // Aim at a random point of the box from a random direction, 1000 to 3000 units away.
    const float dist = 1000.0f + 2000.0f * u(rng);
    const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int a = 0; a < 3; ++a) {
      d[a] /= len;
      o[a] = u(rng) * dims[a] - d[a] * dist;
    }
  }
  if (kind == kStartOnFace) {
    for (int a = 0; a < 3; ++a)
      if (u(rng) < 0.7f) o[a] = latticePoint(a);
      else o[a] = u(rng) * dims[a];
  }
  r->o = vec3_make(o[0], o[1], o[2]);
  r->d = vec3_make(d[0], d[1], d[2]);
  if (vec3_is_zero(r->d)) r->d = vec3_make(1, 0, 0);
  float tn, tf;
  if (!intersect_box(r->o, r->d, vec3_make(dims[0], dims[1], dims[2]), &tn, &tf)) return false;
  if (kind == kStartOnFace) {
    if (!(tn <= 0.0f && tf > 0.0f)) return false;  // must start inside (on a face)
    tn = 0.0f;
  }
  if (!(tf > tn)) return false;
  r->t0 = tn;
  r->t1 = tf;
  if (kind == kSubSegment) {
    float a = tn + u(rng) * (tf - tn), b = tn + u(rng) * (tf - tn);
    if (a > b) std::swap(a, b);
    if (!(b > a)) return false;
    r->t0 = a;
    r->t1 = b;
  }
  return true;
}

// For each ray: (1) contiguity, bit-exact: first t0 = ray t0, each t1 = next t0, last t1 = ray t1,
// all lengths > 0; (2) at most cx + cy + cz − 2 segments (one per step of one axis, plus one) and
// the loop never ran out of budget (it.t == it.t_end at the end); (3) each segment's midpoint p lies
// in the reported cell: floor(p / cellSize) (clamped to the grid) equals it, except where p is within
// 1e-4 of the face between the two (float noise on a sliver); (4) the visited set equals the brute-
// force set: in double, the ray's crossings with every face plane cut [t0, t1] into pieces, each
// inside one cell; every piece longer than 1e-3 must be visited, and every visited segment longer
// than 1e-3 must be some piece's cell (shorter ones are float slivers at corners and edges);
// (5) dense sampling: the cell of each of 512 evenly spaced points (float, floor) is visited,
// up to the same 1e-4 face tolerance.
TEST(MajorantDda, RandomRaysMatchBruteForce) {
  std::mt19937 rng(99);
  int rays = 0, perKind[kKinds] = {};
  long segments = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::uniform_int_distribution<int> dim(4, 40), cells(1, 9);
    const DenseGrid g = randomGrid(rng, dim(rng), dim(rng), dim(rng), 0.3);
    const MajorantGrid m = narval::buildMajorantGrid(g, cells(rng), cells(rng), cells(rng));
    const int budget = m.cellsX + m.cellsY + m.cellsZ;
    for (int rayIndex = 0; rayIndex < 300; ++rayIndex) {
      const int kind = rayIndex % kKinds;
      TestRay r;
      if (!makeRay(rng, g, m, kind, &r)) continue;
      ++rays;
      ++perKind[kind];
      const std::string what = "trial " + std::to_string(trial) + " kind " + std::to_string(kind) + " " +
                               describe(r.o, r.d, r.t0, r.t1);
      const Walk w = walk(m, r.o, r.d, r.t0, r.t1);
      // (1), (2)
      ASSERT_FALSE(w.segs.empty()) << what;
      ASSERT_EQ(w.segs.front().t0, r.t0) << what;
      ASSERT_EQ(w.segs.back().t1, r.t1) << what;
      for (size_t i = 0; i < w.segs.size(); ++i) {
        ASSERT_GT(w.segs[i].t1, w.segs[i].t0) << what;
        if (i + 1 < w.segs.size()) {
          ASSERT_EQ(w.segs[i].t1, w.segs[i + 1].t0) << what;
        }
        ASSERT_EQ(w.segs[i].max, m.maxDensity[size_t(w.segs[i].cell)]) << what;
      }
      ASSERT_LE(int(w.segs.size()), budget - 2) << what;
      ASSERT_EQ(w.calls, int(w.segs.size()) + 1) << what;
      ASSERT_EQ(w.end.t, w.end.t_end) << what;
      segments += long(w.segs.size());
      // (3)
      auto nearFace = [&](int a, float p, int c0, int c1) {
        const int k = std::max(c0, c1);
        return std::fabs(double(p) - face(m, a, k)) <= 1e-4 * std::max(1.0, std::fabs(double(p)));
      };
      auto floorCell = [&](int a, float p) {
        const float f = std::floor(p / m.cellSize[size_t(a)]);
        return int(std::min(std::max(f, 0.0f), float(cellsOf(m, a) - 1)));
      };
      std::set<int> visited;
      for (const Seg& s : w.segs) {
        visited.insert(s.cell);
        const vec3 p = vec3_madd(r.o, r.d, 0.5f * (s.t0 + s.t1));
        int c[3];
        cellCoords(m, s.cell, c);
        for (int a = 0; a < 3; ++a) {
          const int f = floorCell(a, comp(p, a));
          if (f != c[a]) {
            ASSERT_TRUE(nearFace(a, comp(p, a), f, c[a])) << what << " axis " << a << " floor " << f << " reported " << c[a];
          }
        }
      }
      // (4)
      const double o[3] = {r.o.x, r.o.y, r.o.z}, d[3] = {r.d.x, r.d.y, r.d.z};
      std::vector<double> cuts = {double(r.t0), double(r.t1)};
      for (int a = 0; a < 3; ++a)
        if (d[a] != 0.0)
          for (int k = 1; k < cellsOf(m, a); ++k) {
            const double t = (face(m, a, k) - o[a]) / d[a];
            if (t > r.t0 && t < r.t1) cuts.push_back(t);
          }
      std::sort(cuts.begin(), cuts.end());
      std::set<int> pieceCells;
      for (size_t i = 0; i + 1 < cuts.size(); ++i) {
        const double len = cuts[i + 1] - cuts[i];
        if (!(len > 0.0)) continue;
        const double tm = 0.5 * (cuts[i] + cuts[i + 1]);
        const int cell = cellIndex(m, cellOfCoord(m, 0, o[0] + tm * d[0]), cellOfCoord(m, 1, o[1] + tm * d[1]),
                                   cellOfCoord(m, 2, o[2] + tm * d[2]));
        pieceCells.insert(cell);
        if (len > 1e-3) {
          ASSERT_TRUE(visited.count(cell)) << what << " misses cell " << cell << " over " << len;
        }
      }
      for (const Seg& s : w.segs) {
        if (s.t1 - s.t0 > 1e-3f) {
          ASSERT_TRUE(pieceCells.count(s.cell)) << what << " extra cell " << s.cell;
        }
      }
      // (5)
      for (int i = 0; i < 512; ++i) {
        const float t = r.t0 + (r.t1 - r.t0) * (float(i) + 0.5f) / 512.0f;
        const vec3 p = vec3_madd(r.o, r.d, t);
        int c[3];
        for (int a = 0; a < 3; ++a) c[a] = floorCell(a, comp(p, a));
        if (visited.count(cellIndex(m, c[0], c[1], c[2]))) continue;
        // Only a point on a face may fall in an unvisited neighbour: some axis near a face.
        bool onFace = false;
        for (int a = 0; a < 3; ++a)
          for (int k = 1; k < cellsOf(m, a); ++k)
            onFace = onFace || std::fabs(double(comp(p, a)) - face(m, a, k)) <= 1e-4 * std::max(1.0, double(std::fabs(comp(p, a))));
        ASSERT_TRUE(onFace) << what << " sample t=" << t << " in unvisited cell";
      }
    }
  }
  for (int k = 0; k < kKinds; ++k) EXPECT_GT(perKind[k], 200) << "kind " << k;
  RecordProperty("rays", std::to_string(rays));
  RecordProperty("segments", std::to_string(segments));
}

// What a kernel relies on: along any ray, grid_density at every point of a segment (float, as
// the kernel evaluates o + t·d, endpoints included) is at most the segment's value (relative 1e-6
// for the lerps' rounding, MAJORANT_MARGIN is 1e-5), and exactly 0 in segments whose value is 0 —
// so skipping those loses nothing. Random grids with 0.3% fill (every other one) make many zero cells.
TEST(MajorantDda, SegmentsBoundTheDensityAlongTheRay) {
  std::mt19937 rng(5);
  long points = 0, zeroSegments = 0;
  for (int trial = 0; trial < 30; ++trial) {
    std::uniform_int_distribution<int> dim(4, 40), cells(1, 12);
    const DenseGrid g = randomGrid(rng, dim(rng), dim(rng), dim(rng), trial % 2 ? 0.003 : 0.3);
    const MajorantGrid m = narval::buildMajorantGrid(g, cells(rng), cells(rng), cells(rng));
    for (int rayIndex = 0; rayIndex < 200; ++rayIndex) {
      TestRay r;
      if (!makeRay(rng, g, m, rayIndex % kKinds, &r)) continue;
      const Walk w = walk(m, r.o, r.d, r.t0, r.t1);
      for (const Seg& s : w.segs) {
        zeroSegments += s.max == 0.0f;
        for (int i = 0; i <= 40; ++i) {
          const float t = i == 0 ? s.t0 : (i == 40 ? s.t1 : s.t0 + (s.t1 - s.t0) * std::uniform_real_distribution<float>(0, 1)(rng));
          const vec3 p = vec3_madd(r.o, r.d, t);
          const float rho = density(g, p.x, p.y, p.z);
          ++points;
          ASSERT_LE(rho, s.max * (1.0f + 1e-6f)) << describe(r.o, r.d, r.t0, r.t1) << " t=" << t;
        }
      }
    }
  }
  EXPECT_GT(zeroSegments, 1000);
  RecordProperty("points", std::to_string(points));
  RecordProperty("zero_segments", std::to_string(zeroSegments));
}

// ---- MajorantDda: the length a kernel may skip ----

// 32×8×8 voxels, density 1 for x < 16 and 0 beyond; 8×2×2 cells of 4. The last nonzero voxel, 15,
// reaches x < 16.5, so x-cells 0..4 (up to x = 20) hold 1 and x-cells 5..7 hold 0
// (EmptyRegionsAreExactlyZero): the skippable part of a ray is exactly where x >= 20.
//  - o = (0, 3, 5), d = +x over [0, 32]: skippable [20, 32], 12.
//  - o = (2, 1, 1), d = (1, 0.25, 0.125) over [0, 28]: x = 2 + t >= 20 from t = 18: 10. The faces it
//    crosses (x = 4k at t = 4k − 2, y = 4 at t = 12, z = 4 at t = 24) are exact in float, so 10 is
//    exact.
//  - random rays clipped to the box: the measure of {t ∈ [t0, t1] : o.x + t·d.x >= 20}, computed in
//    double, within 1e-4 (float t at the faces).
TEST(MajorantDda, SkippableLengthOnAHalfEmptyGrid) {
  DenseGrid g = makeGrid(32, 8, 8);
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) setVoxel(g, x, y, z, 1.0f);
  const MajorantGrid m = narval::buildMajorantGrid(g, 8, 2, 2);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 8; ++i) ASSERT_EQ(m.at(i, j, k), i <= 4 ? 1.0f : 0.0f);
  auto skippable = [&](vec3 o, vec3 d, float t0, float t1) {
    double len = 0.0, total = 0.0;
    for (const Seg& s : walk(m, o, d, t0, t1).segs) {
      total += double(s.t1) - double(s.t0);
      if (s.max == 0.0f) len += double(s.t1) - double(s.t0);
    }
    EXPECT_EQ(total, double(t1) - double(t0));
    return len;
  };
  EXPECT_EQ(skippable(vec3_make(0, 3, 5), vec3_make(1, 0, 0), 0.0f, 32.0f), 12.0);
  EXPECT_EQ(skippable(vec3_make(2, 1, 1), vec3_make(1, 0.25f, 0.125f), 0.0f, 28.0f), 10.0);

  std::mt19937 rng(3);
  std::normal_distribution<float> n(0.0f, 1.0f);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const vec3 o = vec3_make(-10 + 52 * u(rng), -4 + 16 * u(rng), -4 + 16 * u(rng));
    const vec3 d = vec3_make(n(rng), n(rng), n(rng));
    float t0, t1;
    if (!intersect_box(o, d, vec3_make(32, 8, 8), &t0, &t1) || !(t1 > t0)) continue;
    ++checked;
    // {t : o.x + t d.x >= 20} ∩ [t0, t1]
    double lo = t0, hi = t1;
    const double tx = (20.0 - o.x) / d.x;
    if (d.x > 0) lo = std::max(lo, tx);
    else if (d.x < 0) hi = std::min(hi, tx);
    else if (o.x < 20) hi = lo;
    const double expected = std::max(0.0, hi - lo);
    EXPECT_NEAR(skippable(o, d, t0, t1), expected, 1e-4) << describe(o, d, t0, t1);
  }
  EXPECT_GT(checked, 500);
}

// ---- real data ----

// The Disney cloud (1/16: 126×86×154) at the resolutions chooseMajorantResolution gives for 16 and
// 32: 13×9×16 = 1872 and 26×18×32 = 14976 cells (MajorantGridResolution). The 32 grid nests in the
// 16 grid (26 = 2·13, ...; float(n/26) = float(n/13)/2 exactly, so faces coincide), and a fine cell's
// grown range lies inside its coarse cell's, so every empty coarse cell is 8 empty fine cells: the
// empty fraction can only grow. The bound holds at random points of the box. Reports the empty
// fractions of the box and the mean cell value over the global max (what a per-cell σ̄ saves in
// null collisions against the global majorant).
TEST(MajorantGridRealData, DisneyCloud) {
  const std::string path = narval::test::realDataPath("wdas_cloud_sixteenth.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  const DenseGrid g = narval::loadGrid(path);
  ASSERT_EQ(g.nx, 126);
  ASSERT_EQ(g.ny, 86);
  ASSERT_EQ(g.nz, 154);
  double emptyFraction[2] = {0, 0};
  const int targets[2] = {16, 32};
  std::mt19937 rng(11);
  for (int r = 0; r < 2; ++r) {
    const std::array<int, 3> c = narval::chooseMajorantResolution(g.nx, g.ny, g.nz, targets[r]);
    const MajorantGrid m = narval::buildMajorantGrid(g, c[0], c[1], c[2]);
    EXPECT_EQ(m.cellCount(), r == 0 ? 1872u : 14976u);
    size_t empty = 0;
    double sum = 0.0;
    for (float v : m.maxDensity) {
      empty += v == 0.0f;
      sum += v;
    }
    emptyFraction[r] = double(empty) / double(m.cellCount());
    const double meanOverMax = sum / double(m.cellCount()) / double(g.maxValue);
    std::uniform_real_distribution<float> ux(0, float(g.nx)), uy(0, float(g.ny)), uz(0, float(g.nz));
    for (int s = 0; s < 200000; ++s) {
      const float x = ux(rng), y = uy(rng), z = uz(rng);
      const float bound = m.at(std::min(int(x / m.cellSize[0]), m.cellsX - 1), std::min(int(y / m.cellSize[1]), m.cellsY - 1),
                               std::min(int(z / m.cellSize[2]), m.cellsZ - 1));
      ASSERT_LE(density(g, x, y, z), bound * (1.0f + 1e-6f));
    }
    const std::string key = "target" + std::to_string(targets[r]);
    RecordProperty(key + "_cells", std::to_string(m.cellCount()));
    RecordProperty(key + "_empty_fraction", std::to_string(emptyFraction[r]));
    RecordProperty(key + "_mean_over_global_max", std::to_string(meanOverMax));
    std::cout << "Disney cloud, target " << targets[r] << ": " << m.cellsX << "x" << m.cellsY << "x" << m.cellsZ << " = "
              << m.cellCount() << " cells, empty " << empty << " (" << 100.0 * emptyFraction[r]
              << "% of the box), mean cell max / global max " << meanOverMax << "\n";
  }
  EXPECT_GE(emptyFraction[1], emptyFraction[0]);
}

}  // namespace
