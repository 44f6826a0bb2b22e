// device_list.cpp: every OpenCL device of every platform, `--device SPEC` selection, and the
// listings of `narval devices [--json]`. Queries go through the C API so a machine without any
// platform (the ICD loader answers CL_PLATFORM_NOT_FOUND_KHR) or a half-broken driver yields fewer
// devices, never an exception.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "core/input_error.h"

namespace narval {

namespace {

struct Found {
  cl_platform_id platform;
  cl_device_id device;
  DeviceInfo info;
};

// A string query of clGetPlatformInfo or clGetDeviceInfo (`get(size, value, sizeRet)`): "" when
// the driver refuses it; cut at its terminating NUL.
template <typename Get>
std::string infoString(Get&& get) {
  size_t size = 0;
  if (get(0, nullptr, &size) != CL_SUCCESS || size == 0) return "";
  std::string s(size, '\0');
  if (get(size, &s[0], nullptr) != CL_SUCCESS) return "";
  s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
  return s;
}

std::string platformString(cl_platform_id p, cl_platform_info what) {
  return infoString([&](size_t n, void* v, size_t* r) { return clGetPlatformInfo(p, what, n, v, r); });
}

std::string deviceString(cl_device_id d, cl_device_info what) {
  std::string s = infoString([&](size_t n, void* v, size_t* r) { return clGetDeviceInfo(d, what, n, v, r); });
  // Some drivers pad names with spaces.
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

template <typename T>
T deviceValue(cl_device_id d, cl_device_info what) {
  T value{};
  if (clGetDeviceInfo(d, what, sizeof(T), &value, nullptr) != CL_SUCCESS) return T{};
  return value;
}

std::vector<Found> enumerate() {
  std::vector<Found> found;
  cl_uint numPlatforms = 0;
  if (clGetPlatformIDs(0, nullptr, &numPlatforms) != CL_SUCCESS || numPlatforms == 0) return found;
  std::vector<cl_platform_id> platforms(numPlatforms);
  if (clGetPlatformIDs(numPlatforms, platforms.data(), nullptr) != CL_SUCCESS) return found;
  for (cl_platform_id p : platforms) {
    cl_uint numDevices = 0;
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &numDevices) != CL_SUCCESS || numDevices == 0)
      continue;
    std::vector<cl_device_id> devices(numDevices);
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, numDevices, devices.data(), nullptr) != CL_SUCCESS)
      continue;
    const std::string platformName = platformString(p, CL_PLATFORM_NAME);
    const std::string platformVersion = platformString(p, CL_PLATFORM_VERSION);
    for (cl_device_id d : devices) {
      DeviceInfo info;
      info.index = static_cast<int>(found.size());
      info.platformName = platformName;
      info.platformVersion = platformVersion;
      info.name = deviceString(d, CL_DEVICE_NAME);
      info.vendor = deviceString(d, CL_DEVICE_VENDOR);
      info.driverVersion = deviceString(d, CL_DRIVER_VERSION);
      info.deviceVersion = deviceString(d, CL_DEVICE_VERSION);
      info.openclCVersion = deviceString(d, CL_DEVICE_OPENCL_C_VERSION);
      const cl_device_type type = deviceValue<cl_device_type>(d, CL_DEVICE_TYPE);
      info.type = (type & CL_DEVICE_TYPE_GPU)           ? "GPU"
                  : (type & CL_DEVICE_TYPE_CPU)         ? "CPU"
                  : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
                                                        : "other";
      info.computeUnits = deviceValue<cl_uint>(d, CL_DEVICE_MAX_COMPUTE_UNITS);
      info.globalMemBytes = deviceValue<cl_ulong>(d, CL_DEVICE_GLOBAL_MEM_SIZE);
      info.maxAllocBytes = deviceValue<cl_ulong>(d, CL_DEVICE_MAX_MEM_ALLOC_SIZE);
      info.localMemBytes = deviceValue<cl_ulong>(d, CL_DEVICE_LOCAL_MEM_SIZE);
      info.constantBufferBytes = deviceValue<cl_ulong>(d, CL_DEVICE_MAX_CONSTANT_BUFFER_SIZE);
      info.maxWorkGroupSize = deviceValue<size_t>(d, CL_DEVICE_MAX_WORK_GROUP_SIZE);
      info.imageSupport = deviceValue<cl_bool>(d, CL_DEVICE_IMAGE_SUPPORT) == CL_TRUE;
      if (info.imageSupport) {
        info.image3dMax[0] = deviceValue<size_t>(d, CL_DEVICE_IMAGE3D_MAX_WIDTH);
        info.image3dMax[1] = deviceValue<size_t>(d, CL_DEVICE_IMAGE3D_MAX_HEIGHT);
        info.image3dMax[2] = deviceValue<size_t>(d, CL_DEVICE_IMAGE3D_MAX_DEPTH);
      }
      info.fp64 = deviceValue<cl_device_fp_config>(d, CL_DEVICE_DOUBLE_FP_CONFIG) != 0 ||
                  deviceString(d, CL_DEVICE_EXTENSIONS).find("cl_khr_fp64") != std::string::npos;
      found.push_back({p, d, info});
    }
  }
  return found;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string deviceListForMessage(const std::vector<Found>& found) {
  std::string s;
  for (const Found& f : found)
    s += (s.empty() ? "" : ", ") + std::to_string(f.info.index) + ": " + f.info.name;
  return s;
}

