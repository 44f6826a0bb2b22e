// grid_load_test.cpp: density grids (host/volume/): .vdb loading against the real data set
// (../shared/data/volumes or NARVAL_DATA_DIR; skipped, saying why, when absent), .vdb write/read
// round trips and error paths, the text .vol format and its errors, and the procedural cloud.
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "core/input_error.h"
#include "test_support.h"
#include "vdb_test_file.h"
#include "volume/dense_grid.h"
#include "volume/grid_info.h"

namespace fs = std::filesystem;
using narval::DenseGrid;
using narval::InputError;
using narval::test::readFile;
using narval::test::realDataPath;
using narval::test::TempDir;
using narval::test::writeFile;

namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

using narval::test::inputErrorOf;

// The float grids of a .vdb by name, as `narval info` lists them.
std::vector<std::string> floatGridNames(const std::string& path) {
  std::vector<std::string> names;
  for (const narval::GridInfo& g : narval::inspectVdb(path))
    if (g.valueType == "float") names.push_back(g.name);
  std::sort(names.begin(), names.end());
  return names;
}

// ---- real data ----

TEST(VdbRealData, DisneyCloudLoadsWithItsDocumentedExtent) {
  const std::string path = realDataPath("wdas_cloud_sixteenth.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  const DenseGrid g = narval::loadVdb(path, "density");
  EXPECT_EQ(g.nx, 126);
  EXPECT_EQ(g.ny, 86);
  EXPECT_EQ(g.nz, 154);
  ASSERT_EQ(g.data.size(), size_t(126) * 86 * 154);
  const auto [lo, hi] = std::minmax_element(g.data.begin(), g.data.end());
  EXPECT_GE(*lo, 0.0f);
  EXPECT_LE(*hi, 1.0f);
  EXPECT_GT(g.maxValue, 0.0f);
  EXPECT_EQ(g.maxValue, *hi);
  EXPECT_TRUE(g.fileTransformIsScaleTranslate);
  // Voxel size 3.333 on the diagonal, nothing off it.
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (r == c) EXPECT_NEAR(g.indexToWorld[size_t(r * 4 + c)], 3.333f, 0.01f);
      else EXPECT_EQ(g.indexToWorld[size_t(r * 4 + c)], 0.0f);
    }
  }
  EXPECT_EQ(g.source, path);
  // loadGrid dispatches .vdb with the default grid name.
  const DenseGrid viaLoadGrid = narval::loadGrid(path);
  EXPECT_EQ(viaLoadGrid.data, g.data);
}

TEST(VdbRealData, SmokeEncodingsHoldTheSameGrid) {
  const std::string v222 = realDataPath("openvdb_smoke1_v222.vdb");
  NARVAL_REQUIRE_REAL_DATA(v222);
  const std::string v223 = realDataPath("openvdb_smoke1_v223_blosc.vdb");
  NARVAL_REQUIRE_REAL_DATA(v223);
  const DenseGrid a = narval::loadVdb(v222, "density");
  const DenseGrid b = narval::loadVdb(v223, "density");
  EXPECT_EQ(a.nx, 111);
  EXPECT_EQ(a.ny, 222);
  EXPECT_EQ(a.nz, 112);
  EXPECT_EQ(b.nx, a.nx);
  EXPECT_EQ(b.ny, a.ny);
  EXPECT_EQ(b.nz, a.nz);
  EXPECT_TRUE(a.data == b.data) << "the two encodings decode to different values";
  EXPECT_EQ(a.indexToWorld, b.indexToWorld);
  // Not normalised: "values up to 5.71" (README).
  EXPECT_GT(a.maxValue, 5.6f);
  EXPECT_LT(a.maxValue, 5.8f);
  EXPECT_EQ(a.maxValue, b.maxValue);
}

