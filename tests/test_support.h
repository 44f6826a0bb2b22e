// test_support.h: helpers shared by the test suites (unit, device, render, cli): Dissertation
// Listing 4.1, the real-data folder and the skip when a file of it is absent, temporary folders,
// whole-file reads and writes, and scoped environment variables.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/input_error.h"

// A device test on a machine without an OpenCL device skips, saying so; with NARVAL_REQUIRE_DEVICE=1
// (CI sets it) a missing device fails instead, so a broken PoCL install cannot turn the device tests
// into a row of silent skips.
#define NARVAL_SKIP_WITHOUT_DEVICE()                                                                \
  do {                                                                                              \
    const char* require_ = std::getenv("NARVAL_REQUIRE_DEVICE");                                    \
    if (require_ && std::string(require_) == "1")                                                   \
      FAIL() << "no OpenCL platform or device on this machine, and NARVAL_REQUIRE_DEVICE=1";        \
    GTEST_SKIP() << "no OpenCL platform or device on this machine (install pocl-opencl-icd)";       \
  } while (0)

namespace narval::test {

// The message of the InputError `fn` throws ("" and a test failure if it throws anything else or
// nothing).
template <typename Fn>
std::string inputErrorOf(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

// ---------------------------------------------------------------- Listing 4.1

// A box of Henyey–Greenstein cloud (g 0.7, density 4, rotated 15° about y) lit by a rectangle
// behind it and a coloured point light in front, over a blue background: every light kind, MIS,
// the box transform and escaping rays in one small scene. `renderer` is the "renderer" object;
// scattering/absorption are JSON triples (unequal channels make the medium chromatic).
inline std::string litCloudJson(const std::string& renderer, const std::string& scattering = "[1.0, 1.1, 1.2]",
                                const std::string& absorption = "[0.02, 0.02, 0.02]") {
  return R"({
  "materials": [
    {"name": "light", "type": "emitter", "albedo": [8, 8, 8]},
    {"name": "bulb", "type": "emitter", "albedo": [3, 2, 1]},
    {"name": "cloud", "type": "volume", "scattering": )" + scattering + R"(, "absorption": )" + absorption + R"(,
     "phaseFunction": "hg", "g": 0.7, "density": 4}
  ],
  "primitives": [
    {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 6], "scale": [8, 6, 1]}, "materialName": "light"},
    {"name": "point", "type": "point", "transform": {"position": [-2, 2, -1]}, "materialName": "bulb"},
    {"name": "box", "type": "volume", "transform": {"scale": [3, 3, 3], "rotation": [0, 15, 0]}, "materialName": "cloud"}
  ],
  "camera": {"position": [0, 0, -7], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 35},
  "renderer": )" + renderer + R"(,
  "background": [0.1, 0.1, 0.2]
})";
}

// Dissertation Listing 4.1, character for character as printed (the "renderer" block's odd
// indentation and trailing spaces included), with the volume path replaceable.
inline std::string listing41Json(const std::string& volumePath = "vdb/wdas_cloud_quarter.vdb") {
  return R"({
  "materials": [
    {
      "name": "emitter",
      "type": "emitter",
      "albedo": [20, 20, 20]
    },
    {
      "name": "cloudVolMat",
      "type": "volume",
      "scattering": [1.1, 1.1, 1.1],
      "absorption": [0.01, 0.01, 0.01],
      "phaseFunction": "hg",
      "g": 0.9,
      "path": ")" + volumePath + R"(",
      "density": 10
    }
  ],
  "primitives": [
    {
      "name": "rectLight",
      "type": "rectangle",
      "transform": {
        "position": [0, 0, 80],
        "scale": [150, 100, 1],
        "rotation": [0, 0, 0]
      },
      "materialName": "emitter"
    },
    {
      "name": "cloud",
      "type": "volume",
      "transform": {
        "position": [0.0, 0, 0],
        "scale": [15.9, 9.51, 13.5],
        "rotation": [0, 0, 0]
      },
      "materialName": "cloudVolMat"
    }
  ],
  "camera": {
    "position": [0, 0, -17],
    "lookAt": [0, 0, 0],
    "up": [0, 1, 0],
    "speed": 5,
    "vfov": 45,
    "aperture": 0.0001,
    "focus": 1
  },
"renderer": {  
  "resolution": [1200, 600],  
  "spp": 1000,  
  "bounces": 3,  
  "HDR": true,  
  "toneMapping": true  
}  
})";
}

// ---------------------------------------------------------------- real data

// The path of a file of the real data set: in $NARVAL_DATA_DIR (an empty value counts as unset),
// else in the folder the build names (../shared/data/volumes beside the repository).
inline std::string realDataPath(const std::string& fileName) {
  const char* env = std::getenv("NARVAL_DATA_DIR");
  const std::filesystem::path dir = env && *env ? env : NARVAL_DEFAULT_DATA_DIR;
  return (dir / fileName).string();
}

// Skips the current test, saying why, when the real data file `path` is absent. A statement:
// `NARVAL_REQUIRE_REAL_DATA(path);` (safe inside an unbraced if/else).
#define NARVAL_REQUIRE_REAL_DATA(path)                      \
  if (std::filesystem::is_regular_file(path)) {             \
  } else                                                    \
    GTEST_SKIP() << "real data absent: " << (path) << " (set NARVAL_DATA_DIR)"

// ---------------------------------------------------------------- files and folders

// A fresh, private folder (mkdtemp) under the system's temporary folder, removed with everything
// in it at the end of the scope (its owner permissions restored first, for tests that take them).
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "narval_test") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed for " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // The path of `name` in the folder (the file need not exist).
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  // The names in the folder, sorted: to check what a test's code left behind.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

// A whole file's bytes ("" when it cannot be read).
inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Writes `bytes` to `path`, replacing what was there.
inline void writeFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// ---------------------------------------------------------------- environment

// Sets (or unsets, with nullopt) an environment variable for one scope, then restores it.
class ScopedEnv {
 public:
  ScopedEnv(std::string name, const std::optional<std::string>& value) : name_(std::move(name)) {
    if (const char* old = std::getenv(name_.c_str())) old_ = old;
    if (value)
      ::setenv(name_.c_str(), value->c_str(), 1);
    else
      ::unsetenv(name_.c_str());
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_.c_str(), old_->c_str(), 1);
    else
      ::unsetenv(name_.c_str());
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

}  // namespace narval::test
