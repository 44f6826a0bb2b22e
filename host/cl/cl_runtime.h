// cl_runtime.h: OpenCL device discovery and selection, context + profiling queue, and program
// builds from the embedded sources with a persistent binary cache. RAII via the Khronos C++
// bindings; every failure becomes an exception carrying a clear message (and the build log).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <CL/opencl.hpp>

namespace narval {

struct DeviceInfo {
  int index = 0;               // position in listDevices(), what --device N refers to
  std::string platformName, platformVersion;
  std::string name, vendor, driverVersion, deviceVersion, openclCVersion;
  std::string type;            // "GPU", "CPU", "accelerator", "other"
  unsigned computeUnits = 0;
  size_t globalMemBytes = 0, maxAllocBytes = 0, localMemBytes = 0, constantBufferBytes = 0;
  size_t maxWorkGroupSize = 0;
  bool imageSupport = false;
  size_t image3dMax[3] = {0, 0, 0};
  bool fp64 = false;
};

// Every device of every platform, in a stable order (platform, then device).
std::vector<DeviceInfo> listDevices();

// SPEC: "" -> the first GPU, else the first CPU, else the first device; a number -> that index;
// otherwise a case-insensitive substring of the device name. Throws InputError when nothing matches
// (the message lists the devices) or no OpenCL platform exists.
struct SelectedDevice {
  cl::Platform platform;
  cl::Device device;
  DeviceInfo info;
};
SelectedDevice selectDevice(const std::string& spec);

// A context and an in-order queue with profiling enabled on one device.
struct ClRuntime {
  SelectedDevice selected;
  cl::Context context;
  cl::CommandQueue queue;
  // Appended to the options of every buildProgram on this runtime (after the caller's), e.g.
  // "-DNARVAL_TRACKING_MAX_STEPS=8": tests force the kernels' iteration caps through it
  // (tests/render/status_word_test.cpp). Part of the program cache key like any option. Empty in
  // the application.
  std::string extraBuildOptions;
  explicit ClRuntime(const std::string& deviceSpec);
};

// Thrown when clBuildProgram fails: what() is "OpenCL build of FILE failed:\n<full build log>".
struct ProgramBuildError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Builds the embedded kernel file `kernelFile` (e.g. "pathtrace.cl") with `options` (-D defines)
// and rt.extraBuildOptions.
// `sources` defaults to kernelSources(); tests pass their own map. Built binaries are cached in
// programCacheDir(), keyed by a hash of the flattened source, the options, platform, device and
// driver version. `cacheHit`, when given, says whether the binary came from that cache.
cl::Program buildProgram(ClRuntime& rt, const std::string& kernelFile, const std::string& options,
                         const std::map<std::string, std::string>* sources = nullptr,
                         bool* cacheHit = nullptr);

// Drivers that ignore #line directives (NVIDIA's reports "<kernel>:76:25: error") get their
// locations rewritten to the original "kernels/shared/phase.h:12:25:" by the markers the kernel
// embedding left in `flattenedSource`; other text is kept as it is.
std::string mapBuildLogLines(const std::string& log, const std::string& flattenedSource);

// "CL_OUT_OF_RESOURCES (-5)" for an error code.
std::string clErrorName(int code);
// "clCreateContext: CL_DEVICE_NOT_AVAILABLE (-2)" for an exception of the C++ bindings.
std::string clErrorText(const cl::Error& e);

// The program cache folder (see buildProgram), or "" for none: $NARVAL_CACHE_DIR ("off": none), else,
// unless the driver keeps a program cache of its own (`driverCaches`), $XDG_CACHE_HOME/narval or
// ~/.cache/narval ("" when no home is known).
std::string programCacheDir(bool driverCaches = false);
// PoCL caches every program it builds from source (its kcache, keyed by the source and the options,
// as narval's is), and asking it for a program's binary builds each kernel once more, for a
// work-group size left to launch time: as long again as the build. There narval's cache only costs.
bool driverCachesPrograms(const DeviceInfo& device);
// 64-bit FNV-1a of `data`, continuing from `h`: the program cache's key and checksum.
std::uint64_t fnv1a64(const std::string& data, std::uint64_t h = 14695981039346656037ull);

// Human-readable and JSON listings used by `narval devices [--json]`.
std::string devicesText(const std::vector<DeviceInfo>& devices);
std::string devicesJson(const std::vector<DeviceInfo>& devices);

}  // namespace narval
