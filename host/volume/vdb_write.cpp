// vdb_write.cpp: DenseGrid -> OpenVDB files (make-cloud's output), written atomically.
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include "core/atomic_file.h"
#include "core/input_error.h"
#include "volume/vdb_io.h"

namespace narval {
namespace {

// An unwritable output is the user's to fix: InputError "PATH: cannot write: REASON" (exit 2).
void writeGrids(const std::string& path, const openvdb::GridPtrVec& grids) {
  try {
    writeAtomically(path, [&](const std::string& tmp) {
      openvdb::io::File out(tmp);
      out.write(grids);
      out.close();
    });
  } catch (const std::runtime_error& e) {
    throw InputError(oneLine(e.what()));
  }
}

// The grid's metadata, then the file (atomically).
void finishAndWrite(const std::string& path, openvdb::FloatGrid::Ptr vdb, const std::string& gridName, float voxelSize) {
  vdb->setName(gridName);
  vdb->setGridClass(openvdb::GRID_FOG_VOLUME);
  vdb->setTransform(openvdb::math::Transform::createLinearTransform(double(voxelSize)));
  vdb->insertMeta("creator", openvdb::StringMetadata("narval"));
  writeGrids(path, {vdb});
}


}  // namespace

void writeVdbSlabs(const std::string& path, int nx, int ny, int nz, int slabSlices,
                   const std::function<void(int, int, float*)>& fill, const std::string& gridName, float voxelSize) {
  initOpenVdb();
  if (nx < 1 || ny < 1 || nz < 1 || slabSlices < 8 || slabSlices % 8 != 0)
    throw std::invalid_argument("writeVdbSlabs: bad dimensions or slab depth (a positive multiple of 8)");
  if (!(voxelSize > 0.0f) || !std::isfinite(voxelSize)) {
    throw std::invalid_argument("writeVdb: voxel size must be positive and finite");
  }
  openvdb::FloatGrid::Ptr vdb = openvdb::FloatGrid::create(0.0f);
  const size_t slice = size_t(nx) * size_t(ny);
  std::vector<float> slab(slice * size_t(std::min(slabSlices, nz)));
  // Slabs start at multiples of 8 slices: every leaf node (8³ voxels from index 0) lies in one
  // slab, so copyFromDense builds each leaf whole, as it does from the whole grid.
  for (int z0 = 0; z0 < nz; z0 += slabSlices) {
    const int z1 = std::min(nz, z0 + slabSlices);
    fill(z0, z1, slab.data());
    const size_t n = slice * size_t(z1 - z0);
    const size_t nans = size_t(std::count_if(slab.begin(), slab.begin() + long(n), [](float v) { return std::isnan(v); }));
    if (nans > 0) throw std::invalid_argument("writeVdb: the grid holds " + std::to_string(nans) + " NaN values");
    const openvdb::CoordBBox bbox(openvdb::Coord(0, 0, z0), openvdb::Coord(nx - 1, ny - 1, z1 - 1));
    const openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bbox, slab.data());
    openvdb::tools::copyFromDense(dense, *vdb, /*tolerance=*/0.0f, /*serial=*/false);
  }
  finishAndWrite(path, vdb, gridName, voxelSize);
}

void writeVdb(const std::string& path, const DenseGrid& grid, const std::string& gridName, float voxelSize) {
  initOpenVdb();
  if (grid.nx < 0 || grid.ny < 0 || grid.nz < 0 || grid.data.size() != grid.voxelCount()) {
    throw std::invalid_argument("writeVdb: grid dimensions " + std::to_string(grid.nx) + "x" + std::to_string(grid.ny) + "x" +
                                std::to_string(grid.nz) +
                                " do not match its " + std::to_string(grid.data.size()) + " values");
  }
  // copyFromDense would turn NaN into inactive background (|NaN - 0| <= 0 is false either way):
  // refuse it instead of silently changing the data.
  const size_t nans = size_t(std::count_if(grid.data.begin(), grid.data.end(), [](float v) { return std::isnan(v); }));
  if (nans > 0) throw std::invalid_argument("writeVdb: the grid holds " + std::to_string(nans) + " NaN values");
  if (!(voxelSize > 0.0f) || !std::isfinite(voxelSize)) {
    throw std::invalid_argument("writeVdb: voxel size must be positive and finite");
  }
  openvdb::FloatGrid::Ptr vdb = openvdb::FloatGrid::create(0.0f);
  if (grid.voxelCount() > 0) {
    const openvdb::CoordBBox bbox(openvdb::Coord(0, 0, 0), openvdb::Coord(grid.nx - 1, grid.ny - 1, grid.nz - 1));
    // Dense only reads through this pointer (copyFromDense takes it const).
    const openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bbox, const_cast<float*>(grid.data.data()));
    openvdb::tools::copyFromDense(dense, *vdb, /*tolerance=*/0.0f, /*serial=*/false);
  }
  finishAndWrite(path, vdb, gridName, voxelSize);
}

}  // namespace narval
