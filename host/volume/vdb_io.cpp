// vdb_io.cpp: OpenVDB <-> DenseGrid. The only translation unit that includes OpenVDB (it costs
// ~15 s to compile), so everything OpenVDB-related lives here, test-file writers included.
#include "volume/grid.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/Dense.h>

#include "scene/input_error.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

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

// Opens `path` (no delayed loading: no memory map, every read goes through the stream and fails
// cleanly on a truncated file) and lists its grids.
std::vector<GridEntry> listGrids(openvdb::io::File& file, const std::string& path) {
  std::vector<GridEntry> out;
  try {
    file.open(/*delayLoad=*/false);
    openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
    for (const openvdb::GridBase::Ptr& g : *grids) {
      out.push_back({g->getName(), g->valueType(), g->isType<openvdb::FloatGrid>()});
    }
  } catch (const std::exception& e) {
    throw inputError(path, "", std::string("not a readable OpenVDB file (") + e.what() + ")");
  }
  return out;
}

// Every grid in the file, read through our own stream with exceptions on: OpenVDB does not check
// for short reads, so io::File hands back a truncated file's grid silently filled with garbage or
// zeros; here any read past the end throws std::ios_base::failure. io::Stream reads every grid in
// the file (all small next to the dense copy).
openvdb::GridPtrVecPtr readAllGrids(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  in.exceptions(std::ios::failbit | std::ios::badbit);
  openvdb::io::Stream stream(in, /*delayLoad=*/false);
  return stream.getGrids();
}

// OpenVDB 10's readers trust the sizes and flags they find in the file: corrupted bytes inside
// compressed leaf data (a size field larger than its buffer, a bad mask flag) overflow a heap
// buffer in io::readCompressedValues and abort the process ("double free or corruption") or,
// worse, corrupt memory silently. That cannot be caught in-process, so a forked child reads the
// file first (single-threaded, nothing shared) and reports whether it survived. True: the child
// died on a signal. False: it finished (exceptions included: the parent reports those itself) or
// the check could not run (no fork, a child stuck past the time limit: it is killed and the
// parent reads the file as it would have anyway).
bool readerCrashes(const std::string& path) {
#if defined(__unix__) || defined(__APPLE__)
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    // Child: no core file, no allocator diagnostics on the parent's terminal, no exit handlers.
    struct rlimit noCore{0, 0};
    ::setrlimit(RLIMIT_CORE, &noCore);
    const int devNull = ::open("/dev/null", O_WRONLY);
    if (devNull >= 0) ::dup2(devNull, 2);
    try {
      readAllGrids(path);
    } catch (...) {
    }
    ::_exit(0);
  }
  // 60 s plus 1 s per 10 MB: far beyond any healthy read.
  const double limit = 60.0 + double(ec ? 0 : size) / 1e7;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  for (useconds_t nap = 200;; nap = std::min<useconds_t>(nap * 2, 20000)) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFSIGNALED(status);
    if (r < 0 && errno != EINTR) return false;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limit) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      return false;
    }
    ::usleep(nap);
  }
#else
  (void)path;
  return false;
#endif
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

std::string dimsString(uint64_t x, uint64_t y, uint64_t z) {
  return std::to_string(x) + "x" + std::to_string(y) + "x" + std::to_string(z);
}

// Writes with `write(tmpPath)` then renames over `path`, so a reader never sees half a file.
template <typename WriteFn>
void writeAtomically(const std::string& path, WriteFn&& write) {
  const std::string tmp = path + ".tmp";
  try {
    write(tmp);
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw inputError(path, "", std::string("cannot write the file (") + e.what() + ")");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw inputError(path, "", "cannot write the file (rename failed: " + ec.message() + ")");
  }
}

void writeGrids(const std::string& path, const openvdb::GridPtrVec& grids) {
  writeAtomically(path, [&](const std::string& tmp) {
    openvdb::io::File out(tmp);
    out.write(grids);
    out.close();
  });
}

}  // namespace

