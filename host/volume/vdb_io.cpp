// vdb_io.cpp: OpenVDB -> DenseGrid: reading, listing and describing a .vdb file's grids (writing:
// vdb_write.cpp). OpenVDB's headers are slow to compile: only these two files include them.
#include "volume/child_reader.h"
#include "volume/vdb_io.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/Dense.h>
#include <tbb/task_arena.h>

#include "core/atomic_file.h"
#include "core/input_error.h"
#include "volume/grid_info.h"

namespace narval {

namespace fs = std::filesystem;

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

namespace {

// What a file OpenVDB cannot read is: its own messages ("iostream error", "Map is not registered")
// do not say.
const std::string kUnreadable = "not a readable OpenVDB file: truncated, corrupt or of another format";

// A missing or unreadable file gets a plain message before OpenVDB sees it (its own messages name
// a temporary copy or nothing at all).
void requireReadableFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw inputError(path, "", "cannot open the file: no such file");
  if (fs::is_directory(st)) throw inputError(path, "", "cannot open the file: it is a directory");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw inputError(path, "", std::string("cannot open the file: ") + std::strerror(errno));
}

std::string quoted(const std::string& name) { return "'" + name + "'"; }

struct GridEntry {
  std::string name;
  std::string valueType;  // "float", "vec3s", ...
  bool isFloat = false;
};

// Every grid in the file, read through our own stream with exceptions on: OpenVDB does not check
// for short reads, so io::File hands back a truncated file's grid silently filled with garbage or
// zeros, takes a file cut inside its header for one with no grids, and reads a cut grid's
// descriptor as a length of gigabytes; here any read past the end throws. io::Stream reads every
// grid in the file (all small next to the dense copy). InputError when the file cannot be read.
openvdb::GridPtrVecPtr readAllGrids(const std::string& path) {
  try {
    std::ifstream in(path, std::ios::binary);
    in.exceptions(std::ios::failbit | std::ios::badbit);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    return stream.getGrids();
  } catch (const std::ios_base::failure&) {
    throw inputError(path, "", kUnreadable + " (a read ran past its end)");
  } catch (const std::exception& e) {
    throw inputError(path, "", kUnreadable + " (OpenVDB: " + oneLine(e.what()) + ")");
  }
}

// The grids' names and types, sorted by name so that a message does not depend on the writer's order.
std::vector<GridEntry> listGrids(const openvdb::GridPtrVec& grids) {
  std::vector<GridEntry> out;
  for (const openvdb::GridBase::Ptr& g : grids)
    out.push_back({g->getName(), g->valueType(), g->isType<openvdb::FloatGrid>()});
  std::sort(out.begin(), out.end(), [](const GridEntry& a, const GridEntry& b) { return a.name < b.name; });
  return out;
}

std::string describeGrids(const std::vector<GridEntry>& grids) {
  if (grids.empty()) return "the file has no grids";
  std::string s = "the file has: ";
  for (size_t i = 0; i < grids.size(); ++i) {
    if (i) s += ", ";
    s += grids[i].name.empty() ? std::string("(unnamed)") : grids[i].name;
    if (!grids[i].isFloat) s += " (" + grids[i].valueType + ")";
  }
  return s;
}

std::string dimsString(int64_t x, int64_t y, int64_t z) {
  return std::to_string(x) + "x" + std::to_string(y) + "x" + std::to_string(z);
}

// The grid named `gridName` of `all`, which must exist and hold floats: one line naming what the
// file has otherwise.
openvdb::FloatGrid::Ptr requireFloatGrid(const std::string& path, const std::string& gridName,
                                         const openvdb::GridPtrVec& all) {
  for (const openvdb::GridBase::Ptr& g : all)
    if (g->getName() == gridName && g->isType<openvdb::FloatGrid>()) return openvdb::gridPtrCast<openvdb::FloatGrid>(g);
  const std::vector<GridEntry> grids = listGrids(all);
  const auto entry = std::find_if(grids.begin(), grids.end(), [&](const GridEntry& g) { return g.name == gridName; });
  if (entry == grids.end())
    throw inputError(path, "grid", "no grid named " + quoted(gridName) + " (" + describeGrids(grids) + ")");
  std::string floats;
  for (const GridEntry& g : grids)
    if (g.isFloat) floats += (floats.empty() ? "" : ", ") + g.name;
  throw inputError(path, "grid",
                   quoted(gridName) + " is a " + entry->valueType + " grid; narval needs a float grid (" +
                       (floats.empty() ? std::string("the file has none") : "float grids in the file: " + floats) + ")");
}

// Dims are ints, an x-y slice's voxel count too (grid_trilinear's stride), and the whole grid at
// most kMaxDenseGridBytes (host/volume/dense_grid.h). Checked in this order, no product overflows;
// in 64 bits, as a corrupt tree can span more than 2^31 voxels per axis.
void requireDenseSize(const std::string& path, const std::string& gridName, const int64_t dim[3]) {
  constexpr int64_t kMaxDim = INT32_MAX;
  constexpr uint64_t kMaxVoxels = kMaxDenseGridBytes / sizeof(float);
  const bool tooBig = dim[0] > kMaxDim || dim[1] > kMaxDim || dim[2] > kMaxDim ||
                      uint64_t(dim[0]) * uint64_t(dim[1]) > uint64_t(kMaxDim) ||
                      uint64_t(dim[0]) * uint64_t(dim[1]) * uint64_t(dim[2]) > kMaxVoxels;
  if (!tooBig) return;
  const bool showCount = dim[0] < (1 << 20) && dim[1] < (1 << 20) && dim[2] < (1 << 20);
  const uint64_t voxels = uint64_t(dim[0]) * uint64_t(dim[1]) * uint64_t(dim[2]);
  throw inputError(path, "grid",
                   quoted(gridName) + " active bounding box " + dimsString(dim[0], dim[1], dim[2]) +
                       (showCount ? " = " + std::to_string(voxels) + " voxels needs " +
                                        std::to_string((voxels * sizeof(float)) >> 20) + " MiB as dense floats,"
                                  : " is") +
                       " over the " + std::to_string(kMaxDenseGridBytes >> 20) + " MiB limit");
}

// Our index u (voxel i covers [i, i+1]) -> vdb index ijk = u - 0.5 + bbox.min -> world, from the
// affine map's row-vector matrix m (world = [ijk 1] * m).
void setIndexToWorld(Decoded& out, const openvdb::Mat4d& m, const openvdb::CoordBBox& bbox) {
  const openvdb::Vec3d shift(bbox.min().x() - 0.5, bbox.min().y() - 0.5, bbox.min().z() - 0.5);
  double maxDiag = 0.0;
  for (int r = 0; r < 3; ++r) maxDiag = std::max(maxDiag, std::abs(m[r][r]));
  for (int r = 0; r < 3; ++r) {
    double t = m[3][r];
    for (int c = 0; c < 3; ++c) {
      out.indexToWorld[size_t(r * 4 + c)] = float(m[c][r]);
      t += shift[c] * m[c][r];
      if (r != c && std::abs(m[c][r]) > 1e-9 * maxDiag) out.scaleTranslate = false;
    }
    out.indexToWorld[size_t(r * 4 + 3)] = float(t);
  }
}

// Everything that parses the file: grid lookup, type and transform checks, the active bounding
// box, the size limit and the dense copy. Throws InputError (the full one-line message).
template <typename Allocate>
Decoded decodeVdb(const std::string& path, const std::string& gridName, Allocate&& allocate, bool serial) {
  const openvdb::GridPtrVecPtr all = readAllGrids(path);  // keeps the grid alive
  const openvdb::FloatGrid::Ptr grid = requireFloatGrid(path, gridName, *all);
  // Transform: affine only (a frustum map is not linear).
  const openvdb::math::MapBase::ConstPtr map = grid->transform().baseMap();
  if (!map->isLinear()) {
    throw inputError(path, "grid", quoted(gridName) + " has a non-affine index-to-world transform (" + map->type() +
                                       "); narval supports affine transforms only");
  }
  const openvdb::CoordBBox bbox = grid->evalActiveVoxelBoundingBox();
  if (grid->activeVoxelCount() == 0 || bbox.empty()) {
    throw inputError(path, "grid", quoted(gridName) + " has no active voxels");
  }
  const int64_t dim[3] = {int64_t(bbox.max().x()) - bbox.min().x() + 1, int64_t(bbox.max().y()) - bbox.min().y() + 1,
                          int64_t(bbox.max().z()) - bbox.min().z() + 1};
  requireDenseSize(path, gridName, dim);
  Decoded out;
  out.nx = int(dim[0]);
  out.ny = int(dim[1]);
  out.nz = int(dim[2]);
  {
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bbox, allocate(size_t(dim[0] * dim[1] * dim[2])));
    openvdb::tools::copyToDense(*grid, dense, serial);
  }
  setIndexToWorld(out, map->getAffineMap()->getMat4(), bbox);
  return out;
}

