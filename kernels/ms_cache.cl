/* ms_cache.cl: adds `count` paths per node to the multiple-scattering cache (shared/ms_cache_build.h),
 * paths [first, first + count) of each node. One work-item per node (1D, padded to a multiple of
 * the local size). `scene` is the scene with one bounce fewer (ms_cache.h, "Bounces"). */
#include "shared/scene_kinds.h"
#include "shared/ms_cache_build.h"

__kernel void ms_cache_build(KERNEL_SCENE_ARGS,
                             __constant realtime_params* params, uint first, uint count, __global float* cache,
                             __global uint* status_word) {
  const int node = get_global_id(0);
  __constant node_grid_params* c = &params->ms_cache;
  if (node >= node_grid_count(c)) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | realtime_kinds_status(params); /* STATUS_UNKNOWN_KIND */
  ms_cache_build_node(KERNEL_ENTRY_ARG(ctx), params, node, cache + (size_t)node * MS_CACHE_STRIDE, first, count);
  if (ctx.status) atomic_or(status_word, ctx.status);
}
