// cl_runtime_test.cpp: device discovery and selection, the runtime, program builds (error logs
// naming the real file and line) and the persistent program cache, on whatever OpenCL device the
// machine has (PoCL in CI).
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "core/input_error.h"
#include "test_support.h"

namespace narval {
const std::map<std::string, std::string>& testKernelSources();
}

namespace fs = std::filesystem;
using namespace narval;
using narval::test::readFile;
using narval::test::ScopedEnv;
using narval::test::TempDir;

namespace {

#define SKIP_WITHOUT_DEVICES()                \
  do {                                        \
    if (listDevices().empty()) NARVAL_SKIP_WITHOUT_DEVICE(); \
  } while (0)

// Runs cache_probe over n items and returns what it wrote.
std::vector<cl_uint> runProbe(ClRuntime& rt, cl::Program& program, cl_uint n) {
  cl::Buffer out(rt.context, CL_MEM_WRITE_ONLY, n * sizeof(cl_uint));
  cl::Kernel kernel(program, "cache_probe");
  kernel.setArg(0, out);
  kernel.setArg(1, n);
  rt.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(n), cl::NullRange);
  std::vector<cl_uint> result(n);
  rt.queue.enqueueReadBuffer(out, CL_TRUE, 0, n * sizeof(cl_uint), result.data());
  return result;
}

void expectProbe(ClRuntime& rt, cl::Program& program, cl_uint factor) {
  const std::vector<cl_uint> got = runProbe(rt, program, 1000);
  for (cl_uint i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], i * factor) << "item " << i;
}

// Builds cache_probe.cl with `options` and says whether the program came from the cache.
bool buildProbeHitsCache(ClRuntime& rt, const std::string& options = "") {
  bool hit = false;
  buildProgram(rt, "cache_probe.cl", options, &testKernelSources(), &hit);
  return hit;
}

// The same, then runs the program and checks what it writes (item i holds i * factor).
bool runProbeHitsCache(ClRuntime& rt, const std::string& options, cl_uint factor) {
  bool hit = false;
  cl::Program program = buildProgram(rt, "cache_probe.cl", options, &testKernelSources(), &hit);
  expectProbe(rt, program, factor);
  return hit;
}

}  // namespace

// ---------------------------------------------------------------- discovery and selection

TEST(Devices, ListsEveryDeviceWithItsProperties) {
  SKIP_WITHOUT_DEVICES();
  const std::vector<DeviceInfo> devices = listDevices();
  for (size_t i = 0; i < devices.size(); ++i) {
    const DeviceInfo& d = devices[i];
    EXPECT_EQ(d.index, static_cast<int>(i));
    EXPECT_FALSE(d.name.empty());
    EXPECT_FALSE(d.platformName.empty());
    EXPECT_TRUE(std::set<std::string>({"GPU", "CPU", "accelerator", "other"}).count(d.type)) << d.type;
    EXPECT_GT(d.computeUnits, 0u);
    EXPECT_GT(d.globalMemBytes, 0u);
    EXPECT_GT(d.maxAllocBytes, 0u);
    EXPECT_LE(d.maxAllocBytes, d.globalMemBytes);
    EXPECT_GT(d.maxWorkGroupSize, 0u);
    EXPECT_NE(d.deviceVersion.find("OpenCL"), std::string::npos) << d.deviceVersion;
    if (d.imageSupport) EXPECT_GT(d.image3dMax[0] * d.image3dMax[1] * d.image3dMax[2], 0u);
  }
  EXPECT_EQ(listDevices().size(), devices.size()) << "the order must be stable";
}

TEST(Devices, DefaultPicksTheFirstGpuElseTheFirstCpu) {
  SKIP_WITHOUT_DEVICES();
  const std::vector<DeviceInfo> devices = listDevices();
  int expected = -1;
  for (const char* type : {"GPU", "CPU"}) {
    for (const DeviceInfo& d : devices)
      if (d.type == type) {
        expected = d.index;
        break;
      }
    if (expected >= 0) break;
  }
  if (expected < 0) expected = 0;
  const SelectedDevice sel = selectDevice("");
  EXPECT_EQ(sel.info.index, expected);
  // (DeviceInfo trims the trailing spaces some drivers pad names with.)
  EXPECT_EQ(std::string(sel.device.getInfo<CL_DEVICE_NAME>().c_str()).substr(0, sel.info.name.size()),
            sel.info.name);
}