// Every grid of the file read whole and described (grid_info.h). Throws InputError.
std::vector<GridInfo> describeVdbGrids(const std::string& path) {
  std::vector<GridInfo> out;
  const openvdb::GridPtrVecPtr grids = readAllGrids(path);
  for (const openvdb::GridBase::Ptr& g : *grids) {
    GridInfo info;
    info.name = g->getName();
    info.valueType = g->valueType();
    info.gridClass = openvdb::GridBase::gridClassToString(g->getGridClass());
    info.activeVoxels = g->activeVoxelCount();
    info.memoryBytes = g->memUsage();
    const openvdb::Vec3d vs = g->voxelSize();
    info.voxelSize = {vs.x(), vs.y(), vs.z()};
    const openvdb::CoordBBox bbox = g->evalActiveVoxelBoundingBox();
    if (info.activeVoxels > 0 && !bbox.empty()) {
      for (int a = 0; a < 3; ++a) {
        info.indexMin[size_t(a)] = bbox.min()[a];
        info.indexMax[size_t(a)] = bbox.max()[a];
        info.worldMin[size_t(a)] = INFINITY;
        info.worldMax[size_t(a)] = -INFINITY;
      }
      for (int corner = 0; corner < 8; ++corner) {
        const openvdb::Vec3d p(corner & 1 ? bbox.max().x() + 0.5 : bbox.min().x() - 0.5,
                               corner & 2 ? bbox.max().y() + 0.5 : bbox.min().y() - 0.5,
                               corner & 4 ? bbox.max().z() + 0.5 : bbox.min().z() - 0.5);
        const openvdb::Vec3d w = g->transform().indexToWorld(p);
        for (int a = 0; a < 3; ++a) {
          info.worldMin[size_t(a)] = std::min(info.worldMin[size_t(a)], w[a]);
          info.worldMax[size_t(a)] = std::max(info.worldMax[size_t(a)], w[a]);
        }
      }
      const openvdb::Coord dim = bbox.dim();
      if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) {
        info.denseBytes = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z()) * sizeof(float);
        info.hasRange = true;
        info.valueMin = INFINITY;
        info.valueMax = -INFINITY;
        for (auto v = f->cbeginValueOn(); v; ++v) {
          info.valueMin = std::min(info.valueMin, double(*v));
          info.valueMax = std::max(info.valueMax, double(*v));
        }
      } else if (auto v3 = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g)) {
        info.hasRange = true;
        info.valueMin = INFINITY;
        info.valueMax = -INFINITY;
        for (auto v = v3->cbeginValueOn(); v; ++v) {
          info.valueMin = std::min(info.valueMin, double(v->length()));
          info.valueMax = std::max(info.valueMax, double(v->length()));
        }
      }
    }
    out.push_back(info);
  }
  return out;
}

