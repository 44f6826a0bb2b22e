// cl_runtime.cpp: one context and one in-order profiling queue on the selected device.
#include "cl/cl_runtime.h"

namespace narval {

ClRuntime::ClRuntime(const std::string& deviceSpec) : selected(selectDevice(deviceSpec)) {
  try {
    context = cl::Context(selected.device);
    queue = cl::CommandQueue(context, selected.device, CL_QUEUE_PROFILING_ENABLE);
  } catch (const cl::Error& e) {
    throw std::runtime_error("cannot open OpenCL device " + std::to_string(selected.info.index) + " (" +
                             selected.info.name + "): " + clErrorText(e));
  }
}

}  // namespace narval
