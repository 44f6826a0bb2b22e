// dense_grid.h: a dense density grid on the host, ready for upload (x fastest, the 3D image order).
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
  // Index space (voxel i: [i, i+1], centre i + 0.5) to the file's world space, row-major 3x4: identity
  // for .vol and generated grids; .vdb: the file's affine map composed with the shift by active bbox min and 0.5.
  std::array<float, 12> indexToWorld{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  bool fileTransformIsScaleTranslate = true;  // false: rotation/shear (warn in "unit" grid space)
  float maxValue = 0.0f;
  std::string source;  // file path, for messages

  float at(int x, int y, int z) const { return data[size_t(x) + size_t(nx) * (size_t(y) + size_t(ny) * size_t(z))]; }
  size_t voxelCount() const { return size_t(nx) * size_t(ny) * size_t(nz); }
};

// The largest grid held densely on the host: 8 GiB of floats (1290³, 2048×2048×512); loaders and the cloud
// generator refuse larger with an error naming the size. Beyond one device image or buffer a grid goes to
// bricks (render/device_grid.h), but the host copy stays dense (the majorant grid is built from it).
constexpr uint64_t kMaxDenseGridBytes = uint64_t(8) << 30;

// Loads `path` by extension (.vdb: FloatGrid `gridName`; .vol: text). Throws InputError naming the
// file on anything wrong (missing file, missing grid with the list of grids present, bad data).
DenseGrid loadGrid(const std::string& path, const std::string& gridName = "density");
// The lower-case extension of `path` (".vdb", ".vol", "" without one): how grid readers tell formats apart.
std::string gridFileExtension(const std::string& path);
// Reads in a forked child on Linux, as inspectVdb does (OpenVDB 10's reader aborts or corrupts memory
// on some corrupt files; the child's death becomes an InputError); NARVAL_VDB_IN_PROCESS=1 reads
// in-process (debuggers, memory checkers).
DenseGrid loadVdb(const std::string& path, const std::string& gridName);
DenseGrid loadVol(const std::string& path);
// loadVol on a seekable stream at its start; `path` names it in messages and becomes DenseGrid::source.
// Reads `chunkBytes` at a time (small ones test the boundaries); a token as long as a chunk is not a number.
DenseGrid parseVol(std::istream& in, const std::string& path, size_t chunkBytes = size_t(1) << 20);

// Writes a FloatGrid named `gridName` (fog volume, zero background, zeros inactive, uniform voxel
// size, index (0,0,0) at the origin), atomically (PATH.tmp, then renamed). Throws InputError when the
// file cannot be written, std::invalid_argument for NaN values or data that does not match the dims.
void writeVdb(const std::string& path, const DenseGrid& grid, const std::string& gridName = "density",
              float voxelSize = 1.0f);

// writeVdb's file for a grid made a slab of z slices at a time (it need not fit densely): fill(z0, z1, out)
// writes slices [z0, z1) (nx·ny·(z1 - z0) values, x fastest). Holds one slab of `slabSlices` (a positive
// multiple of 8: whole OpenVDB leaf nodes) and the sparse tree; throws as writeVdb.
void writeVdbSlabs(const std::string& path, int nx, int ny, int nz, int slabSlices,
                   const std::function<void(int, int, float*)>& fill, const std::string& gridName = "density",
                   float voxelSize = 1.0f);

// The one rule every loaded grid obeys: densities are finite and >= 0. Sets grid.maxValue; throws
// InputError "SOURCE: KEY: SUBJECT3 non-finite and 2 negative values (first at voxel X Y Z);
// densities must be finite and >= 0" when any value breaks it (KEY and SUBJECT may be empty).
void checkDensityValues(DenseGrid& grid, const std::string& key, const std::string& subject = "");

// The procedural cloud is exactly 0 at every voxel centred within this distance of a unit-cube face
// (normalised): at resolution r, at least ceil(kCloudMargin * r - 0.5) voxels a face (1 at 8, 5 at 64, 20 at 256).
constexpr float kCloudMargin = 0.08f;

// Procedural cumulus-like cloud of resolution^3 voxels, density in [0, 1], deterministic for (resolution,
// seed). Throws std::invalid_argument for a resolution under 8 or over kMaxDenseGridBytes.
DenseGrid makeCloud(int resolution, uint32_t seed);
// Slices [z0, z1) of makeCloud(resolution, seed), the same bits, into `out` (resolution²·(z1 - z0)
// floats, x fastest): make-cloud writes clouds too large to hold densely slab by slab (writeVdbSlabs).
void makeCloudSlab(int resolution, uint32_t seed, int z0, int z1, float* out);

}  // namespace narval