TEST(VdbRealData, FireWithoutDensityNamesTheGridsItHas) {
  const std::string path = realDataPath("embergen_fire_a_50.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(path, "density"); }),
            path + ": grid: no grid named 'density' (the file has: flames, temperature)");
  EXPECT_EQ(inputErrorOf([&] { narval::loadGrid(path); }),
            path + ": grid: no grid named 'density' (the file has: flames, temperature)");
  EXPECT_EQ(floatGridNames(path), (std::vector<std::string>{"flames", "temperature"}));
  // Half-float grids load as float grids.
  const DenseGrid flames = narval::loadVdb(path, "flames");
  EXPECT_EQ(flames.nx, 104);
  EXPECT_EQ(flames.ny, 97);
  EXPECT_EQ(flames.nz, 103);
  const DenseGrid temperature = narval::loadGrid(path, "temperature");
  EXPECT_EQ(temperature.nx, 109);
  EXPECT_EQ(temperature.ny, 101);
  EXPECT_EQ(temperature.nz, 104);
}

TEST(VdbRealData, DragonKeepsItsAffineTransform) {
  const std::string path = realDataPath("vpt_dragon_with_xform.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  const DenseGrid g = narval::loadVdb(path, "density");
  EXPECT_EQ(g.nx, 141);
  EXPECT_EQ(g.ny, 99);
  EXPECT_EQ(g.nz, 63);
  EXPECT_FALSE(g.fileTransformIsScaleTranslate);
  EXPECT_GT(g.maxValue, 0.0f);
  float offDiagonal = 0.0f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (r != c) offDiagonal = std::max(offDiagonal, std::fabs(g.indexToWorld[size_t(r * 4 + c)]));
  EXPECT_GT(offDiagonal, 0.0f);
}

// Truncated and corrupted copies of a real file fail with an InputError naming the file: never
// a crash, never a silently partial grid.
TEST(VdbRealData, TruncatedOrCorruptFilesAreCleanErrors) {
  const std::string path = realDataPath("wdas_cloud_sixteenth.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  const std::string bytes = readFile(path);
  TempDir dir;
  const std::string cut = dir.file("cut.vdb");
  for (double fraction : {0.0, 0.001, 0.01, 0.1, 0.3, 0.5, 0.9, 0.999}) {
    writeFile(cut, bytes.substr(0, size_t(double(bytes.size()) * fraction)));
    const std::string msg = inputErrorOf([&] { narval::loadVdb(cut, "density"); });
    EXPECT_EQ(msg.rfind(cut + ": ", 0), 0u) << "fraction " << fraction << ": " << msg;
  }
  // Garbage after a valid header region.
  std::string corrupt = bytes;
  for (size_t i = 4096; i < corrupt.size(); i += 7) corrupt[i] = char(corrupt[i] ^ 0x5a);
  writeFile(cut, corrupt);
  const std::string msg = inputErrorOf([&] { narval::loadVdb(cut, "density"); });
  EXPECT_EQ(msg.rfind(cut + ": ", 0), 0u) << msg;
}

// Random byte flips in Blosc-compressed leaf data make OpenVDB 10's reader overflow heap buffers
// (an abort, or silent heap corruption that crashes later); loadVdb decodes in a child process so
// that this process survives and reports the file. Each corrupted copy either loads (the flips hit
// nothing that matters) or fails with an InputError naming the file, and nothing crashes later.
TEST(VdbRealData, CorruptedCompressedFilesNeverCrashTheProcess) {
  const std::string path = realDataPath("vpt_dragon_with_xform.vdb");
  NARVAL_REQUIRE_REAL_DATA(path);
  const std::string bytes = readFile(path);
  TempDir dir;
  const std::string bad = dir.file("bad.vdb");
  int failed = 0;
  for (uint32_t s = 0; s < 40; ++s) {
    std::string b = bytes;
    uint32_t h = 2166136261u * (s + 1);
    for (int k = 0; k < 20; ++k) {
      h = h * 1664525u + 1013904223u;
      const size_t pos = h % b.size();
      b[pos] = char(b[pos] ^ char(1 + (h >> 24) % 255));
    }
    writeFile(bad, b);
    try {
      narval::loadVdb(bad, "density");
    } catch (const InputError& e) {
      ++failed;
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(bad + ": ", 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  EXPECT_GT(failed, 30);
  // The process is intact: the genuine file still loads.
  EXPECT_EQ(narval::loadVdb(path, "density").nx, 141);
}

// ---- .vdb written by narval ----

// nx x ny x nz with zeros in the first `zx` x-slices, `zy` y-rows and `zz` z-slices, distinct
// positive values elsewhere.
DenseGrid paddedGrid(int nx, int ny, int nz, int zx, int zy, int zz) {
  DenseGrid g;
  g.nx = nx;
  g.ny = ny;
  g.nz = nz;
  g.data.assign(size_t(nx) * ny * nz, 0.0f);
  for (int z = zz; z < nz; ++z)
    for (int y = zy; y < ny; ++y)
      for (int x = zx; x < nx; ++x)
        g.data[size_t(x) + size_t(nx) * (size_t(y) + size_t(ny) * z)] = 0.25f + float(x) + 10.0f * y + 100.0f * z;
  return g;
}

TEST(VdbRoundTrip, EveryVoxelAndTheBoundingBoxShiftSurvive) {
  TempDir dir;
  const std::string path = dir.file("small.vdb");
  const DenseGrid src = paddedGrid(9, 7, 6, 2, 1, 3);  // active box (2,1,3)..(8,6,5)
  narval::writeVdb(path, src, "density", 0.5f);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"small.vdb"}) << "a temporary file was left behind";
  EXPECT_EQ(floatGridNames(path), std::vector<std::string>{"density"});

  const DenseGrid g = narval::loadVdb(path, "density");
  ASSERT_EQ(g.nx, 7);
  ASSERT_EQ(g.ny, 6);
  ASSERT_EQ(g.nz, 3);
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x) ASSERT_EQ(g.at(x, y, z), src.at(x + 2, y + 1, z + 3)) << x << " " << y << " " << z;
  EXPECT_EQ(g.maxValue, src.at(8, 6, 5));
  EXPECT_TRUE(g.fileTransformIsScaleTranslate);
  // Our index u -> vdb index u - 0.5 + (2,1,3) -> world 0.5 * that.
  const std::array<float, 12> expected{0.5f, 0, 0, 0.5f * 1.5f, 0, 0.5f, 0, 0.5f * 0.5f, 0, 0, 0.5f, 0.5f * 2.5f};
  EXPECT_EQ(g.indexToWorld, expected);
}

TEST(VdbRoundTrip, OverwritesAnExistingFileAndKeepsTheGridName) {
  TempDir dir;
  const std::string path = dir.file("out.vdb");
  narval::writeVdb(path, paddedGrid(4, 4, 4, 0, 0, 0), "smoke", 1.0f);
  narval::writeVdb(path, paddedGrid(5, 4, 4, 0, 0, 0), "smoke", 1.0f);
  EXPECT_EQ(narval::loadVdb(path, "smoke").nx, 5);
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(path, "density"); }),
            path + ": grid: no grid named 'density' (the file has: smoke)");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.vdb"});
}

