// device_allocation.h: device memory with errors that name the size asked for.
// An allocation over the device's largest (CL_DEVICE_MAX_MEM_ALLOC_SIZE) is refused before asking
// the driver: InputError "FILE: KEY: ..." (exit 2), since the scene asked for more than the device
// has. What the driver refuses at allocation or launch time (CL_MEM_OBJECT_ALLOCATION_FAILURE,
// CL_OUT_OF_RESOURCES, CL_OUT_OF_HOST_MEMORY) becomes a DeviceFault naming the bytes (exit 1).
#pragma once

#include <stdexcept>
#include <string>

#include "cl/cl_runtime.h"

namespace narval {

// What an allocation is for, for messages: the scene file and key that decided its size.
struct AllocationSite {
  std::string file, key, what;
};

struct DeviceFault : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "4294967296 bytes (4.00 GiB)"; "512 bytes" below 1 KiB.
std::string byteCount(size_t bytes);

// Throws InputError "FILE: KEY: WHAT needs N bytes (X GiB), over the largest allocation of device
// 'NAME', M bytes (Y GiB)" when bytes > device.maxAllocBytes.
void checkAllocation(const DeviceInfo& device, size_t bytes, const AllocationSite& site);

// checkAllocation, then a buffer; a driver refusal is a DeviceFault naming the size.
cl::Buffer allocateBuffer(ClRuntime& rt, cl_mem_flags flags, size_t bytes, const AllocationSite& site,
                          void* hostData = nullptr);

// For an error of a launch: resource errors (see above) become a DeviceFault "device 'NAME' ran out
// of memory or resources running WHAT (this render holds N bytes (X GiB) of device memory):
// CL_OUT_OF_RESOURCES (-5)"; anything else is rethrown as it is.
[[noreturn]] void rethrowLaunchError(const cl::Error& e, const DeviceInfo& device, const std::string& what,
                                     size_t deviceBytes);

}  // namespace narval
