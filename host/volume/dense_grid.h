// grid.h: a dense density grid on the host, ready for upload (x fastest, the 3D image order).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <iosfwd>
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

// The largest grid held densely on the host: 8 GiB of floats (1290³, or 2048×2048×512). Loaders
// and the cloud generator refuse larger grids with an error naming the size. On the device such a
// grid goes to sparse bricks when one image or buffer cannot hold it (render/device_grid.h); the
// host copy stays dense (the majorant grid is built from it), so a render holds it once, plus the
// occupied bricks on the device.
constexpr uint64_t kMaxDenseGridBytes = uint64_t(8) << 30;

// Loads `path` by extension (.vdb: FloatGrid `gridName`; .vol: text). Throws InputError naming the
// file on anything wrong (missing file, missing grid with the list of grids present, bad data).
DenseGrid loadGrid(const std::string& path, const std::string& gridName = "density");
// The extension of `path` in lower case (".vdb", ".vol", "" without one): how loadGrid and the
// other readers of grid files tell the formats apart.
std::string gridFileExtension(const std::string& path);
DenseGrid loadVdb(const std::string& path, const std::string& gridName);
DenseGrid loadVol(const std::string& path);
// The .vol text from a seekable stream positioned at its start (loadVol is this on the opened
// file); `path` names it in messages and becomes DenseGrid::source. Throws InputError as loadVol.
// The input is read `chunkBytes` at a time (never more than its size); a token as long as a chunk
// is not a number. Tests and the fuzzer pass small chunks to exercise the chunk boundaries.
DenseGrid parseVol(std::istream& in, const std::string& path, size_t chunkBytes = size_t(1) << 20);

// loadVdb and vdbGridNames read the file in a forked child process on Linux (OpenVDB 10's reader
// aborts or corrupts memory on some corrupt files; the child's death becomes an InputError here).
// NARVAL_VDB_IN_PROCESS=1 reads in-process instead (debuggers, memory checkers).
//
// The names of the float grids in a .vdb file (for error messages and `narval info`).
std::vector<std::string> vdbGridNames(const std::string& path);

// Writes a FloatGrid named `gridName` (fog volume, zero background, zeros inactive, uniform voxel
// size, index (0,0,0) at the origin), atomically (PATH.tmp, then renamed). Throws InputError when the
// file cannot be written, std::invalid_argument for NaN values or data that does not match the dims.
void writeVdb(const std::string& path, const DenseGrid& grid, const std::string& gridName = "density",
              float voxelSize = 1.0f);

// The same file as writeVdb, for a grid produced a slab of z slices at a time (one that need not
// fit in memory densely): fill(z0, z1, out) writes the nx·ny·(z1 - z0) values of slices [z0, z1),
// x fastest, to `out`. Holds one slab of `slabSlices` slices (a positive multiple of 8: whole
// OpenVDB leaf nodes) and the sparse tree. Throws as writeVdb.
void writeVdbSlabs(const std::string& path, int nx, int ny, int nz, int slabSlices,
                   const std::function<void(int, int, float*)>& fill, const std::string& gridName = "density",
                   float voxelSize = 1.0f);

// The one rule every loaded grid obeys: densities are finite and >= 0. Sets grid.maxValue; throws
// InputError "SOURCE: KEY: SUBJECT3 non-finite and 2 negative values (first at voxel X Y Z);
// densities must be finite and >= 0" when any value breaks it (KEY and SUBJECT may be empty).
void checkDensityValues(DenseGrid& grid, const std::string& key, const std::string& subject = "");

// The procedural cloud leaves every voxel whose centre lies within this distance of a face of the
// unit cube (normalised coordinates) at exactly 0: at resolution r that is at least
// ceil(kCloudMargin * r - 0.5) voxels at each face (1 at r = 8, 5 at r = 64, 20 at r = 256).
constexpr float kCloudMargin = 0.08f;

// Procedural cumulus-like cloud: noise-displaced blobs with soft edges, density in [0, 1],
// resolution^3 voxels, deterministic for (resolution, seed). Throws std::invalid_argument for a
// resolution under 8 or over kMaxDenseGridBytes.
DenseGrid makeCloud(int resolution, uint32_t seed);
// Slices [z0, z1) of makeCloud(resolution, seed), the same bits, into `out`
// (resolution²·(z1 - z0) floats, x fastest): for clouds too large to hold densely (make-cloud
// writes them slab by slab with writeVdbSlabs).
void makeCloudSlab(int resolution, uint32_t seed, int z0, int z1, float* out);

}  // namespace narval