TEST(VdbErrors, UnwritablePathIsAnInputError) {
  TempDir dir;
  const std::string path = dir.file("no/such/dir/out.vdb");
  const std::string msg = inputErrorOf([&] { narval::writeVdb(path, paddedGrid(2, 2, 2, 0, 0, 0)); });
  EXPECT_EQ(msg, path + ": cannot write: No such file or directory");
}

TEST(VdbErrors, NonFiniteAndNegativeValuesAreCountedAndRejected) {
  TempDir dir;
  const std::string path = dir.file("bad.vdb");
  DenseGrid g = paddedGrid(4, 3, 2, 0, 0, 0);
  g.data[7] = -2.0f;   // (3, 1, 0)
  g.data[13] = kInf;   // (1, 0, 1)
  g.data[20] = -kInf;  // (0, 2, 1)
  g.data[22] = -0.5f;  // (2, 2, 1)
  narval::writeVdb(path, g);
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(path, "density"); }),
            path + ": grid: 'density' has 2 non-finite and 2 negative values (first at voxel 3 1 0); "
                   "densities must be finite and >= 0");
  // NaN (which copyFromDense would silently turn into inactive background) comes from a file
  // written directly: active voxels (0,0,0) = 1, (1,0,0) = NaN, (2,0,0) = -1, (3,0,0) = +inf.
  narval::writeVdbTestFile(path, "invalid");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(path, "density"); }),
            path + ": grid: 'density' has 2 non-finite and 1 negative values (first at voxel 1 0 0); "
                   "densities must be finite and >= 0");
  // writeVdb refuses NaN rather than dropping it.
  g.data[5] = kNaN;
  EXPECT_THROW(narval::writeVdb(path, g), std::invalid_argument);
}