// "1.5 GiB", "512 MiB", "64 KiB".
std::string bytesText(size_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 4) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, (u > 0 && v < 10.0) ? "%.1f %s" : "%.0f %s", v, units[u]);
  return buf;
}

}  // namespace

std::vector<DeviceInfo> listDevices() {
  std::vector<DeviceInfo> infos;
  for (Found& f : enumerate()) infos.push_back(std::move(f.info));
  return infos;
}

SelectedDevice selectDevice(const std::string& spec) {
  const std::vector<Found> found = enumerate();
  if (found.empty()) {
    cl_uint numPlatforms = 0;
    if (clGetPlatformIDs(0, nullptr, &numPlatforms) == CL_SUCCESS && numPlatforms > 0)
      throw InputError("no OpenCL device found: the installed OpenCL platforms report no devices");
    throw InputError("no OpenCL platform found: install an OpenCL driver (e.g. Debian's pocl-opencl-icd)");
  }
  const Found* chosen = nullptr;
  if (spec.empty()) {
    for (const char* type : {"GPU", "CPU"}) {
      for (const Found& f : found)
        if (f.info.type == type) {
          chosen = &f;
          break;
        }
      if (chosen) break;
    }
    if (!chosen) chosen = &found.front();
  } else if (std::all_of(spec.begin(), spec.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    const unsigned long index = spec.size() > 9 ? found.size() : std::stoul(spec);
    if (index >= found.size())
      throw inputError("--device", "",
                       "no OpenCL device has index " + spec + " (devices: " + deviceListForMessage(found) + ")");
    chosen = &found[index];
  } else {
    // The device name first (DESIGN.md); then the platform name, so "pocl" or "nvidia" work too.
    const std::string needle = lower(spec);
    for (const bool byPlatform : {false, true}) {
      for (const Found& f : found)
        if (lower(byPlatform ? f.info.platformName : f.info.name).find(needle) != std::string::npos) {
          chosen = &f;
          break;
        }
      if (chosen) break;
    }
    if (!chosen)
      throw inputError("--device", "",
                       "no OpenCL device matches '" + spec + "' (devices: " + deviceListForMessage(found) + ")");
  }
  SelectedDevice sel;
  // retainObject=true: the C++ wrappers then own a reference of their own.
  sel.platform = cl::Platform(chosen->platform, true);
  sel.device = cl::Device(chosen->device, true);
  sel.info = chosen->info;
  return sel;
}

std::string devicesText(const std::vector<DeviceInfo>& devices) {
  if (devices.empty())
    return "no OpenCL device found: install an OpenCL driver (e.g. Debian's pocl-opencl-icd)\n";
  std::vector<std::vector<std::string>> rows = {{"#", "type", "name", "platform", "driver", "CUs",
                                                 "global mem", "max alloc", "image3d max", "max WG"}};
  for (const DeviceInfo& d : devices) {
    std::string image3d = "none";
    if (d.imageSupport)
      image3d = std::to_string(d.image3dMax[0]) + "x" + std::to_string(d.image3dMax[1]) + "x" +
                std::to_string(d.image3dMax[2]);
    rows.push_back({std::to_string(d.index), d.type, d.name, d.platformName, d.driverVersion,
                    std::to_string(d.computeUnits), bytesText(d.globalMemBytes),
                    bytesText(d.maxAllocBytes), image3d, std::to_string(d.maxWorkGroupSize)});
  }
  std::vector<size_t> width(rows[0].size(), 0);
  for (const auto& row : rows)
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  std::ostringstream out;
  for (const auto& row : rows) {
    std::string line;
    for (size_t c = 0; c < row.size(); ++c) {
      std::string cell = row[c];
      if (c + 1 < row.size()) cell.resize(width[c] + 2, ' ');
      line += cell;
    }
    out << line << "\n";
  }
  return out.str();
}

std::string devicesJson(const std::vector<DeviceInfo>& devices) {
  nlohmann::ordered_json array = nlohmann::ordered_json::array();  // keys in the order above
  for (const DeviceInfo& d : devices) {
    array.push_back({{"index", d.index},
                     {"platform", d.platformName},
                     {"platform_version", d.platformVersion},
                     {"name", d.name},
                     {"vendor", d.vendor},
                     {"type", d.type},
                     {"driver_version", d.driverVersion},
                     {"device_version", d.deviceVersion},
                     {"opencl_c_version", d.openclCVersion},
                     {"compute_units", d.computeUnits},
                     {"global_mem_bytes", d.globalMemBytes},
                     {"max_alloc_bytes", d.maxAllocBytes},
                     {"local_mem_bytes", d.localMemBytes},
                     {"constant_buffer_bytes", d.constantBufferBytes},
                     {"max_work_group_size", d.maxWorkGroupSize},
                     {"image_support", d.imageSupport},
                     {"image3d_max", {d.image3dMax[0], d.image3dMax[1], d.image3dMax[2]}},
                     {"fp64", d.fp64}});
  }
  return array.dump(2) + "\n";
}

}  // namespace narval
