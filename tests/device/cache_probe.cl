/* cache_probe.cl: the smallest useful kernel, built twice by tests/device/cl_runtime_test.cpp to
 * check the program cache (the second build must come from the cached binary and still run). */
#include "shared/compat.h"

#ifndef PROBE_FACTOR
#define PROBE_FACTOR 2
#endif

__kernel void cache_probe(__global uint* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i < n) out[i] = i * PROBE_FACTOR;
}