TEST(VdbErrors, MissingAndNonVdbFiles) {
  TempDir dir;
  const std::string missing = dir.file("missing.vdb");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(missing, "density"); }), missing + ": cannot open the file: no such file");
  EXPECT_EQ(inputErrorOf([&] { floatGridNames(missing); }), missing + ": cannot open the file: no such file");
  EXPECT_EQ(inputErrorOf([&] { narval::loadGrid(missing); }), missing + ": cannot open the file: no such file");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(dir.file(""), "density"); }).find("it is a directory") != std::string::npos,
            true);
  const std::string text = dir.file("text.vdb");
  writeFile(text, "this is not a vdb file at all, just some text\n");
  const std::string msg = inputErrorOf([&] { narval::loadVdb(text, "density"); });
  const std::string unreadable = ": not a readable OpenVDB file: truncated, corrupt or of another format (OpenVDB: ";
  EXPECT_EQ(msg.rfind(text + unreadable, 0), 0u) << msg;
  const std::string empty = dir.file("empty.vdb");
  writeFile(empty, "");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(empty, "density"); }),
            empty + ": not a readable OpenVDB file: truncated, corrupt or of another format (a read ran past its end)");
  // A real file cut short inside its grid says so.
  const std::string whole = dir.file("whole.vdb"), cut = dir.file("cut.vdb");
  narval::writeVdb(whole, paddedGrid(4, 4, 4, 1, 1, 1));
  const std::string bytes = narval::test::readFile(whole);
  for (size_t n : {bytes.size() / 2, bytes.size() - 10}) {
    writeFile(cut, bytes.substr(0, n));
    EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(cut, "density"); }),
              cut + ": not a readable OpenVDB file: truncated, corrupt or of another format (a read ran past its end)")
        << n << " bytes";
  }
}

TEST(VdbErrors, NonFloatGridsAreNamedAsSuch) {
  TempDir dir;
  const std::string path = dir.file("vec3.vdb");
  narval::writeVdbTestFile(path, "vec3");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(path, "velocity"); }),
            path + ": grid: 'velocity' is a vec3s grid; narval needs a float grid (float grids in the file: heat)");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(path, "density"); }),
            path + ": grid: no grid named 'density' (the file has: heat, velocity (vec3s))");
  EXPECT_EQ(floatGridNames(path), std::vector<std::string>{"heat"});
  EXPECT_EQ(narval::loadVdb(path, "heat").maxValue, 1.0f);
}

TEST(VdbErrors, FrustumEmptyAndOversizedGrids) {
  TempDir dir;
  const std::string frustum = dir.file("frustum.vdb");
  narval::writeVdbTestFile(frustum, "frustum");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(frustum, "density"); }),
            frustum + ": grid: 'density' has a non-affine index-to-world transform (NonlinearFrustumMap); "
                      "narval supports affine transforms only");
  const std::string empty = dir.file("empty.vdb");
  narval::writeVdbTestFile(empty, "empty");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(empty, "density"); }), empty + ": grid: 'density' has no active voxels");
  const std::string huge = dir.file("huge.vdb");
  narval::writeVdbTestFile(huge, "huge");
  // The size is refused from the bounding box, before any dense allocation (that is what the
  // message reports: the box, not a failed allocation).
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(huge, "density"); }),
            huge + ": grid: 'density' active bounding box 2048x2048x2048 = 8589934592 voxels needs 32768 MiB as "
                   "dense floats, over the 8192 MiB limit");
}

