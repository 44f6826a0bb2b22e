// brick_grid.h: a dense grid cut into sparse bricks, the layout kernels/shared/grid.h reads with
// -DGRID_STORAGE_BRICKS (8³ voxels per brick plus a one-voxel apron, an index table, a pool of the
// occupied bricks; the layout is documented there). For grids that fit neither one 3D image nor one
// buffer on the device: only bricks holding a non-zero value take memory.
//
// Two passes, so the pool can be written straight into device memory (render/device_grid.cpp) in
// chunks without a second whole copy on the host: planBricks finds the occupied bricks,
// writeBrickHeader and writeBricks fill the buffer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "volume/dense_grid.h"

namespace narval {

struct BrickLayout {
  int nx = 0, ny = 0, nz = 0;                 // voxels
  int bricksX = 0, bricksY = 0, bricksZ = 0;  // bricks per axis: ceil(n / 8)
  // Per brick, x fastest (bx + bricksX·(by + bricksY·bz)): its slot in the pool, or
  // GRID_BRICK_EMPTY (0xffffffff) when all 9³ values it would store (apron included) are 0.
  // Slots are given in table order.
  std::vector<uint32_t> table;
  // The brick (table index) in each pool slot: occupied[slot].
  std::vector<uint32_t> occupied;

  size_t brickCount() const { return table.size(); }
  size_t occupiedCount() const { return occupied.size(); }
  // Where the pool starts in the device buffer, in floats: header and table, rounded up to 16 bytes.
  size_t poolOffsetFloats() const;
  // The device buffer: header, table, padding, pool.
  size_t bufferFloats() const;
  size_t bufferBytes() const { return bufferFloats() * sizeof(float); }
  size_t poolBytes() const;
};

// Floats of one stored brick (9³) and voxels per brick edge, as in shared/grid.h.
constexpr size_t kBrickFloats = 729;
constexpr int kBrickEdge = 8;

// Which bricks of `grid` hold a non-zero value (apron included). Throws std::invalid_argument when
// the dims do not match the data or the grid has more bricks than the table can index (2^32 - 1).
// Parallel (TBB) over z slabs of bricks; the result does not depend on the thread count.
BrickLayout planBricks(const DenseGrid& grid);

// The device buffer's first poolOffsetFloats() floats: GRID_BRICKS_HEADER slots (nx, ny, nz, pool
// offset), the table, zero padding. `out` holds poolOffsetFloats() floats.
void writeBrickHeader(const BrickLayout& layout, float* out);

// The bricks in pool slots [firstSlot, firstSlot + count): count · 729 floats into `out`, x fastest
// within a brick; apron values beyond the grid are 0.
void writeBricks(const DenseGrid& grid, const BrickLayout& layout, size_t firstSlot, size_t count, float* out);

// The whole device buffer in host memory (tests, small grids): header, table, pool.
std::vector<float> buildBrickBuffer(const DenseGrid& grid, const BrickLayout& layout);

}  // namespace narval
