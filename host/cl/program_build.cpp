// program_build.cpp: builds an embedded kernel file for one device, with a persistent binary cache
// (DESIGN.md, "Model only what a scene needs": each scene gets its own -D specialisation, so the
// same few programs are built again and again; a cache hit skips the front end).
//
// Cache entry <dir>/<16 hex digits>.bin: "NARVALCL", payload size (u64 LE), FNV-1a of the payload
// (u64 LE), then the payload (CL_PROGRAM_BINARIES for the one device). The key hashes the flattened
// source, the full build options, platform name and version, device name and driver version. A
// truncated or corrupt entry is a miss; a binary the driver refuses falls back to the source and
// the entry is overwritten. The cache never makes a build fail: every cache I/O error is ignored.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>

#include "cl/cl_runtime.h"
#include "cl/kernel_sources.h"
#include "core/atomic_file.h"

namespace narval {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'N', 'A', 'R', 'V', 'A', 'L', 'C', 'L'};
constexpr size_t kHeaderBytes = sizeof kMagic + 16;

std::string envOr(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

void putU64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

std::uint64_t getU64(const std::string& in, size_t pos) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(in[pos + i]);
  return v;
}

std::string hex(std::uint64_t v) {
  static const char digits[] = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4) s[i] = digits[v & 0xf];
  return s;
}

// The payload of a valid cache entry, or "" for a missing, truncated or corrupt one.
std::string readEntry(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.size() <= kHeaderBytes || data.compare(0, sizeof kMagic, kMagic, sizeof kMagic) != 0) return "";
  const std::uint64_t size = getU64(data, sizeof kMagic);
  const std::uint64_t sum = getU64(data, sizeof kMagic + 8);
  if (size != data.size() - kHeaderBytes) return "";
  std::string payload = data.substr(kHeaderBytes);
  return fnv1a64(payload) == sum ? payload : "";
}

// Written atomically: readers see the old entry or the whole new one. A cache that cannot be
// written costs a build next time, nothing more: failures are ignored.
void writeEntry(const fs::path& file, const std::string& payload) {
  std::error_code ec;
  fs::create_directories(file.parent_path(), ec);
  if (ec) return;
  std::string header(kMagic, sizeof kMagic);
  putU64(header, payload.size());
  putU64(header, fnv1a64(payload));
  try {
    writeTextAtomic(file.string(), header + payload);
  } catch (const std::runtime_error&) {
  }
}

std::string buildLog(const cl::Program& program, const cl::Device& device) {
  try {
    return program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
  } catch (const cl::Error&) {
    return "";
  }
}

[[noreturn]] void throwBuildError(const std::string& kernelFile, const cl::Error& e, std::string log,
                                  const std::string& source) {
  log = mapBuildLogLines(log, source);
  while (!log.empty() && (log.back() == '\n' || log.back() == '\0' || log.back() == ' ')) log.pop_back();
  if (log.empty()) log = clErrorText(e) + ", and the driver gave no build log";
  throw ProgramBuildError("OpenCL build of " + kernelFile + " failed:\n" + log);
}

}  // namespace