// A file cut anywhere (its header included: OpenVDB's own reader takes a cut header for a file with
// no grids) says it is truncated or corrupt, in one printable line of bounded length (OpenVDB's
// messages can quote the file's bytes); a valid file with no grids says that.
TEST(VdbErrors, CutFilesAreTruncatedAndAFileWithoutGridsSaysSo) {
  TempDir dir;
  const std::string whole = dir.file("whole.vdb"), cut = dir.file("cut.vdb");
  narval::writeVdbTestFile(whole, "affine");
  const std::string bytes = readFile(whole);
  const std::string unreadable = cut + ": not a readable OpenVDB file: truncated, corrupt or of another format (";
  for (size_t n = 1; n < bytes.size(); n += (n < 256 ? 1 : 97)) {
    writeFile(cut, bytes.substr(0, n));
    const std::string msg = inputErrorOf([&] { narval::loadVdb(cut, "density"); });
    EXPECT_EQ(msg.rfind(unreadable, 0), 0u) << n << " bytes: " << msg;
    EXPECT_LE(msg.size(), unreadable.size() + 170) << n << " bytes: " << msg;
    EXPECT_TRUE(std::all_of(msg.begin(), msg.end(), [](char c) { return c >= 0x20 && c < 0x7f; })) << n;
  }
  const std::string none = dir.file("none.vdb");
  narval::writeVdbTestFile(none, "no grids");
  EXPECT_EQ(inputErrorOf([&] { narval::loadVdb(none, "density"); }),
            none + ": grid: no grid named 'density' (the file has no grids)");
}

TEST(VdbTransform, AffineMapIsComposedWithTheBoundingBoxShift) {
  TempDir dir;
  const std::string path = dir.file("affine.vdb");
  narval::writeVdbTestFile(path, "affine");
  const DenseGrid g = narval::loadVdb(path, "density");
  ASSERT_EQ(g.nx, 2);
  ASSERT_EQ(g.ny, 3);
  ASSERT_EQ(g.nz, 4);
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 2; ++x) EXPECT_EQ(g.at(x, y, z), float((x + 3) + 10 * (y + 4) + 100 * (z + 5)));
  EXPECT_FALSE(g.fileTransformIsScaleTranslate);
  const auto& A = g.indexToWorld;
  // Linear part M = R_z(30 deg) * diag(2, 3, 4): columns of length 2, 3, 4; z column (0, 0, 4);
  // the x column rotated 30 degrees in the xy plane.
  auto column = [&](int c) { return std::array<double, 3>{A[size_t(c)], A[size_t(4 + c)], A[size_t(8 + c)]}; };
  auto length = [](std::array<double, 3> v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  EXPECT_NEAR(length(column(0)), 2.0, 1e-6);
  EXPECT_NEAR(length(column(1)), 3.0, 1e-6);
  EXPECT_NEAR(length(column(2)), 4.0, 1e-6);
  EXPECT_NEAR(column(2)[2], 4.0, 1e-6);
  EXPECT_NEAR(column(0)[0], 2.0 * std::cos(M_PI / 6.0), 1e-6);
  EXPECT_NEAR(std::fabs(column(0)[1]), 2.0 * std::sin(M_PI / 6.0), 1e-6);
  // Our u = (0.5, 0.5, 0.5), the centre of our voxel 0, is vdb index (3, 4, 5): world M*(3,4,5) + (1,2,3).
  const double ijk[3] = {3, 4, 5};
  for (int r = 0; r < 3; ++r) {
    double expectedWorld = (r == 0 ? 1.0 : r == 1 ? 2.0 : 3.0);
    double ours = A[size_t(r * 4 + 3)];
    for (int c = 0; c < 3; ++c) {
      expectedWorld += A[size_t(r * 4 + c)] * ijk[c];
      ours += A[size_t(r * 4 + c)] * 0.5;
    }
    EXPECT_NEAR(ours, expectedWorld, 1e-5) << "row " << r;
  }
}

// ---- .vol ----

std::string volText(const DenseGrid& g, int perLine) {
  std::ostringstream s;
  s.precision(9);
  s << g.nx << " " << g.ny << " " << g.nz << "\n";
  for (size_t i = 0; i < g.data.size(); ++i) s << g.data[i] << ((i + 1) % size_t(perLine) == 0 ? "\n" : " ");
  return s.str();
}

