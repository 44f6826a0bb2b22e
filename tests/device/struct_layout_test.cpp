// struct_layout_test.cpp: every struct that crosses host and device (kernels/shared/structs.h) has
// the same size and field offsets in C++ and in OpenCL C on the device, and a size that is a
// multiple of 16 bytes (DESIGN.md: declared once, padded explicitly, checked by a layout test).
// The field list lives in tests/device/struct_layout.cl, included here as C++ so that both sides
// walk the same list.
#include <gtest/gtest.h>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "device/struct_layout.cl"
#include "test_support.h"

namespace narval {
const std::map<std::string, std::string>& testKernelSources();
}

namespace {

struct LayoutValue {
  std::string what;  // "sizeof(camera_params)", "offsetof(camera_params, up)", ...
  unsigned value;
  bool isStructSize;
};

#define HOST_LAYOUT_SIZE(type) out.push_back({"sizeof(" #type ")", static_cast<unsigned>(sizeof(type)), true});
#define HOST_LAYOUT_FIELD(type, field)                                                                 \
  out.push_back({"offsetof(" #type ", " #field ")",                                                    \
                 static_cast<unsigned>(STRUCT_LAYOUT_OFFSETOF(type, field)), false});                    \
  out.push_back({"sizeof(" #type "::" #field ")", static_cast<unsigned>(STRUCT_LAYOUT_FIELD_SIZE(type, field)), \
                 false});

std::vector<LayoutValue> hostLayout() {
  std::vector<LayoutValue> out;
  STRUCT_LAYOUT_ENTRIES(HOST_LAYOUT_SIZE, HOST_LAYOUT_FIELD)
  return out;
}

// Sizes fixed by the field list in structs.h (4-byte scalars, nv_float4 = 16, no implicit padding):
// camera 4·16 + 8·4 = 96, light 5·16 + 4·4 = 96, majorant grid 16 + 4·4 = 32,
// emission 48 + 2·16 + 8·4 = 112, phase 16 + 4·4 = 32, medium 48 + 3·16 + 4·4 + 32 + 32 + 112 = 288,
// scene 96 + 288 + 16 + 8·4 = 432, node grid 48 + 4·4 = 64, realtime 12·4 + 2·64 + 16·4 = 240.
// A change to a struct must be a deliberate change here too.
TEST(StructLayoutHost, SizesAreMultiplesOf16) {
  int structs = 0;
  for (const LayoutValue& v : hostLayout()) {
    if (!v.isStructSize) continue;
    ++structs;
    EXPECT_EQ(v.value % 16u, 0u) << v.what << " = " << v.value;
  }
  EXPECT_EQ(structs, 13);  // nv_float4, nv_affine, camera, light, medium, phase, emission, majorant grid, scene,
                           // march, lobe, ms cache, node grid
  EXPECT_EQ(sizeof(nv_float4), 16u);
  EXPECT_EQ(sizeof(nv_affine), 48u);
  EXPECT_EQ(sizeof(camera_params), 96u);
  EXPECT_EQ(sizeof(light_params), 96u);
  EXPECT_EQ(sizeof(node_grid_params), 64u);
  EXPECT_EQ(sizeof(march_params), 48u);
  EXPECT_EQ(sizeof(lobe_params), 32u);
  EXPECT_EQ(sizeof(ms_cache_params), 96u);  // node grid 64 + six fields and two pads of 4
  EXPECT_EQ(sizeof(majorant_grid_params), 32u);
  EXPECT_EQ(sizeof(emission_params), 112u);
  EXPECT_EQ(sizeof(phase_params), 32u);
  EXPECT_EQ(sizeof(medium_params), 288u);
  EXPECT_EQ(sizeof(scene_params), 432u);
}

TEST(StructLayoutOnDevice, MatchesTheHost) {
  if (narval::listDevices().empty()) NARVAL_SKIP_WITHOUT_DEVICE();
  narval::ClRuntime rt("");
  cl::Program program = narval::buildProgram(rt, "struct_layout.cl", "", &narval::testKernelSources());
  const std::vector<LayoutValue> host = hostLayout();
  const cl_uint capacity = static_cast<cl_uint>(host.size() + 16);
  cl::Buffer out(rt.context, CL_MEM_WRITE_ONLY, capacity * sizeof(cl_uint));
  cl::Kernel kernel(program, "struct_layout");
  kernel.setArg(0, out);
  kernel.setArg(1, capacity);
  rt.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1), cl::NullRange);
  std::vector<cl_uint> device(capacity, 0xdeadbeefu);
  rt.queue.enqueueReadBuffer(out, CL_TRUE, 0, capacity * sizeof(cl_uint), device.data());
  ASSERT_EQ(device[0], host.size()) << "the kernel walked a different number of entries";
  for (size_t i = 0; i < host.size(); ++i)
    EXPECT_EQ(device[i + 1], host[i].value) << host[i].what << " on " << rt.selected.info.name;
}

}  // namespace
