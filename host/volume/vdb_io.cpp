// vdb_io.cpp: OpenVDB <-> DenseGrid. The only translation unit that includes OpenVDB (it costs
// ~15 s to compile), so everything OpenVDB-related lives here, test-file writers included.
#include "volume/grid.h"

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

#include "scene/input_error.h"
#include "volume/grid_info.h"

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

// An exception's text made fit for a one-line message (OpenVDB's can span lines).
std::string oneLine(const char* what) {
  std::string s(what);
  for (char& c : s) {
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  }
  return s;
}

struct GridEntry {
  std::string name;
  std::string valueType;  // "float", "vec3s", ...
  bool isFloat = false;
};

// Opens `path` (no delayed loading, so no memory map) and lists its grids from their metadata
// (names, types, transforms: no tree data is read).
std::vector<GridEntry> listGrids(openvdb::io::File& file, const std::string& path) {
  std::vector<GridEntry> out;
  try {
    file.open(/*delayLoad=*/false);
    openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
    for (const openvdb::GridBase::Ptr& g : *grids) {
      out.push_back({g->getName(), g->valueType(), g->isType<openvdb::FloatGrid>()});
    }
  } catch (const std::exception& e) {
    throw inputError(path, "", "not a readable OpenVDB file (" + oneLine(e.what()) + ")");
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
    throw inputError(path, "", "cannot write the file (" + oneLine(e.what()) + ")");
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

// Where decodeVdb puts its result: the dense values go to `allocate(n)`'s n floats.
struct Decoded {
  int nx = 0, ny = 0, nz = 0;
  std::array<float, 12> indexToWorld{};
  bool scaleTranslate = true;
};

// Everything that parses the file: grid lookup, type and transform checks, the active bounding
// box, the size limit and the dense copy. Throws InputError (the full one-line message).
template <typename Allocate>
Decoded decodeVdb(const std::string& path, const std::string& gridName, Allocate&& allocate, bool serial) {
  {
    openvdb::io::File file(path);
    const std::vector<GridEntry> grids = listGrids(file, path);
    const auto entry =
        std::find_if(grids.begin(), grids.end(), [&](const GridEntry& g) { return g.name == gridName; });
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
                                       oneLine(e.what()) + ")");
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
  // In 64 bits: a corrupt tree can span more than 2^31 voxels per axis (Coord::dim would wrap).
  const int64_t dim[3] = {int64_t(bbox.max().x()) - bbox.min().x() + 1, int64_t(bbox.max().y()) - bbox.min().y() + 1,
                          int64_t(bbox.max().z()) - bbox.min().z() + 1};
  // Dims are ints, an x-y slice's voxel count too (grid_trilinear's stride), and the whole grid at
  // most kMaxDenseGridBytes (volume/grid.h). Checked in this order, no product overflows.
  constexpr int64_t kMaxDim = INT32_MAX;
  constexpr uint64_t kMaxVoxels = kMaxDenseGridBytes / sizeof(float);
  const bool tooBig = dim[0] > kMaxDim || dim[1] > kMaxDim || dim[2] > kMaxDim ||
                      uint64_t(dim[0]) * uint64_t(dim[1]) > uint64_t(kMaxDim) ||
                      uint64_t(dim[0]) * uint64_t(dim[1]) * uint64_t(dim[2]) > kMaxVoxels;
  if (tooBig) {
    const bool showCount = dim[0] < (1 << 20) && dim[1] < (1 << 20) && dim[2] < (1 << 20);
    const uint64_t voxels = uint64_t(dim[0]) * uint64_t(dim[1]) * uint64_t(dim[2]);
    throw inputError(path, "grid",
                     quoted(gridName) + " active bounding box " + dimsString(dim[0], dim[1], dim[2]) +
                         (showCount ? " = " + std::to_string(voxels) + " voxels needs " +
                                          std::to_string((voxels * sizeof(float)) >> 20) + " MiB as dense floats,"
                                    : " is") +
                         " over the " + std::to_string(kMaxDenseGridBytes >> 20) + " MiB limit");
  }

  Decoded out;
  out.nx = int(dim[0]);
  out.ny = int(dim[1]);
  out.nz = int(dim[2]);
  {
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bbox, allocate(size_t(dim[0] * dim[1] * dim[2])));
    openvdb::tools::copyToDense(*grid, dense, serial);
  }

  // Our index u (voxel i covers [i, i+1]) -> vdb index ijk = u - 0.5 + bbox.min -> world.
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
  return out;
}

std::vector<std::string> floatGridNames(const std::string& path) {
  openvdb::io::File file(path);
  std::vector<std::string> names;
  for (const GridEntry& g : listGrids(file, path)) {
    if (g.isFloat) names.push_back(g.name);
  }
  return names;
}

// Every grid of the file read whole and described (grid_info.h). Throws InputError.
std::vector<GridInfo> describeVdbGrids(const std::string& path) {
  std::vector<GridInfo> out;
  openvdb::GridPtrVecPtr grids;
  try {
    grids = readAllGrids(path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, "", "not a readable OpenVDB file (" + oneLine(e.what()) + ")");
  }
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
// OpenVDB 10's readers trust the sizes and flags they find in a file. Corrupted bytes inside
// compressed leaf data (a size field larger than its buffer, a wrong mask flag) overflow a heap
// buffer in io::readCompressedValues / io::bloscFromStream: that aborts the process ("double free
// or corruption") or, worse, corrupts the heap silently and crashes it later. A corrupted length
// in the metadata makes it build (and zero) a string of up to 4 GiB. None of this can be caught,
// so every read of a file's contents runs in a forked child that shares nothing with us but a
// memfd: it writes a result record (and the dense values after the first page) there. A child
// that dies on a signal, or runs past a time limit, is reported as a corrupt file. The child runs
// single-threaded (a one-slot TBB arena and a serial copy: the parent's TBB workers do not exist
// in it), writes nothing to our stderr and leaves with _exit. NARVAL_VDB_IN_PROCESS=1 reads in
// this process instead (for debuggers and memory checkers).
struct ChildRecord {
  uint64_t magic;
  int32_t ok;  // 1: result (Decoded, or names in the data area); 0: InputError message; -1: other error
  uint32_t payloadBytes;  // names: bytes after the first page
  Decoded decoded;
  char message[3072];
};
constexpr uint64_t kRecordMagic = 0x6e617276616c7664ull;  // "narvalvd"
constexpr size_t kDataOffset = 4096;
static_assert(sizeof(ChildRecord) <= kDataOffset, "the record fits in the first page");

struct Fd {
  int fd = -1;
  Fd() = default;
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Runs `work(fd, record)` in a child; returns false (nothing ran) when no child can be used.
// After a true return `mem` holds what the child wrote and `rec` its record (ok == 1); InputErrors
// from the child, crashes and time-outs are thrown here as "PATH: grid: CANNOT (...)".
template <typename Work>
bool runInChild(const std::string& path, const std::string& cannot, Work&& work, Fd& mem, ChildRecord& rec) {
  if (std::getenv("NARVAL_VDB_IN_PROCESS")) return false;
  mem.fd = ::memfd_create("narval-vdb", MFD_CLOEXEC);
  if (mem.fd < 0) return false;
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    struct rlimit noCore{0, 0};
    ::setrlimit(RLIMIT_CORE, &noCore);
    const int devNull = ::open("/dev/null", O_WRONLY);
    if (devNull >= 0) ::dup2(devNull, 2);  // allocator diagnostics are ours to report
    ChildRecord out{};
    out.magic = kRecordMagic;
    try {
      tbb::task_arena arena(1, 1);
      arena.execute([&] { work(mem.fd, out); });
      out.ok = 1;
    } catch (const std::exception& e) {
      out.ok = dynamic_cast<const InputError*>(&e) ? 0 : -1;
      std::snprintf(out.message, sizeof(out.message), "%s", oneLine(e.what()).c_str());
    }
    // The record goes last: a child that dies before this leaves no magic behind.
    if (::pwrite(mem.fd, &out, sizeof(out), 0) != ssize_t(sizeof(out))) ::_exit(3);
    ::_exit(0);
  }

  // A healthy read takes well under a second for these files; the limit is for pathological ones.
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  const double limitS = 120.0 + double(ec ? 0 : size) / 5e6;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  for (useconds_t nap = 100;; nap = std::min<useconds_t>(nap * 2, 20000)) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw inputError(path, "grid", cannot + " (lost the reader process)");
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limitS) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      throw inputError(path, "grid", cannot + " (reading took more than " + std::to_string(int(limitS)) +
                                         " s: the file is probably corrupt)");
    }
    ::usleep(nap);
  }
  if (WIFSIGNALED(status)) {
    throw inputError(path, "grid", cannot + " (the file is corrupt: OpenVDB's reader crashed on it, " +
                                       strsignal(WTERMSIG(status)) + ")");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
      ::pread(mem.fd, &rec, sizeof(rec), 0) != ssize_t(sizeof(rec)) || rec.magic != kRecordMagic) {
    throw inputError(path, "grid", cannot + " (the reader process failed)");
  }
  rec.message[sizeof(rec.message) - 1] = '\0';
  if (rec.ok == 0) throw InputError(rec.message);
  if (rec.ok != 1) throw inputError(path, "grid", cannot + " (" + rec.message + ")");
  return true;
}

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

