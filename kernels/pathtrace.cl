/* pathtrace.cl: thin entry point over shared/pathtrace.h. One work-item per pixel adds the samples
 * [sample_begin, sample_begin + sample_count) to a compensated accumulator, so long renders run as
 * many short launches (progress, no GPU watchdog) and any split gives the same per-sample values.
 * -DCOUNTERS adds a last argument: 3 ulongs per pixel (tentative collisions, real collisions,
 * density lookups; kernel_context.h) to which each work-item adds its own pass's counts, no atomics. */
#include "shared/scene_kinds.h"
#include "shared/accum.h"
#include "shared/pathtrace.h"

__kernel void pathtrace(KERNEL_SCENE_ARGS,
                        __global float4* accum_sum, __global float4* accum_comp, uint sample_begin,
                        uint sample_count, __global uint* status_word
#ifdef COUNTERS
                        , __global ulong* counter_buf
#endif
                        ) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= scene->camera.width || y >= scene->camera.height) return;
  KERNEL_CONTEXT_BEGIN(ctx); /* counters (-DCOUNTERS) start at 0 */
  ctx.status = scene_kinds_status(scene, lights); /* unknown kinds: STATUS_UNKNOWN_KIND */
  const int idx = y * scene->camera.width + x;
  const float4 a = accum_sum[idx], c = accum_comp[idx];
  float ax = a.x, ay = a.y, az = a.z, cx = c.x, cy = c.y, cz = c.z;
  /* Every sample goes through the compensated sum: a small image may run 10⁶ samples in one launch. */
  for (uint s = 0u; s < sample_count; ++s) {
    const vec3 L = pathtrace_sample(KERNEL_ENTRY_ARG(ctx), x, y, sample_begin + s);
    accum_kahan_add(&ax, &cx, L.x);
    accum_kahan_add(&ay, &cy, L.y);
    accum_kahan_add(&az, &cz, L.z);
  }
  accum_sum[idx] = (float4)(ax, ay, az, 0.0f);
  accum_comp[idx] = (float4)(cx, cy, cz, 0.0f);
  if (ctx.status) atomic_or(status_word, ctx.status);
#ifdef COUNTERS
  counter_buf[3 * idx + 0] += ctx.counters.tentative;
  counter_buf[3 * idx + 1] += ctx.counters.real;
  counter_buf[3 * idx + 2] += ctx.counters.lookups;
#endif
}
