// majorant_grid.cpp: building the majorant grid (majorant_grid.h).
//
// The bound. Along one axis grid_density (kernels/shared/grid.h) takes f = p - 0.5, x0 = floor(f),
// a = f - x0 in [0, 1), weighting voxel x0 by 1 - a and x0 + 1 by a: voxel j has positive weight only on its
// open support j - 0.5 < p < j + 1.5 (as x0: j + 0.5 <= p < j + 1.5; as x0 + 1, a > 0: j - 0.5 < p < j + 0.5).
// In 3D the value is sum w·v over the 8 corners, w the product of axis weights (w >= 0, sum w = 1; corners
// outside the grid read v = 0), so at most the largest v over corners with w > 0, or 0 (the max starts at 0,
// standing for every out-of-grid voxel). For p in [A, B] on an axis, such a j has A - 1.5 <= p - 1.5 < j <
// p + 0.5 <= B + 0.5, i.e. floor(A - 0.5) <= j <= ceil(B - 0.5) for integer j. The axes are independent, so
// every corner with positive weight anywhere in the closed cell [A, B] (per axis) lies in the product of the
// three ranges, and the cell value (their max, and 0) bounds the density there.
//
// It is the least bound from voxel values alone: each j in the range has positive weight on a positive-length
// part of the cell ((j - 0.5, j + 1.5) meets [A, B] as j > A - 1.5, j < B + 0.5), and at a voxel centre the
// density is that voxel's value (weight 1): attained when the largest relevant voxel's centre is in the cell.
//
// Float rounding. The DDA (kernels/shared/majorant_dda.h) assigns points to cells in float, a few ulps of the
// index coordinates either side of a face, so each cell is grown by MAJORANT_SLACK = 1/256 index units before
// taking its range: that only enlarges it, and the bound holds up to 1/256 outside the cell. Only a face on a
// plane of voxel centres (A or B = m + 0.5) then takes one more voxel, whose support merely touches it (faces
// sit at k·n/c, so A - 0.5 is a multiple of 1/(2c) from an integer: for c < 128 cells an axis, 1/256 reaches
// no other voxel). The lerps round too: the host's can exceed the largest corner by a few ulps (a GPU
// sampler's fixed-point weights stay convex); MAJORANT_MARGIN on σ̄ covers that, as for the global majorant.
#include "volume/majorant_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace narval {
namespace {

struct AxisRanges {
  std::vector<int> lo, hi;  // voxel range per cell
};

// Cell k covers [k·size, (k+1)·size] with size and the products in float, exactly as the DDA forms
// its faces; the last cell reaches at least n (the DDA clamps points up to the box's far face to it).
AxisRanges axisRanges(int n, int cells, float size) {
  AxisRanges r;
  r.lo.resize(size_t(cells));
  r.hi.resize(size_t(cells));
  for (int k = 0; k < cells; ++k) {
    const double a = k == 0 ? 0.0 : double(float(k) * size);
    double b = double(float(k + 1) * size);
    if (k == cells - 1) b = std::max(b, double(n));
    majorantVoxelRange(a, b, n, &r.lo[size_t(k)], &r.hi[size_t(k)]);
  }
  return r;
}

inline float maxOf(float m, float v) { return v > m ? v : m; }  // NaN never wins

}  // namespace

majorant_grid_params MajorantGrid::params() const {
  majorant_grid_params p{};
  p.cell_size = nv_float4{cellSize[0], cellSize[1], cellSize[2], 0.0f};
  p.cells_x = cellsX;
  p.cells_y = cellsY;
  p.cells_z = cellsZ;
  return p;
}

void majorantVoxelRange(double cellMin, double cellMax, int n, int* lo, int* hi) {
  const double slack = double(MAJORANT_SLACK);
  const double l = std::floor(cellMin - slack - 0.5), h = std::ceil(cellMax + slack - 0.5);
  *lo = int(std::clamp(l, 0.0, double(n - 1)));
  *hi = int(std::clamp(h, 0.0, double(n - 1)));
}