// Runs produce() in a child (runInChild) and passes the text it returns back into *text; false
// when no child can be used. `cannot` words the failures ("cannot list the grids").
template <typename Produce>
bool textInChild(const std::string& path, const std::string& cannot, Produce&& produce, std::string* text) {
  Fd mem;
  ChildRecord rec{};
  auto work = [&](int fd, ChildRecord& result) {
    const std::string out = produce();
    result.payloadBytes = uint32_t(out.size());
    if (::pwrite(fd, out.data(), out.size(), off_t(kDataOffset)) != ssize_t(out.size())) {
      throw std::runtime_error(cannot + ": cannot pass the result back");
    }
  };
  if (!runInChild(path, cannot, work, mem, rec)) return false;
  text->assign(rec.payloadBytes, '\0');
  if (::pread(mem.fd, text->data(), text->size(), off_t(kDataOffset)) != ssize_t(text->size())) {
    throw inputError(path, "grid", cannot + " (the reader process returned an inconsistent result)");
  }
  return true;
}

bool namesInChild(const std::string& path, std::vector<std::string>& names) {
  std::string joined;
  const bool ran = textInChild(path, "cannot list the grids", [&] {
    std::string out;
    for (const std::string& n : floatGridNames(path)) out.append(n).push_back('\0');
    return out;
  }, &joined);
  if (!ran) return false;
  for (size_t start = 0; start < joined.size();) {
    const size_t end = joined.find('\0', start);
    names.push_back(joined.substr(start, end - start));
    start = end + 1;
  }
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

std::vector<std::string> vdbGridNames(const std::string& path) {
  initOpenVdb();
  requireReadableFile(path);
#if defined(__linux__)
  std::vector<std::string> names;
  if (namesInChild(path, names)) return names;
#endif
  return floatGridNames(path);
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

namespace {

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
  finishAndWrite(path, vdb, gridName, voxelSize);
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
  } else if (kind == "emission") {
    // Density "smoke": voxels (0..7)³ = 0.5 at voxel size 1. Emission "heat": voxel size 0.5,
    // translated by (−1, −1, −1), voxels −1..20 on each axis holding 100 + 10x + 20y + 30z of
    // their world centre (x, y, z), a field trilinear filtering reproduces exactly; its box
    // covers the smoke's with a voxel to spare. And a Vec3 grid "velocity".
    openvdb::FloatGrid::Ptr smoke = openvdb::FloatGrid::create(0.0f);
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) smoke->tree().setValue(openvdb::Coord(x, y, z), 0.5f);
    smoke->setName("smoke");
    grids.push_back(smoke);
    openvdb::FloatGrid::Ptr heat = openvdb::FloatGrid::create(0.0f);
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(0.5);
    xf->postTranslate(openvdb::Vec3d(-1, -1, -1));
    heat->setTransform(xf);
    for (int k = -1; k <= 20; ++k)
      for (int j = -1; j <= 20; ++j)
        for (int i = -1; i <= 20; ++i) {
          const openvdb::Vec3d w = xf->indexToWorld(openvdb::Coord(i, j, k));
          heat->tree().setValue(openvdb::Coord(i, j, k), float(100 + 10 * w.x() + 20 * w.y() + 30 * w.z()));
        }
    heat->setName("heat");
    grids.push_back(heat);
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create();
    v->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
    v->setName("velocity");
    grids.push_back(v);
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
    f->tree().setValue(openvdb::Coord(2037, 2037, 2037), 1.0f);
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
