// vdb_io.h: what vdb_io.cpp (reading) and vdb_write.cpp (writing) share; the public functions are
// in dense_grid.h and grid_info.h.
#pragma once

#include <array>
#include <string>

#include "volume/dense_grid.h"

namespace narval {

// openvdb::initialize(), once per process.
void initOpenVdb();

// A grid as decoded (vdb_io.cpp, decodeVdb): its size and index-to-world map; the dense values go
// where the caller asked.
struct Decoded {
  int nx = 0, ny = 0, nz = 0;
  std::array<float, 12> indexToWorld{};
  bool scaleTranslate = true;
};

}  // namespace narval