MajorantGrid buildMajorantGrid(const DenseGrid& density, int cellsX, int cellsY, int cellsZ) {
  const int nx = density.nx, ny = density.ny, nz = density.nz;
  if (nx < 1 || ny < 1 || nz < 1)
    throw std::invalid_argument("buildMajorantGrid: empty grid " + std::to_string(nx) + "x" + std::to_string(ny) +
                                "x" + std::to_string(nz));
  if (cellsX < 1 || cellsY < 1 || cellsZ < 1)
    throw std::invalid_argument("buildMajorantGrid: cell counts must be >= 1, got " + std::to_string(cellsX) + "x" +
                                std::to_string(cellsY) + "x" + std::to_string(cellsZ));
  if (density.data.size() != density.voxelCount())
    throw std::invalid_argument("buildMajorantGrid: data size does not match the grid's dimensions");

  MajorantGrid g;
  g.cellsX = cellsX;
  g.cellsY = cellsY;
  g.cellsZ = cellsZ;
  g.cellSize = {float(nx) / float(cellsX), float(ny) / float(cellsY), float(nz) / float(cellsZ)};
  const AxisRanges rx = axisRanges(nx, cellsX, g.cellSize[0]);
  const AxisRanges ry = axisRanges(ny, cellsY, g.cellSize[1]);
  const AxisRanges rz = axisRanges(nz, cellsZ, g.cellSize[2]);

  // Separable max over x, then y, then z: each voxel is read about 1 + 2/cellSize times, not (1 + 2/cellSize)³.
  const size_t cx = size_t(cellsX), cy = size_t(cellsY), cz = size_t(cellsZ);
  std::vector<float> byX(cx * size_t(ny) * size_t(nz), 0.0f);  // (cell x, voxel y, voxel z)
  for (size_t yz = 0; yz < size_t(ny) * size_t(nz); ++yz) {
    const float* row = density.data.data() + yz * size_t(nx);
    for (size_t i = 0; i < cx; ++i) {
      float m = 0.0f;
      for (int x = rx.lo[i]; x <= rx.hi[i]; ++x) m = maxOf(m, row[x]);
      byX[i + cx * yz] = m;
    }
  }
  std::vector<float> byY(cx * cy * size_t(nz), 0.0f);  // (cell x, cell y, voxel z)
  for (size_t z = 0; z < size_t(nz); ++z)
    for (size_t j = 0; j < cy; ++j)
      for (size_t i = 0; i < cx; ++i) {
        float m = 0.0f;
        for (int y = ry.lo[j]; y <= ry.hi[j]; ++y) m = maxOf(m, byX[i + cx * (size_t(y) + size_t(ny) * z)]);
        byY[i + cx * (j + cy * z)] = m;
      }
  g.maxDensity.assign(cx * cy * cz, 0.0f);
  for (size_t k = 0; k < cz; ++k)
    for (size_t j = 0; j < cy; ++j)
      for (size_t i = 0; i < cx; ++i) {
        float m = 0.0f;
        for (int z = rz.lo[k]; z <= rz.hi[k]; ++z) m = maxOf(m, byY[i + cx * (j + cy * size_t(z))]);
        g.maxDensity[i + cx * (j + cy * k)] = m;
      }
  return g;
}

std::array<int, 3> chooseMajorantResolution(int nx, int ny, int nz, int target) {
  if (nx < 1 || ny < 1 || nz < 1 || target < 1)
    throw std::invalid_argument("chooseMajorantResolution: dims and target must be >= 1, got " +
                                std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz) +
                                ", target " + std::to_string(target));
  const int n[3] = {nx, ny, nz};
  const double longest = double(std::max({nx, ny, nz}));
  std::array<int, 3> cells{};
  for (int a = 0; a < 3; ++a) {
    const long c = std::lround(double(target) * double(n[a]) / longest);
    cells[size_t(a)] = int(std::max(1L, std::min(long(n[a]), c)));
  }
  return cells;
}

}  // namespace narval