#if defined(__linux__)
bool decodeInChild(const std::string& path, const std::string& gridName, DenseGrid& out) {
  const std::string cannot = "cannot read " + quoted(gridName);
  Fd mem;
  ChildRecord rec{};
  auto work = [&](int fd, ChildRecord& result) {
    void* map = nullptr;
    size_t mapBytes = 0;
    result.decoded = decodeVdb(
        path, gridName,
        [&](size_t n) {
          mapBytes = kDataOffset + n * sizeof(float);
          if (::ftruncate(fd, off_t(mapBytes)) != 0) throw std::bad_alloc();
          map = ::mmap(nullptr, mapBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
          if (map == MAP_FAILED) throw std::bad_alloc();
          return reinterpret_cast<float*>(static_cast<char*>(map) + kDataOffset);
        },
        /*serial=*/true);
    if (map) ::munmap(map, mapBytes);
  };
  if (!runInChild(path, cannot, work, mem, rec)) return false;

  const Decoded& d = rec.decoded;
  const uint64_t voxels = uint64_t(d.nx) * uint64_t(d.ny) * uint64_t(d.nz);
  struct stat st {};
  if (d.nx <= 0 || d.ny <= 0 || d.nz <= 0 || voxels * sizeof(float) > kMaxDenseGridBytes ||
      ::fstat(mem.fd, &st) != 0 || uint64_t(st.st_size) != kDataOffset + voxels * sizeof(float)) {
    throw inputError(path, "grid", cannot + " (the reader process returned an inconsistent result)");
  }
  out.nx = d.nx;
  out.ny = d.ny;
  out.nz = d.nz;
  out.indexToWorld = d.indexToWorld;
  out.fileTransformIsScaleTranslate = d.scaleTranslate;
  // Copied out a slice at a time, each slice's pages released from the memfd (a hole punched)
  // once copied: the grid is held about once, not twice (4 GiB, not 8, for a 1024³ grid).
  out.data.clear();
  out.data.reserve(voxels);
  void* map = ::mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_SHARED, mem.fd, 0);
  if (map == MAP_FAILED) throw inputError(path, "grid", cannot + " (cannot map the reader's result)");
  const float* values = reinterpret_cast<const float*>(static_cast<const char*>(map) + kDataOffset);
  constexpr size_t kSlice = size_t(64) << 20;  // bytes, a multiple of the page size
  static_assert(kSlice % 4096 == 0 && kDataOffset % 4096 == 0, "holes are punched in whole pages");
  for (size_t done = 0; done < voxels;) {
    const size_t n = std::min<size_t>(kSlice / sizeof(float), voxels - done);
    out.data.insert(out.data.end(), values + done, values + done + n);
    ::fallocate(mem.fd, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, off_t(kDataOffset + done * sizeof(float)),
                off_t(n * sizeof(float)));  // best effort: a kernel without it only keeps the memory longer
    done += n;
  }
  ::munmap(map, size_t(st.st_size));
  return true;
}