TEST(Devices, SelectsByIndex) {
  SKIP_WITHOUT_DEVICES();
  const std::vector<DeviceInfo> devices = listDevices();
  for (const DeviceInfo& d : devices) {
    const SelectedDevice sel = selectDevice(std::to_string(d.index));
    EXPECT_EQ(sel.info.index, d.index);
    EXPECT_EQ(sel.info.name, d.name);
    EXPECT_EQ(sel.platform.getInfo<CL_PLATFORM_NAME>().c_str(), d.platformName);
  }
}

TEST(Devices, SelectsByCaseInsensitiveSubstringOfTheName) {
  SKIP_WITHOUT_DEVICES();
  const std::vector<DeviceInfo> devices = listDevices();
  // PoCL's CPU device is called "pthread-<cpu>-<model>" (clinfo -l); the platform, not the device,
  // is "Portable Computing Language".
  for (const DeviceInfo& d : devices)
    if (d.name.find("pthread") != std::string::npos) {
      EXPECT_EQ(selectDevice("PTHREAD").info.name.find("pthread"), 0u);
      break;
    }
  // Any device: its own name in upper case finds it (or an earlier device with the same name).
  const DeviceInfo& last = devices.back();
  std::string upper = last.name;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(selectDevice(upper).info.name, last.name);
}

TEST(Devices, FallsBackToThePlatformName) {
  SKIP_WITHOUT_DEVICES();
  // No device name contains "computing language"; PoCL's platform name does, so the first device
  // of that platform is chosen. On a machine without PoCL the spec matches nothing.
  for (const DeviceInfo& d : listDevices())
    if (d.platformName == "Portable Computing Language") {
      EXPECT_EQ(selectDevice("computing LANGUAGE").info.platformName, "Portable Computing Language");
      return;
    }
  GTEST_SKIP() << "PoCL is not installed here";
}

TEST(Devices, NoMatchIsAnInputErrorListingTheDevices) {
  SKIP_WITHOUT_DEVICES();
  std::string list;
  for (const DeviceInfo& d : listDevices())
    list += (list.empty() ? "" : ", ") + std::to_string(d.index) + ": " + d.name;
  try {
    selectDevice("xyz-no-such-device");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--device: no OpenCL device matches 'xyz-no-such-device' (devices: " + list + ")");
  }
  EXPECT_THROW(selectDevice(std::to_string(listDevices().size())), InputError);
  EXPECT_THROW(selectDevice("99999999999999999999"), InputError);
}

// A machine without any OpenCL platform: this binary runs again with an ICD folder that does not
// exist (ocl-icd and the Khronos loader read OCL_ICD_VENDORS once, at the first OpenCL call).
TEST(Devices, NoPlatformGivesAnEmptyListAndAClearError) {
  if (std::getenv("NARVAL_TEST_NO_PLATFORM_CHILD")) {
    if (!listDevices().empty()) GTEST_SKIP() << "the ICD loader ignored OCL_ICD_VENDORS";
    try {
      selectDevice("");
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()),
                "no OpenCL platform found: install an OpenCL driver (e.g. Debian's pocl-opencl-icd)");
    }
    EXPECT_THROW(ClRuntime("0"), InputError);
    EXPECT_EQ(devicesJson({}), "[]\n");
    return;
  }
  const fs::path self = fs::read_symlink("/proc/self/exe");
  TempDir dir;
  const fs::path log = dir.path() / "child.log";
  const std::string cmd = "NARVAL_TEST_NO_PLATFORM_CHILD=1 OCL_ICD_VENDORS='" + (dir.path() / "none").string() +
                          "' '" + self.string() +
                          "' --gtest_filter=Devices.NoPlatformGivesAnEmptyListAndAClearError > '" +
                          log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string out = readFile(log);
  if (out.find("[  SKIPPED ] 1 test") != std::string::npos) GTEST_SKIP() << out;
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("[  PASSED  ] 1 test"), std::string::npos) << out;
}

