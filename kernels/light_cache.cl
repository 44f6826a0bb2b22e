/* light_cache.cl: builds one light's slab of the light-transmittance cache (shared/light_cache.h).
 * One work-item per node (1D, padded to a multiple of the local size; items past the slab return).
 * `light` selects the light and its slab, so a light that changed is rebuilt alone. */
#include "shared/scene_kinds.h"
#include "shared/light_cache.h"

__kernel void light_cache_build(KERNEL_SCENE_ARGS,
                                __constant realtime_params* params, int light, __global float* cache,
                                __global uint* status_word) {
  const int node = get_global_id(0);
  __constant node_grid_params* c = &params->light_cache;
  const int nodes = node_grid_count(c);
  if (node >= nodes) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights); /* unknown kinds: STATUS_UNKNOWN_KIND */
  cache[(size_t)light * (size_t)nodes + (size_t)node] = light_cache_build_node(
      KERNEL_ENTRY_ARG(ctx), c, params->shadow_steps, params->shadow_area_samples, params->shadow_weighting,
      &lights[light], node);
  if (ctx.status) atomic_or(status_word, ctx.status);
}
