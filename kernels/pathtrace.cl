/* pathtrace.cl: thin entry point over shared/pathtrace.h. One work-item per pixel adds the samples
 * [sample_begin, sample_begin + sample_count) to its exact fixed-point accumulator (accum.h:
 * ACCUM_WORDS ulongs per pixel), so long renders run as many short launches (progress, no GPU
 * watchdog) and any split of the samples, in launches or in processes merged afterwards, gives the
 * same bits. -DCOUNTERS adds a last argument: 3 ulongs per pixel (tentative collisions, real
 * collisions, density lookups; kernel_context.h) to which each work-item adds its own pass's
 * counts, no atomics. */
#include "shared/scene_kinds.h"
#include "shared/accum.h"
#include "shared/pathtrace.h"

__kernel void pathtrace(KERNEL_SCENE_ARGS,
                        __global ulong* accum, uint sample_begin,
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
  __global ulong* pixel = accum + ACCUM_WORDS * idx;
  ulong words[ACCUM_WORDS];
  for (int w = 0; w < ACCUM_WORDS; ++w) words[w] = pixel[w];
  for (uint s = 0u; s < sample_count; ++s)
    accum_add_sample(words, pathtrace_sample(KERNEL_ENTRY_ARG(ctx), x, y, sample_begin + s));
  for (int w = 0; w < ACCUM_WORDS; ++w) pixel[w] = words[w];
  if (ctx.status) atomic_or(status_word, ctx.status);
#ifdef COUNTERS
  counter_buf[3 * idx + 0] += ctx.counters.tentative;
  counter_buf[3 * idx + 1] += ctx.counters.real;
  counter_buf[3 * idx + 2] += ctx.counters.lookups;
#endif
}