// Without a device a device test skips, unless NARVAL_REQUIRE_DEVICE=1 (as in CI) makes that a
// failure: this binary again, with no ICD, on a test guarded by SKIP_WITHOUT_DEVICES.
TEST(Devices, RequireDeviceTurnsTheSkipIntoAFailure) {
  const fs::path self = fs::read_symlink("/proc/self/exe");
  TempDir dir;
  const fs::path log = dir.path() / "child.log";
  auto runChild = [&](const std::string& require) {
    const std::string cmd = "env -u NARVAL_REQUIRE_DEVICE " + require + " OCL_ICD_VENDORS='" +
                            (dir.path() / "none").string() + "' '" + self.string() +
                            "' --gtest_filter=Devices.SelectsByIndex > '" + log.string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    return std::make_pair(status, readFile(log));
  };
  const auto [skipStatus, skipped] = runChild("");
  if (skipped.find("[  PASSED  ] 1 test") != std::string::npos)
    GTEST_SKIP() << "the ICD loader ignored OCL_ICD_VENDORS: " << skipped;
  EXPECT_EQ(skipStatus, 0) << skipped;
  EXPECT_NE(skipped.find("[  SKIPPED ] 1 test"), std::string::npos) << skipped;
  const auto [failStatus, failed] = runChild("NARVAL_REQUIRE_DEVICE=1");
  EXPECT_NE(failStatus, 0) << failed;
  EXPECT_NE(failed.find("no OpenCL platform or device on this machine, and NARVAL_REQUIRE_DEVICE=1"),
            std::string::npos)
      << failed;
  EXPECT_NE(failed.find("[  FAILED  ] 1 test"), std::string::npos) << failed;
}

TEST(Devices, JsonParsesWithEveryKey) {
  SKIP_WITHOUT_DEVICES();
  const std::vector<DeviceInfo> devices = listDevices();
  const nlohmann::json j = nlohmann::json::parse(devicesJson(devices));
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), devices.size());
  for (const char* key : {"index", "platform", "name", "vendor", "type", "driver_version",
                          "device_version", "opencl_c_version", "compute_units", "global_mem_bytes",
                          "max_alloc_bytes", "local_mem_bytes", "max_work_group_size", "image_support",
                          "image3d_max", "fp64"})
    EXPECT_TRUE(j[0].contains(key)) << key;
  EXPECT_EQ(j[0]["name"], devices[0].name);
  EXPECT_EQ(j[0]["global_mem_bytes"].get<size_t>(), devices[0].globalMemBytes);
  ASSERT_TRUE(j[0]["image3d_max"].is_array());
  EXPECT_EQ(j[0]["image3d_max"].size(), 3u);
  EXPECT_TRUE(j[0]["fp64"].is_boolean());
  EXPECT_EQ(nlohmann::json::parse(devicesJson({})), nlohmann::json::array());
}

TEST(Devices, TextHasAHeaderAndOneRowPerDevice) {
  SKIP_WITHOUT_DEVICES();
  const std::vector<DeviceInfo> devices = listDevices();
  const std::string text = devicesText(devices);
  size_t lines = 0;
  for (char c : text) lines += c == '\n';
  EXPECT_EQ(lines, devices.size() + 1) << text;
  for (const DeviceInfo& d : devices) EXPECT_NE(text.find(d.name), std::string::npos) << text;
  EXPECT_NE(text.find("global mem"), std::string::npos) << text;
  EXPECT_NE(devicesText({}).find("no OpenCL device"), std::string::npos);
}

// ---------------------------------------------------------------- runtime and errors

TEST(ClRuntime, OpensAContextAndAProfilingQueue) {
  SKIP_WITHOUT_DEVICES();
  ClRuntime rt("");
  EXPECT_EQ(rt.context.getInfo<CL_CONTEXT_DEVICES>().size(), 1u);
  EXPECT_TRUE(rt.queue.getInfo<CL_QUEUE_PROPERTIES>() & CL_QUEUE_PROFILING_ENABLE);
  EXPECT_THROW(ClRuntime("xyz-no-such-device"), InputError);
}

TEST(ClRuntime, NamesErrorCodes) {
  EXPECT_EQ(clErrorName(CL_OUT_OF_RESOURCES), "CL_OUT_OF_RESOURCES (-5)");
  EXPECT_EQ(clErrorName(0), "CL_SUCCESS (0)");
  EXPECT_EQ(clErrorName(-11), "CL_BUILD_PROGRAM_FAILURE (-11)");
  EXPECT_EQ(clErrorName(-68), "CL_INVALID_DEVICE_PARTITION_COUNT (-68)");
  EXPECT_EQ(clErrorName(-1001), "CL_PLATFORM_NOT_FOUND_KHR (-1001)");
  EXPECT_EQ(clErrorName(-12345), "unknown OpenCL error (-12345)");
  // Every OpenCL 1.2 code has a name.
  for (int code = -68; code <= 0; ++code)
    if (code >= -19 || code <= -30)
      EXPECT_EQ(clErrorName(code).rfind("CL_", 0), 0u) << clErrorName(code);
  EXPECT_EQ(clErrorText(cl::Error(-5, "clEnqueueNDRangeKernel")),
            "clEnqueueNDRangeKernel: CL_OUT_OF_RESOURCES (-5)");
}