TEST(VolFormat, RoundTripIsBitExactWithAnyLineBreaks) {
  TempDir dir;
  DenseGrid src;
  src.nx = 5;
  src.ny = 3;
  src.nz = 4;
  for (int i = 0; i < 60; ++i) src.data.push_back(i == 7 ? 0.0f : std::ldexp(float(i * 37 % 61) / 7.0f, i % 9 - 4));
  const std::string path = dir.file("grid.vol");
  for (int perLine : {1, 5, 7, 60}) {
    writeFile(path, volText(src, perLine));
    const DenseGrid g = narval::loadVol(path);
    ASSERT_EQ(g.nx, 5);
    ASSERT_EQ(g.ny, 3);
    ASSERT_EQ(g.nz, 4);
    EXPECT_EQ(g.data, src.data) << perLine << " values per line";
    EXPECT_EQ(g.maxValue, *std::max_element(src.data.begin(), src.data.end()));
    EXPECT_EQ(g.indexToWorld, (std::array<float, 12>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}));
    EXPECT_TRUE(g.fileTransformIsScaleTranslate);
    EXPECT_EQ(g.source, path);
  }
  // x fastest: the value at (x, y, z) is number x + nx * (y + ny * z) in the file.
  writeFile(path, "2 2 2\n0 1 2 3 4 5 6 7");
  const DenseGrid g = narval::loadVol(path);
  EXPECT_EQ(g.at(1, 0, 0), 1.0f);
  EXPECT_EQ(g.at(0, 1, 0), 2.0f);
  EXPECT_EQ(g.at(0, 0, 1), 4.0f);
  EXPECT_EQ(g.at(1, 1, 1), 7.0f);
  // Windows line endings, tabs, a byte order mark, '+' signs and exponents are fine.
  writeFile(path, "\xEF\xBB\xBF" "2 1 1\r\n+1.5e0\t\r\n 2E-1 \r\n");
  const DenseGrid w = narval::loadGrid(path);
  EXPECT_EQ(w.data, (std::vector<float>{1.5f, 0.2f}));
  // Upper-case extension dispatches too.
  const std::string upper = dir.file("GRID.VOL");
  writeFile(upper, "1 1 1\n0.5\n");
  EXPECT_EQ(narval::loadGrid(upper).data, std::vector<float>{0.5f});
}

TEST(VolFormat, HeaderErrors) {
  TempDir dir;
  const std::string p = dir.file("bad.vol");
  auto err = [&](const std::string& text) {
    writeFile(p, text);
    return inputErrorOf([&] { narval::loadVol(p); });
  };
  const std::string hdr = p + ": line 1: expected the header 'X Y Z' (three positive integers), found ";
  EXPECT_EQ(err(""), hdr + "an empty file");
  EXPECT_EQ(err("\n1 1 1\n0\n"), hdr + "an empty line");
  EXPECT_EQ(err("4 4\n1 2 3 4\n"), hdr + "'4 4'");
  EXPECT_EQ(err("4 0 4\n"), hdr + "'4 0 4'");
  EXPECT_EQ(err("4 -4 4\n"), hdr + "'4 -4 4'");
  EXPECT_EQ(err("4 4 x\n"), hdr + "'4 4 x'");
  EXPECT_EQ(err("4 4 4.0\n"), hdr + "'4 4 4.0'");
  EXPECT_EQ(err("1 1 1 0.5\n"), hdr + "'1 1 1 0.5'");
  EXPECT_EQ(err("2 1 1 1 2 3 4 5 6 7 8 9\n"), hdr + "'2 1 1 1 2 ...'");
}

TEST(VolFormat, AbsurdSizesFailBeforeAllocating) {
  TempDir dir;
  const std::string p = dir.file("big.vol");
  auto err = [&](const std::string& text) {
    writeFile(p, text);
    return inputErrorOf([&] { narval::loadVol(p); });
  };
  EXPECT_EQ(err("100000 100000 100000\n1 2 3\n"),
            p + ": line 1: header declares 100000x100000x100000 = 1000000000000000 values, over the limit of "
                "1073741824 (2^30)");
  EXPECT_EQ(err("99999999999999999999999 1 1\n1\n"),
            p + ": line 1: header declares 99999999999999999999999x1x1 values, over the limit of 1073741824 (2^30)");
  // Under the limit (1024*1024*1023 values, 4 GiB as floats) but a 19-byte file cannot hold them.
  EXPECT_EQ(err("1024 1024 1023\n1 2\n"),
            p + ": line 1: header declares 1024x1024x1023 = 1072693248 values, but the file has only 19 bytes "
                "(each value needs at least 2)");
}