std::vector<std::string> vdbGridNames(const std::string& path) {
  initOpenVdb();
  requireReadableFile(path);
  openvdb::io::File file(path);
  std::vector<std::string> names;
  for (const GridEntry& g : listGrids(file, path)) {
    if (g.isFloat) names.push_back(g.name);
  }
  return names;
}

DenseGrid loadVdb(const std::string& path, const std::string& gridName) {
  initOpenVdb();
  requireReadableFile(path);
  openvdb::io::File file(path);
  const std::vector<GridEntry> grids = listGrids(file, path);

  const auto entry = std::find_if(grids.begin(), grids.end(),
                                  [&](const GridEntry& g) { return g.name == gridName; });
  if (entry == grids.end()) {
    throw inputError(path, "grid", "no grid named " + quoted(gridName) + " (" + describeGrids(grids) + ")");
  }
  if (!entry->isFloat) {
    std::string floats;
    for (const GridEntry& g : grids) {
      if (g.isFloat) floats += (floats.empty() ? "" : ", ") + g.name;
    }
    throw inputError(path, "grid",
                     quoted(gridName) + " is a " + entry->valueType + " grid; narval needs a float grid (" +
                         (floats.empty() ? std::string("the file has none") : "float grids in the file: " + floats) +
                         ")");
  }

  file.close();

  // The grid data is read through our own stream with exceptions on (see readAllGrids), after a
  // forked child has survived reading the same file (see readerCrashes).
  if (readerCrashes(path)) {
    throw inputError(path, "grid", "cannot read " + quoted(gridName) +
                                       " (the file is corrupt: OpenVDB's reader crashes on it)");
  }
  openvdb::FloatGrid::Ptr grid;
  try {
    const openvdb::GridPtrVecPtr all = readAllGrids(path);  // keep it alive through the loop
    for (const openvdb::GridBase::Ptr& g : *all) {
      if (g->getName() == gridName) {
        grid = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
        break;
      }
    }
  } catch (const std::ios_base::failure&) {
    throw inputError(path, "grid", "cannot read " + quoted(gridName) +
                                       " (the file is truncated or corrupt: a read ran past its end)");
  } catch (const std::exception& e) {
    throw inputError(path, "grid", "cannot read " + quoted(gridName) + " (the file is truncated or corrupt: " +
                                       e.what() + ")");
  }
  if (!grid) throw inputError(path, "grid", "cannot read " + quoted(gridName) + " as a float grid");

  // Transform: affine only (a frustum map is not linear).
  const openvdb::math::MapBase::ConstPtr map = grid->transform().baseMap();
  if (!map->isLinear()) {
    throw inputError(path, "grid", quoted(gridName) + " has a non-affine index-to-world transform (" + map->type() +
                                       "); narval supports affine transforms only");
  }
  const openvdb::Mat4d m = map->getAffineMap()->getMat4();  // row vectors: world = [ijk 1] * m

  const openvdb::CoordBBox bbox = grid->evalActiveVoxelBoundingBox();
  if (grid->activeVoxelCount() == 0 || bbox.empty()) {
    throw inputError(path, "grid", quoted(gridName) + " has no active voxels");
  }
  const openvdb::Coord dim = bbox.dim();
  const uint64_t voxels = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z());
  const uint64_t bytes = voxels * sizeof(float);
  constexpr uint64_t kMaxBytes = uint64_t(1) << 31;
  if (bytes > kMaxBytes) {
    throw inputError(path, "grid",
                     quoted(gridName) + " active bounding box " + dimsString(dim.x(), dim.y(), dim.z()) + " = " +
                         std::to_string(voxels) + " voxels needs " + std::to_string(bytes >> 20) +
                         " MiB as dense floats, over the 2048 MiB limit");
  }

  DenseGrid out;
  out.nx = dim.x();
  out.ny = dim.y();
  out.nz = dim.z();
  out.source = path;
  out.data.assign(voxels, 0.0f);
  {
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bbox, out.data.data());
    openvdb::tools::copyToDense(*grid, dense, /*serial=*/false);
  }

  // Our index u (voxel i covers [i, i+1]) -> vdb index ijk = u - 0.5 + bbox.min -> world.
  const openvdb::Vec3d shift(bbox.min().x() - 0.5, bbox.min().y() - 0.5, bbox.min().z() - 0.5);
  bool diagonal = true;
  double maxDiag = 0.0;
  for (int r = 0; r < 3; ++r) maxDiag = std::max(maxDiag, std::abs(m[r][r]));
  for (int r = 0; r < 3; ++r) {
    double t = m[3][r];
    for (int c = 0; c < 3; ++c) {
      out.indexToWorld[size_t(r * 4 + c)] = float(m[c][r]);
      t += shift[c] * m[c][r];
      if (r != c && std::abs(m[c][r]) > 1e-9 * maxDiag) diagonal = false;
    }
    out.indexToWorld[size_t(r * 4 + 3)] = float(t);
  }
  out.fileTransformIsScaleTranslate = diagonal;

  checkDensityValues(out, "grid", quoted(gridName) + " has ");
  return out;
}