// ---------------------------------------------------------------- program builds and cache

TEST(ProgramCache, BuildErrorNamesTheRealFileAndLine) {
  SKIP_WITHOUT_DEVICES();
  ScopedEnv cache("NARVAL_CACHE_DIR", std::string("off"));
  // The line of the deliberate error, read from the file itself so the test follows edits.
  std::ifstream in(std::string(NARVAL_SOURCE_DIR) + "/tests/device/build_error_test.cl");
  ASSERT_TRUE(in) << "cannot read build_error_test.cl";
  int errorLine = 0;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (line.find("deliberate type error") != std::string::npos) errorLine = n;
  ASSERT_GT(errorLine, 0);

  ClRuntime rt("");
  try {
    buildProgram(rt, "build_error_test.cl", "", &testKernelSources());
    FAIL() << "expected ProgramBuildError";
  } catch (const ProgramBuildError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("OpenCL build of build_error_test.cl failed:\n", 0), 0u) << what;
    EXPECT_NE(what.find("tests/device/build_error_test.cl:" + std::to_string(errorLine) + ":"),
              std::string::npos)
        << "the log must name the real file and line " << errorLine << ":\n"
        << what;
  }
}

// NVIDIA's compiler ignores #line and reports the flattened line ("<kernel>:76:25:"). In this
// flattened source, line 5 is the first line after the marker "#line 3 \"b.h\"" (line 4), so
// flattened line 6 is b.h:4; line 2 follows "#line 1 \"a.cl\"" (line 1), so it is a.cl:1; text
// before any marker and other numbers stay as they are.
TEST(ProgramCache, BuildLogLinesOfDriversThatIgnoreLineMarkersAreMapped) {
  const std::string source = "#line 1 \"a.cl\"\nint a;\nint b;\n#line 3 \"kernels/shared/b.h\"\nint c;\nint d;\n";
  EXPECT_EQ(mapBuildLogLines("<kernel>:6:25: error: x\n<kernel>:2:1: note: y\n<source>:5:3: warning\n", source),
            "kernels/shared/b.h:4:25: error: x\na.cl:1:1: note: y\nkernels/shared/b.h:3:3: warning\n");
  EXPECT_EQ(mapBuildLogLines("a.cl:2:1: error (already mapped by the driver) 10:3:", source),
            "a.cl:2:1: error (already mapped by the driver) 10:3:");
  EXPECT_EQ(mapBuildLogLines("<kernel>:1:1: before any marker", "int x;\n#line 1 \"a.cl\"\nint y;\n"),
            "<kernel>:1:1: before any marker");
  EXPECT_EQ(mapBuildLogLines("<kernel>:3:1: no markers", "int x;\n"), "<kernel>:3:1: no markers");
}

TEST(ProgramCache, UnknownKernelFileIsARuntimeError) {
  SKIP_WITHOUT_DEVICES();
  ClRuntime rt("");
  EXPECT_THROW(buildProgram(rt, "no_such_kernel.cl", "", &testKernelSources()), std::runtime_error);
}

TEST(ProgramCache, SecondBuildComesFromTheCacheAndRuns) {
  SKIP_WITHOUT_DEVICES();
  TempDir dir("narval-cache");
  ASSERT_FALSE(dir.path().empty());
  ScopedEnv cache("NARVAL_CACHE_DIR", dir.path().string());
  ClRuntime rt("");
  EXPECT_FALSE(runProbeHitsCache(rt, "", 2));
  ASSERT_EQ(dir.entries().size(), 1u);
  EXPECT_EQ(fs::path(dir.entries()[0]).extension(), ".bin");

  EXPECT_TRUE(runProbeHitsCache(rt, "", 2));
  EXPECT_EQ(dir.entries().size(), 1u);

  // A fresh runtime (as a second narval process would have) also hits.
  ClRuntime other("");
  EXPECT_TRUE(runProbeHitsCache(other, "", 2));
}

TEST(ProgramCache, OptionsChangeTheKey) {
  SKIP_WITHOUT_DEVICES();
  TempDir dir("narval-cache");
  ScopedEnv cache("NARVAL_CACHE_DIR", dir.path().string());
  ClRuntime rt("");
  EXPECT_FALSE(buildProbeHitsCache(rt));
  EXPECT_FALSE(runProbeHitsCache(rt, "-DPROBE_FACTOR=3", 3));
  EXPECT_EQ(dir.entries().size(), 2u);
  EXPECT_TRUE(runProbeHitsCache(rt, "-DPROBE_FACTOR=3", 3));
}

