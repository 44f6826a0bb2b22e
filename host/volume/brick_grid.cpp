// brick_grid.cpp: sparse bricks from a dense grid (brick_grid.h; layout in kernels/shared/grid.h).
#include "volume/brick_grid.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "shared/grid.h"

namespace narval {
namespace {

static_assert(kBrickFloats == GRID_BRICK_FLOATS && kBrickEdge == GRID_BRICK, "brick_grid.h mirrors shared/grid.h");
constexpr int kStored = GRID_BRICK_STORED;

void checkGrid(const DenseGrid& grid, const char* who) {
  if (grid.nx < 1 || grid.ny < 1 || grid.nz < 1 || grid.data.size() != grid.voxelCount())
    throw std::invalid_argument(std::string(who) + ": grid dimensions do not match its data");
}

// The voxels a brick stores along one axis that lie inside the grid: [lo, hi).
struct Span {
  int lo, hi;
};
Span storedSpan(int brick, int n) { return {brick * kBrickEdge, std::min(n, brick * kBrickEdge + kStored)}; }

// Whether any stored value of brick (bx, by, bz) is non-zero.
bool brickOccupied(const DenseGrid& g, int bx, int by, int bz) {
  const Span sx = storedSpan(bx, g.nx), sy = storedSpan(by, g.ny), sz = storedSpan(bz, g.nz);
  for (int z = sz.lo; z < sz.hi; ++z)
    for (int y = sy.lo; y < sy.hi; ++y) {
      const float* row = g.data.data() + size_t(g.nx) * (size_t(y) + size_t(g.ny) * size_t(z));
      for (int x = sx.lo; x < sx.hi; ++x)
        if (row[x] != 0.0f) return true;
    }
  return false;
}

}  // namespace

size_t BrickLayout::poolOffsetFloats() const { return (GRID_BRICKS_HEADER + table.size() + 3) / 4 * 4; }

size_t BrickLayout::poolBytes() const { return occupied.size() * kBrickFloats * sizeof(float); }

size_t BrickLayout::bufferFloats() const { return poolOffsetFloats() + occupied.size() * kBrickFloats; }

BrickLayout planBricks(const DenseGrid& grid) {
  checkGrid(grid, "planBricks");
  BrickLayout L;
  L.nx = grid.nx;
  L.ny = grid.ny;
  L.nz = grid.nz;
  L.bricksX = grid_brick_count(grid.nx);
  L.bricksY = grid_brick_count(grid.ny);
  L.bricksZ = grid_brick_count(grid.nz);
  const size_t count = size_t(L.bricksX) * size_t(L.bricksY) * size_t(L.bricksZ);
  // Slots must stay below GRID_BRICK_EMPTY, and the pool offset (an int in the header) below 2^31.
  if (count >= size_t(std::numeric_limits<int32_t>::max()) - GRID_BRICKS_HEADER - 3)
    throw std::invalid_argument("planBricks: " + std::to_string(count) + " bricks are more than the index can hold");
  // Pass 1: occupancy, one byte per brick, in parallel over z slabs of bricks.
  std::vector<uint8_t> full(count, 0);
  const size_t perSlab = size_t(L.bricksX) * size_t(L.bricksY);
  tbb::parallel_for(tbb::blocked_range<int>(0, L.bricksZ), [&](const tbb::blocked_range<int>& r) {
    for (int bz = r.begin(); bz != r.end(); ++bz)
      for (int by = 0; by < L.bricksY; ++by)
        for (int bx = 0; bx < L.bricksX; ++bx)
          full[size_t(bz) * perSlab + size_t(by) * size_t(L.bricksX) + size_t(bx)] =
              brickOccupied(grid, bx, by, bz) ? 1 : 0;
  });
  // Pass 2: slots in table order (deterministic).
  L.table.assign(count, GRID_BRICK_EMPTY);
  for (size_t i = 0; i < count; ++i) {
    if (!full[i]) continue;
    L.table[i] = uint32_t(L.occupied.size());
    L.occupied.push_back(uint32_t(i));
  }
  return L;
}

void writeBrickHeader(const BrickLayout& layout, float* out) {
  const size_t poolOffset = layout.poolOffsetFloats();
  const int32_t header[GRID_BRICKS_HEADER] = {layout.nx, layout.ny, layout.nz, int32_t(poolOffset)};
  std::memcpy(out, header, sizeof(header));
  if (!layout.table.empty())
    std::memcpy(out + GRID_BRICKS_HEADER, layout.table.data(), layout.table.size() * sizeof(uint32_t));
  const size_t used = GRID_BRICKS_HEADER + layout.table.size();
  std::fill(out + used, out + poolOffset, 0.0f);
}

void writeBricks(const DenseGrid& grid, const BrickLayout& layout, size_t firstSlot, size_t count, float* out) {
  checkGrid(grid, "writeBricks");
  if (grid.nx != layout.nx || grid.ny != layout.ny || grid.nz != layout.nz || firstSlot > layout.occupiedCount() ||
      count > layout.occupiedCount() - firstSlot)
    throw std::invalid_argument("writeBricks: the slots or the grid do not match the layout");
  const size_t perSlab = size_t(layout.bricksX) * size_t(layout.bricksY);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const size_t brick = layout.occupied[firstSlot + k];
      const int bz = int(brick / perSlab), by = int(brick % perSlab / size_t(layout.bricksX)),
                bx = int(brick % size_t(layout.bricksX));
      float* dst = out + k * kBrickFloats;
      std::fill(dst, dst + kBrickFloats, 0.0f);
      const Span sx = storedSpan(bx, grid.nx), sy = storedSpan(by, grid.ny), sz = storedSpan(bz, grid.nz);
      for (int z = sz.lo; z < sz.hi; ++z)
        for (int y = sy.lo; y < sy.hi; ++y) {
          const float* row = grid.data.data() + size_t(grid.nx) * (size_t(y) + size_t(grid.ny) * size_t(z));
          std::copy(row + sx.lo, row + sx.hi,
                    dst + size_t(z - sz.lo) * kStored * kStored + size_t(y - sy.lo) * kStored);
        }
    }
  });
}

std::vector<float> buildBrickBuffer(const DenseGrid& grid, const BrickLayout& layout) {
  std::vector<float> buf(layout.bufferFloats());
  writeBrickHeader(layout, buf.data());
  writeBricks(grid, layout, 0, layout.occupiedCount(), buf.data() + layout.poolOffsetFloats());
  return buf;
}

}  // namespace narval