bool describeInChild(const std::string& path, std::vector<GridInfo>& infos) {
  std::string text;
  if (!textInChild(path, "cannot describe the grids", [&] { return gridInfoJson(path, describeVdbGrids(path)); },
                   &text))
    return false;
  infos = gridInfoFromJson(text);
  return true;
}
#endif

}  // namespace

std::vector<GridInfo> inspectVdb(const std::string& path) {
  initOpenVdb();
  requireReadableFile(path);
#if defined(__linux__)
  std::vector<GridInfo> infos;
  if (describeInChild(path, infos)) return infos;
#endif
  return describeVdbGrids(path);
}

DenseGrid loadVdb(const std::string& path, const std::string& gridName) {
  initOpenVdb();
  requireReadableFile(path);
  DenseGrid out;
  out.source = path;
  bool done = false;
#if defined(__linux__)
  done = decodeInChild(path, gridName, out);
#endif
  if (!done) {
    const Decoded d = decodeVdb(
        path, gridName,
        [&](size_t n) {
          out.data.assign(n, 0.0f);
          return out.data.data();
        },
        /*serial=*/false);
    out.nx = d.nx;
    out.ny = d.ny;
    out.nz = d.nz;
    out.indexToWorld = d.indexToWorld;
    out.fileTransformIsScaleTranslate = d.scaleTranslate;
  }
  checkDensityValues(out, "grid", quoted(gridName) + " has ");
  return out;
}

}  // namespace narval
