// The host binds kernel arguments by the names listed in cl/kernel_args.cpp; each list must be the
// kernel's own signature. Every kernel is built from source with -cl-kernel-arg-info in each build
// variant that changes its signature (the grid as an unused int, a buffer or an image; the path
// tracer's counters; emission), and the device's names (clGetKernelArgInfo) must equal the list, in order.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "cl/kernel_args.h"

namespace narval {
namespace {

// The arguments' names do not depend on optimisation, which is most of a build's time
// (-cl-opt-disable: these builds are never run).
std::vector<std::string> deviceArgumentNames(ClRuntime& rt, const std::string& kernel, const std::string& options) {
  const cl::Program program = buildProgram(rt, kernel == "light_cache_build" ? "light_cache.cl"
                                               : kernel.rfind("ms_cache_", 0) == 0 ? "ms_cache.cl"
                                                                             : kernel + ".cl",
                                           options + " -cl-kernel-arg-info -cl-opt-disable");
  const cl::Kernel k(program, kernel.c_str());
  std::vector<std::string> names;
  const cl_uint count = k.getInfo<CL_KERNEL_NUM_ARGS>();
  for (cl_uint i = 0; i < count; ++i) {
    std::string name = k.getArgInfo<CL_KERNEL_ARG_NAME>(i);
    name.erase(name.find_last_not_of('\0') + 1);  // some drivers count the terminator
    names.push_back(name);
  }
  return names;
}

TEST(KernelArgs, EveryListIsItsKernelsSignatureInEveryVariant) {
  ClRuntime rt("");
  const std::vector<std::string> kernels = kernelsWithArgumentNames();
  ASSERT_EQ(kernels, (std::vector<std::string>{"light_cache_build", "lobe", "ms_cache_blend_view", "ms_cache_build",
                                                "ms_cache_filter_view", "ms_cache_place_view", "ms_cache_reproject_view",
                                                "pathtrace", "raymarch"}));
  for (const std::string& kernel : kernels) {
    std::vector<std::string> listed = kernelArgumentNames(kernel);
    // Bricks take the buffer's signature (grid.h): the three kinds of grid argument are these.
    // With and without -DEMISSION: the emission grid and table are arguments of every build.
    for (const char* variant : {"-DMEDIUM_HOMOGENEOUS", "-DGRID_STORAGE_BUFFER", "", "-DMEDIUM_HOMOGENEOUS -DEMISSION",
                                "-DGRID_STORAGE_BUFFER -DEMISSION", "-DEMISSION"}) {
      SCOPED_TRACE(kernel + " " + variant);
      std::vector<std::string> expected = listed;
      if (kernel == "pathtrace") {
        EXPECT_EQ(deviceArgumentNames(rt, kernel, std::string(variant) + " -DCOUNTERS"), expected);
        expected.pop_back();  // counter_buf: the -DCOUNTERS build's last argument only
      }
      EXPECT_EQ(deviceArgumentNames(rt, kernel, variant), expected);
    }
  }
}

TEST(KernelArgs, AnUnknownNameIsAnErrorNamingTheArguments) {
  ClRuntime rt("");
  const cl::Program program = buildProgram(rt, "light_cache.cl", "-DMEDIUM_HOMOGENEOUS");
  NamedKernel k(program, "light_cache_build");
  EXPECT_NO_THROW(k.set("light", cl_int(0)));
  try {
    k.set("status", cl_int(0));
    FAIL() << "no error";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(),
                 "kernel 'light_cache_build' has no argument 'status' (its arguments: scene, lights, grid, "
                 "grid_majorants, emission_grid, emission_table, march, light_cache, light, cache, status_word)");
  }
  EXPECT_THROW(kernelArgumentNames("volume_march"), std::logic_error);
}

}  // namespace
}  // namespace narval