TEST(VolFormat, ValueErrors) {
  TempDir dir;
  const std::string p = dir.file("v.vol");
  auto err = [&](const std::string& text) {
    writeFile(p, text);
    return inputErrorOf([&] { narval::loadVol(p); });
  };
  auto values = [](int n, const std::string& sep = " ") {
    std::string s;
    for (int i = 0; i < n; ++i) s += std::to_string(i % 10) + ".5" + sep;
    return s;
  };
  EXPECT_EQ(err("4 4 4\n" + values(60)), p + ": declares 4x4x4 = 64 values, found 60");
  EXPECT_EQ(err("4 4 4\n" + values(70, "\n")), p + ": declares 4x4x4 = 64 values, found 70");
  EXPECT_EQ(err("4 4 4\n"), p + ": line 1: header declares 4x4x4 = 64 values, but the file has only 6 bytes "
                               "(each value needs at least 2)");
  // Value 17 is x 1, y 0, z 1 in a 4x4x4 grid; it sits on line 3 (16 values per line).
  EXPECT_EQ(err("4 4 4\n" + values(16) + "\n0 abc " + values(46)),
            p + ": line 3: value 17 (x 1, y 0, z 1) is not a number: 'abc'");
  EXPECT_EQ(err("2 1 1\n1.5abc 2\n"), p + ": line 2: value 0 (x 0, y 0, z 0) is not a number: '1.5abc'");
  EXPECT_EQ(err("2 1 1\n1,5 2\n"), p + ": line 2: value 0 (x 0, y 0, z 0) is not a number: '1,5'");
  EXPECT_EQ(err("2 1 1\n1 " + std::string(100, '7') + "x\n"),
            p + ": line 2: value 1 (x 1, y 0, z 0) is not a number: '77777777777777777777777777777777...'");
  // NaN, infinities, overflow and negative values: counted, first one located, rejected.
  EXPECT_EQ(err("3 2 2\n1 -1 nan 2\ninf 0 -0.5 1e40\n-inf 3 4 5\n"),
            p + ": 4 non-finite and 2 negative values (first at voxel 1 0 0); densities must be finite and >= 0");
  EXPECT_EQ(err("2 1 1\n1 NaN\n"), p + ": 1 non-finite value (first at voxel 1 0 0); densities must be finite and >= 0");
  // Underflow is 0, negative zero is fine.
  writeFile(p, "3 1 1\n1e-60 -0 0.5\n");
  const DenseGrid g = narval::loadVol(p);
  EXPECT_EQ(g.data[0], 0.0f);
  EXPECT_EQ(g.maxValue, 0.5f);
}

TEST(GridLoad, DispatchOnExtension) {
  TempDir dir;
  const std::string raw = dir.file("cloud.raw");
  writeFile(raw, "1 1 1\n1\n");
  EXPECT_EQ(inputErrorOf([&] { narval::loadGrid(raw); }),
            raw + ": unknown volume file type '.raw' (narval reads .vdb and .vol)");
  const std::string none = dir.file("cloud");
  writeFile(none, "1 1 1\n1\n");
  EXPECT_EQ(inputErrorOf([&] { narval::loadGrid(none); }),
            none + ": unknown volume file type '(none)' (narval reads .vdb and .vol)");
  const std::string missing = dir.file("missing.vol");
  EXPECT_EQ(inputErrorOf([&] { narval::loadGrid(missing); }), missing + ": cannot open the file: no such file");
}

// ---- procedural cloud ----

double meanOf(const DenseGrid& g) {
  return std::accumulate(g.data.begin(), g.data.end(), 0.0) / double(g.data.size());
}

TEST(CloudGenerator, DeterministicBitForBit) {
  const DenseGrid a = narval::makeCloud(48, 7);
  const DenseGrid b = narval::makeCloud(48, 7);
  ASSERT_EQ(a.data.size(), size_t(48) * 48 * 48);
  EXPECT_EQ(std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)), 0);
  EXPECT_EQ(a.nx, 48);
  EXPECT_EQ(a.ny, 48);
  EXPECT_EQ(a.nz, 48);
  EXPECT_EQ(a.indexToWorld, (std::array<float, 12>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}));
}