std::string mapBuildLogLines(const std::string& log, const std::string& source) {
  // (flattened line where a #line marker's next line starts, file, its line number there), in order.
  struct Marker {
    long flat;
    std::string file;
    long line;
  };
  std::vector<Marker> markers;
  {
    std::istringstream in(source);
    std::string text;
    const std::regex lineDirective(R"(^\s*#\s*line\s+(\d+)\s+"([^"]*)\")");
    std::smatch m;
    for (long flat = 1; std::getline(in, text); ++flat)
      if (std::regex_search(text, m, lineDirective)) markers.push_back({flat + 1, m[2], std::stol(m[1])});
  }
  if (markers.empty()) return log;
  const std::regex anonymous(R"(<(kernel|source)>:(\d+):)");
  std::string out;
  auto from = log.cbegin();
  for (std::sregex_iterator it(log.begin(), log.end(), anonymous), end; it != end; ++it) {
    const long flat = std::stol((*it)[2]);
    auto after = std::upper_bound(markers.begin(), markers.end(), flat,
                                  [](long f, const Marker& mk) { return f < mk.flat; });
    out.append(from, log.cbegin() + it->position());
    if (after == markers.begin()) {
      out += it->str();
    } else {
      const Marker& mk = *(after - 1);
      out += mk.file + ":" + std::to_string(mk.line + (flat - mk.flat)) + ":";
    }
    from = log.cbegin() + it->position() + it->length();
  }
  out.append(from, log.cend());
  return out;
}

std::uint64_t fnv1a64(const std::string& data, std::uint64_t h) {
  for (unsigned char c : data) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

bool driverCachesPrograms(const DeviceInfo& device) {
  return device.platformName == "Portable Computing Language";
}

std::string programCacheDir(bool driverCaches) {
  const std::string narval = envOr("NARVAL_CACHE_DIR");
  if (narval == "off") return "";
  if (!narval.empty()) return narval;
  if (driverCaches) return "";
  const std::string xdg = envOr("XDG_CACHE_HOME");
  if (!xdg.empty() && xdg[0] == '/') return (fs::path(xdg) / "narval").string();
  const std::string home = envOr("HOME");
  if (!home.empty()) return (fs::path(home) / ".cache" / "narval").string();
  return "";
}

cl::Program buildProgram(ClRuntime& rt, const std::string& kernelFile, const std::string& options,
                         const std::map<std::string, std::string>* sources, bool* cacheHit) {
  if (cacheHit) *cacheHit = false;
  const std::map<std::string, std::string>& all = sources ? *sources : kernelSources();
  const auto found = all.find(kernelFile);
  if (found == all.end()) {
    std::string names;
    for (const auto& kv : all) names += (names.empty() ? "" : ", ") + kv.first;
    throw std::runtime_error("no embedded OpenCL source named '" + kernelFile + "' (have: " +
                             (names.empty() ? "none" : names) + ")");
  }
  const std::string& source = found->second;
  // Sources are flattened at build time, so no -I; never -cl-fast-relaxed-math (DESIGN.md,
  // platform facts: it breaks determinism and isnan) unless the caller asks for it.
  const std::string fullOptions = "-cl-std=CL1.2" + (options.empty() ? "" : " " + options) +
                                  (rt.extraBuildOptions.empty() ? "" : " " + rt.extraBuildOptions);
  const cl::Device& device = rt.selected.device;
  const DeviceInfo& info = rt.selected.info;

  fs::path entry;
  const std::string dir = programCacheDir(driverCachesPrograms(info));
  if (!dir.empty()) {
    std::uint64_t key = fnv1a64("narval program cache v1");
    for (const std::string* part : {&source, &fullOptions, &info.platformName, &info.platformVersion,
                                    &info.name, &info.driverVersion}) {
      key = fnv1a64(*part, key);
      key = fnv1a64(std::string(1, '\0'), key);  // field separator: ("ab","c") != ("a","bc")
    }
    entry = fs::path(dir) / (hex(key) + ".bin");
    const std::string binary = readEntry(entry);
    if (!binary.empty()) {
      try {
        cl::Program::Binaries binaries{std::vector<unsigned char>(binary.begin(), binary.end())};
        cl::Program program(rt.context, {device}, binaries);
        program.build({device}, fullOptions.c_str());
        if (cacheHit) *cacheHit = true;
        return program;
      } catch (const cl::Error&) {
        // Refused (another driver build, a corrupt entry): rebuild from source, overwrite below.
      }
    }
  }

  cl::Program program;
  try {
    program = cl::Program(rt.context, source);
  } catch (const cl::Error& e) {
    throw std::runtime_error("OpenCL: cannot create program " + kernelFile + ": " + clErrorText(e));
  }
  try {
    program.build({device}, fullOptions.c_str());
  } catch (const cl::BuildError& e) {
    std::string log;
    for (const auto& deviceLog : e.getBuildLog()) log += deviceLog.second;
    if (log.empty()) log = buildLog(program, device);
    throwBuildError(kernelFile, e, log, source);
  } catch (const cl::Error& e) {
    throwBuildError(kernelFile, e, buildLog(program, device), source);
  }

  if (!entry.empty()) {
    try {
      const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
      if (binaries.size() == 1 && !binaries[0].empty())
        writeEntry(entry, std::string(binaries[0].begin(), binaries[0].end()));
    } catch (...) {
      // The cache is an optimisation: never fatal.
    }
  }
  return program;
}

}  // namespace narval