void writeVdb(const std::string& path, const DenseGrid& grid, const std::string& gridName, float voxelSize) {
  initOpenVdb();
  if (grid.nx < 0 || grid.ny < 0 || grid.nz < 0 || grid.data.size() != grid.voxelCount()) {
    throw std::invalid_argument("writeVdb: grid dimensions " + dimsString(grid.nx, grid.ny, grid.nz) +
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
  vdb->setName(gridName);
  vdb->setGridClass(openvdb::GRID_FOG_VOLUME);
  vdb->setTransform(openvdb::math::Transform::createLinearTransform(double(voxelSize)));
  vdb->insertMeta("creator", openvdb::StringMetadata("narval"));
  writeGrids(path, {vdb});
}

void writeVdbTestFile(const std::string& path, const std::string& kind) {
  initOpenVdb();
  openvdb::GridPtrVec grids;
  if (kind == "vec3") {
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create();
    v->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
    v->setName("velocity");
    grids.push_back(v);
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    f->setName("heat");
    grids.push_back(f);
  } else if (kind == "frustum") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(1, 1, 1), 1.0f);
    f->setName("density");
    const openvdb::BBoxd box(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(10, 10, 10));
    f->setTransform(openvdb::math::Transform::createFrustumTransform(box, 0.5, 10.0, 1.0));
    grids.push_back(f);
  } else if (kind == "huge") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(-10, -10, -10), 1.0f);
    f->tree().setValue(openvdb::Coord(1013, 1013, 1013), 1.0f);
    f->setName("density");
    grids.push_back(f);
  } else if (kind == "empty") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->setName("density");
    grids.push_back(f);
  } else if (kind == "invalid") {
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    f->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    f->tree().setValue(openvdb::Coord(1, 0, 0), std::numeric_limits<float>::quiet_NaN());
    f->tree().setValue(openvdb::Coord(2, 0, 0), -1.0f);
    f->tree().setValue(openvdb::Coord(3, 0, 0), std::numeric_limits<float>::infinity());
    f->setName("density");
    grids.push_back(f);
  } else if (kind == "affine") {
    // Voxels (3,4,5)..(4,6,8) with value x + 10y + 100z, under rotate(30 deg about z) * scale(2,3,4)
    // then translate(1,2,3): world = M * ijk + t with M = R * S.
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(0.0f);
    for (int z = 5; z <= 8; ++z)
      for (int y = 4; y <= 6; ++y)
        for (int x = 3; x <= 4; ++x) f->tree().setValue(openvdb::Coord(x, y, z), float(x + 10 * y + 100 * z));
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    m.preScale(openvdb::Vec3d(2, 3, 4));
    m.postRotate(openvdb::math::Z_AXIS, M_PI / 6.0);
    m.postTranslate(openvdb::Vec3d(1, 2, 3));
    f->setTransform(openvdb::math::Transform::createLinearTransform(m));
    f->setName("density");
    grids.push_back(f);
  } else {
    throw std::invalid_argument("writeVdbTestFile: unknown kind '" + kind + "'");
  }
  for (auto& g : grids) g->setGridClass(openvdb::GRID_FOG_VOLUME);
  writeGrids(path, grids);
}

}  // namespace narval