TEST(CloudGenerator, IndependentOfTheThreadCount) {
  const DenseGrid many = narval::makeCloud(40, 3);
  DenseGrid one;
  {
    tbb::task_arena arena(1);
    arena.execute([&] { one = narval::makeCloud(40, 3); });
  }
  EXPECT_EQ(std::memcmp(many.data.data(), one.data.data(), many.data.size() * sizeof(float)), 0);
}

TEST(CloudGenerator, DensityInUnitRangeWithAZeroMargin) {
  for (int res : {8, 9, 33, 64}) {
    for (uint32_t seed : {0u, 1u, 12345u, 0xffffffffu}) {
      const DenseGrid g = narval::makeCloud(res, seed);
      const auto [lo, hi] = std::minmax_element(g.data.begin(), g.data.end());
      EXPECT_GE(*lo, 0.0f);
      EXPECT_LE(*hi, 1.0f);
      EXPECT_EQ(g.maxValue, *hi);
      if (res >= 33) EXPECT_GT(g.maxValue, 0.9f) << "res " << res << " seed " << seed;
      // Every voxel whose centre is within kCloudMargin of a face is 0: ceil(0.08 r - 0.5) layers.
      const int layers = int(std::ceil(narval::kCloudMargin * float(res) - 0.5f));
      EXPECT_GE(layers, 1);
      size_t nonzeroInMargin = 0;
      for (int z = 0; z < res; ++z)
        for (int y = 0; y < res; ++y)
          for (int x = 0; x < res; ++x) {
            const bool inMargin = std::min({x, y, z}) < layers || std::max({x, y, z}) >= res - layers;
            if (inMargin && g.at(x, y, z) != 0.0f) ++nonzeroInMargin;
          }
      EXPECT_EQ(nonzeroInMargin, 0u) << "res " << res << " seed " << seed;
    }
  }
}

TEST(CloudGenerator, SeedsDifferAndMeanDensityIsSensible) {
  // Mean density over the whole cube: a flat-bottomed cumulus, wider than tall, fitted uniformly
  // into the cube, is neither a speck nor a solid block. Measured 0.040-0.101 over seeds 0..63 at
  // 64^3 (4-12% of the voxels non-zero); the bound [0.02, 0.20] leaves a factor 2 either way.
  std::vector<DenseGrid> clouds;
  for (uint32_t seed = 0; seed < 8; ++seed) {
    clouds.push_back(narval::makeCloud(64, seed));
    const double mean = meanOf(clouds.back());
    EXPECT_GT(mean, 0.02) << "seed " << seed;
    EXPECT_LT(mean, 0.20) << "seed " << seed;
  }
  for (size_t i = 0; i < clouds.size(); ++i)
    for (size_t j = i + 1; j < clouds.size(); ++j) EXPECT_NE(clouds[i].data, clouds[j].data) << i << " vs " << j;
}

TEST(CloudGenerator, ShapeDoesNotDependOnResolution) {
  // The same seed at 32^3 and 64^3: box-filter 64^3 down to 32^3 and compare.
  const DenseGrid lo = narval::makeCloud(32, 11);
  const DenseGrid hi = narval::makeCloud(64, 11);
  double diff = 0.0;
  for (int z = 0; z < 32; ++z)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        double s = 0.0;
        for (int k = 0; k < 8; ++k) s += hi.at(2 * x + (k & 1), 2 * y + ((k >> 1) & 1), 2 * z + (k >> 2));
        diff += std::fabs(s / 8.0 - lo.at(x, y, z));
      }
  const double meanDiff = diff / (32.0 * 32 * 32);
  EXPECT_LT(meanDiff, 0.25 * meanOf(lo)) << "mean |down(64) - 32| per voxel";
  EXPECT_NEAR(meanOf(hi), meanOf(lo), 0.05 * meanOf(lo));
}

TEST(CloudGenerator, RejectsTinyResolutions) {
  EXPECT_THROW(narval::makeCloud(7, 0), std::invalid_argument);
  EXPECT_THROW(narval::makeCloud(0, 0), std::invalid_argument);
  EXPECT_THROW(narval::makeCloud(-5, 0), std::invalid_argument);
}

// Timing, not a check: run with --gtest_also_run_disabled_tests.
}  // namespace
