#include "cl/device_allocation.h"

#include <cstdio>

#include "core/input_error.h"

namespace narval {
namespace {

bool isResourceError(int code) {
  return code == CL_MEM_OBJECT_ALLOCATION_FAILURE || code == CL_OUT_OF_RESOURCES || code == CL_OUT_OF_HOST_MEMORY;
}

}  // namespace

std::string byteCount(size_t bytes) {
  const std::string exact = std::to_string(bytes) + " bytes";
  if (bytes < 1024) return exact;
  const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB"};
  double v = double(bytes) / 1024.0;
  int u = 0;
  while (v >= 1024.0 && u < 4) v /= 1024.0, ++u;
  char scaled[32];
  std::snprintf(scaled, sizeof scaled, " (%.2f %s)", v, units[u]);
  return exact + scaled;
}

void checkAllocation(const DeviceInfo& device, size_t bytes, const AllocationSite& site) {
  if (bytes <= device.maxAllocBytes) return;
  throw inputError(site.file, site.key,
                   site.what + " needs " + byteCount(bytes) + ", over the largest allocation of device '" +
                       device.name + "', " + byteCount(device.maxAllocBytes));
}

cl::Buffer allocateBuffer(ClRuntime& rt, cl_mem_flags flags, size_t bytes, const AllocationSite& site,
                          void* hostData) {
  checkAllocation(rt.selected.info, bytes, site);
  try {
    return cl::Buffer(rt.context, flags, bytes, hostData);
  } catch (const cl::Error& e) {
    if (!isResourceError(e.err())) throw;
    throw DeviceFault("device '" + rt.selected.info.name + "' could not allocate " + site.what + " of " +
                      byteCount(bytes) + ": " + clErrorName(e.err()));
  }
}

void rethrowLaunchError(const cl::Error& e, const DeviceInfo& device, const std::string& what, size_t deviceBytes) {
  if (!isResourceError(e.err())) throw e;
  throw DeviceFault("device '" + device.name + "' ran out of memory or resources running " + what +
                    " (this render holds " + byteCount(deviceBytes) + " of device memory): " +
                    clErrorName(e.err()));
}

}  // namespace narval