TEST(ProgramCache, CorruptEntriesFallBackToTheSourceAndAreRewritten) {
  SKIP_WITHOUT_DEVICES();
  TempDir dir("narval-cache");
  ScopedEnv cache("NARVAL_CACHE_DIR", dir.path().string());
  ClRuntime rt("");
  buildProbeHitsCache(rt);
  ASSERT_EQ(dir.entries().size(), 1u);
  const fs::path entry = dir.path() / dir.entries()[0];
  const std::string good = readFile(entry);

  // Truncated: the header's size no longer matches.
  std::ofstream(entry, std::ios::binary | std::ios::trunc) << good.substr(0, good.size() / 2);
  EXPECT_FALSE(runProbeHitsCache(rt, "", 2));
  // Rewritten whole, so read back as a hit (not byte for byte the first entry: a PoCL binary also holds
  // the kernels compiled into PoCL's own cache since, by this test's run or another process's).
  EXPECT_TRUE(buildProbeHitsCache(rt)) << "the entry is rewritten";

  // A well-formed entry whose payload the driver must refuse.
  const std::string payload = "this is not a program binary";
  std::string forged = "NARVALCL";
  for (std::uint64_t v : {std::uint64_t(payload.size()), fnv1a64(payload)})
    for (int i = 0; i < 8; ++i) forged.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  std::ofstream(entry, std::ios::binary | std::ios::trunc) << forged + payload;
  EXPECT_FALSE(runProbeHitsCache(rt, "", 2));
  EXPECT_TRUE(buildProbeHitsCache(rt));
}

TEST(ProgramCache, OffAndUnwritableFoldersNeverFail) {
  SKIP_WITHOUT_DEVICES();
  ClRuntime rt("");
  {
    ScopedEnv cache("NARVAL_CACHE_DIR", std::string("off"));
    EXPECT_EQ(programCacheDir(), "");
    EXPECT_FALSE(runProbeHitsCache(rt, "", 2));
  }
  {
    // A folder under a regular file can never be created.
    TempDir dir("narval-cache");
    const fs::path file = dir.path() / "a-file";
    std::ofstream(file) << "x";
    ScopedEnv cache("NARVAL_CACHE_DIR", (file / "cache").string());
    EXPECT_FALSE(runProbeHitsCache(rt, "", 2));
  }
}

TEST(ProgramCache, FolderFollowsTheEnvironment) {
  ScopedEnv narval("NARVAL_CACHE_DIR", std::nullopt);
  {
    ScopedEnv xdg("XDG_CACHE_HOME", std::string("/tmp/xdg"));
    EXPECT_EQ(programCacheDir(), "/tmp/xdg/narval");
  }
  {
    ScopedEnv xdg("XDG_CACHE_HOME", std::nullopt);
    ScopedEnv home("HOME", std::string("/home/someone"));
    EXPECT_EQ(programCacheDir(), "/home/someone/.cache/narval");
  }
  // A driver with a cache of its own (PoCL) gets narval's only where NARVAL_CACHE_DIR names a folder.
  EXPECT_EQ(programCacheDir(/*driverCaches=*/true), "");
  ScopedEnv set("NARVAL_CACHE_DIR", std::string("/var/tmp/nc"));
  EXPECT_EQ(programCacheDir(), "/var/tmp/nc");
  EXPECT_EQ(programCacheDir(/*driverCaches=*/true), "/var/tmp/nc");
}

// Without NARVAL_CACHE_DIR a build writes to the default folder exactly when the driver keeps no
// cache of its own (PoCL keeps one: nothing is written there, and nothing comes from narval's cache).
TEST(ProgramCache, TheDefaultFolderIsLeftToADriverThatCachesItself) {
  SKIP_WITHOUT_DEVICES();
  TempDir home("narval-cache-home");
  ScopedEnv narval("NARVAL_CACHE_DIR", std::nullopt);
  ScopedEnv xdg("XDG_CACHE_HOME", home.path().string());
  ClRuntime rt("");
  const bool own = driverCachesPrograms(rt.selected.info);
  EXPECT_FALSE(runProbeHitsCache(rt, "-DPROBE_FACTOR=5", 5));
  EXPECT_EQ(fs::exists(home.path() / "narval"), !own);
  EXPECT_EQ(runProbeHitsCache(rt, "-DPROBE_FACTOR=5", 5), !own);
}
