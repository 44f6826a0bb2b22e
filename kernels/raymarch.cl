/* raymarch.cl: thin entry point over shared/raymarch.h. One work-item per pixel writes (L, 0); the
 * global size is padded to a multiple of the work-group size, so items past the image return.
 * light_cache_nodes and ms_cache_nodes hold the light-transmittance and multiple-scattering caches
 * (a one-float placeholder when off). */
#include "shared/scene_kinds.h"
#include "shared/raymarch.h"

__kernel void raymarch(KERNEL_SCENE_ARGS, march_params march, node_grid_params light_cache,
                       ms_cache_params ms_cache, __global const float* light_cache_nodes,
                       __global const float* ms_cache_nodes, __global float4* out, __global uint* status_word) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= scene->camera.width || y >= scene->camera.height) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | march_kinds_status(&march) |
               ms_cache_kinds_status(&ms_cache); /* unknown kinds */
  const vec3 L = raymarch_pixel(KERNEL_ENTRY_ARG(ctx), &march, &light_cache, &ms_cache, light_cache_nodes,
                                ms_cache_nodes, x, y);
  out[y * scene->camera.width + x] = (float4)(L.x, L.y, L.z, 0.0f);
  if (ctx.status) atomic_or(status_word, ctx.status);
}
