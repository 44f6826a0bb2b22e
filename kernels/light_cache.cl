/* light_cache.cl: builds one light's slab of the light-transmittance cache (shared/light_cache.h).
 * One work-item per node (1D, padded to a multiple of the local size; items past the slab return).
 * `light` selects the light and its slab, so a light that changed is rebuilt alone. */
#include "shared/scene_kinds.h"
#include "shared/light_cache.h"

__kernel void light_cache_build(KERNEL_SCENE_ARGS, march_params march, node_grid_params light_cache, int light,
                                __global float* cache, __global uint* status_word) {
  const int node = get_global_id(0);
  const int nodes = node_grid_count(&light_cache);
  if (node >= nodes) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | march_kinds_status(&march); /* STATUS_UNKNOWN_KIND */
  cache[(size_t)light * (size_t)nodes + (size_t)node] =
      light_cache_build_node(KERNEL_ENTRY_ARG(ctx), &light_cache, march.shadow_steps, march.shadow_area_samples,
                             march.shadow_weighting, &lights[light], node);
  if (ctx.status) atomic_or(status_word, ctx.status);
}
