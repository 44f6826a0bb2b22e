// grid.h: a dense density grid on the host, ready for upload (x fastest, the 3D image order).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace narval {

struct DenseGrid {
  int nx = 0, ny = 0, nz = 0;
  std::vector<float> data;  // nx*ny*nz values, index x + nx*(y + ny*z)
  // Maps our index space (voxel i covers [i, i+1], centre i + 0.5) to the file's world space,
  // row-major 3x4. For .vol and generated grids: identity. For .vdb: the file's affine
  // index-to-world map composed with the shift by the active bounding box minimum and 0.5.
  std::array<float, 12> indexToWorld{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  bool fileTransformIsScaleTranslate = true;  // false: rotation/shear (warn in "unit" grid space)
  float maxValue = 0.0f;
  std::string source;  // file path, for messages

  float at(int x, int y, int z) const { return data[size_t(x) + size_t(nx) * (size_t(y) + size_t(ny) * size_t(z))]; }
  size_t voxelCount() const { return size_t(nx) * size_t(ny) * size_t(nz); }
};

// Loads `path` by extension (.vdb: FloatGrid `gridName`; .vol: text). Throws InputError naming the
// file on anything wrong (missing file, missing grid with the list of grids present, bad data).
DenseGrid loadGrid(const std::string& path, const std::string& gridName = "density");
DenseGrid loadVdb(const std::string& path, const std::string& gridName);
DenseGrid loadVol(const std::string& path);

// The names of the float grids in a .vdb file (for error messages and `narval info`).
std::vector<std::string> vdbGridNames(const std::string& path);

// Writes a FloatGrid named `gridName` (zero background, values at or below `tolerance` inactive).
void writeVdb(const std::string& path, const DenseGrid& grid, const std::string& gridName = "density",
              float voxelSize = 1.0f);

// Procedural cumulus-like cloud: noise-displaced blobs with soft edges, density in [0, 1],
// resolution^3 voxels, deterministic for (resolution, seed).
DenseGrid makeCloud(int resolution, uint32_t seed);

}  // namespace narval
