// majorant_grid.h: a coarse grid of density bounds over a DenseGrid's box (pbrt-v4's MajorantGrid),
// walked on the device by the DDA in kernels/shared/majorant_dda.h: empty-space skipping for the
// real-time kernels, a per-cell σ̄ for delta and ratio tracking in the path tracer.
#pragma once

#include <array>
#include <vector>

#include "shared/majorant_dda.h"
#include "volume/dense_grid.h"

namespace narval {

struct MajorantGrid {
  int cellsX = 0, cellsY = 0, cellsZ = 0;
  std::array<float, 3> cellSize{};  // index units per cell: (nx / cellsX, ny / cellsY, nz / cellsZ)
  // Per cell, x fastest (index x + cellsX·(y + cellsY·z)): an upper bound of the trilinear
  // density anywhere in the closed cell (grown by MAJORANT_SLACK), exactly the largest voxel whose
  // support reaches it. Density, not σt: the kernel multiplies by max-channel σt·D·MAJORANT_MARGIN.
  std::vector<float> maxDensity;

  float at(int x, int y, int z) const {
    return maxDensity[size_t(x) + size_t(cellsX) * (size_t(y) + size_t(cellsY) * size_t(z))];
  }
  size_t cellCount() const { return size_t(cellsX) * size_t(cellsY) * size_t(cellsZ); }
  // The struct the DDA takes (kernels/shared/majorant_dda.h), ready to cross to the device.
  majorant_grid_params params() const;
};

// The voxel range [lo, hi] (clamped to [0, n-1]) along one axis whose trilinear support reaches the
// interval [cellMin, cellMax] grown by MAJORANT_SLACK: floor(cellMin - slack - 0.5) .. ceil(cellMax +
// slack - 0.5). The proof is at the top of majorant_grid.cpp.
void majorantVoxelRange(double cellMin, double cellMax, int n, int* lo, int* hi);

// Bounds `density` (nx×ny×nz voxels, index space as in kernels/shared/grid.h) on cellsX×cellsY×cellsZ
// equal cells over [0, nx]×[0, ny]×[0, nz]. Throws std::invalid_argument for an empty grid, fewer
// than one cell on an axis, or data that does not match the dims.
MajorantGrid buildMajorantGrid(const DenseGrid& density, int cellsX, int cellsY, int cellsZ);

// The automatic majorant grid resolution: cells along the grid's longest axis (chosen by
// measurement, bench/majorant.py).
constexpr int kDefaultMajorantResolution = 16;

// About `target` cells along the grid's longest axis and the same cell edge (rounded) along the
// others: max(1, min(n_i, round(target · n_i / max n))). For the Disney cloud (126×86×154) and 16:
// 13×9×16. Throws std::invalid_argument for non-positive dims or target.
std::array<int, 3> chooseMajorantResolution(int nx, int ny, int nz, int target = kDefaultMajorantResolution);

}  // namespace narval
