/* build_error_test.cl: a kernel that DELIBERATELY fails to compile. tests/device/cl_runtime_test.cpp
 * checks that the build error names this file and the line of the error below, which proves the
 * #line markers of tools/embed_kernels.cpp survive the include of shared/compat.h. */
#include "shared/compat.h"

__kernel void build_error_test(__global float* out) {
  out[get_global_id(0)] = vec3_make(1.0f, 2.0f, 3.0f); /* deliberate type error: float3 into float */
}
