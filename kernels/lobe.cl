/* lobe.cl: thin entry point over shared/lobe.h (Lobe Estimator, DESIGN.md "lobe"). One work-item
 * per pixel, one deterministic estimate through the pixel centre; the global size is padded to a
 * multiple of the local size, so work-items past the image return at once. light_cache_nodes holds
 * the light-transmittance cache (a one-float placeholder when it is off). */
#include "shared/scene_kinds.h"
#include "shared/lobe.h"

__kernel void lobe(KERNEL_SCENE_ARGS, march_params march, lobe_params lobe, node_grid_params light_cache,
                   __global const float4* lobe_directions, __global const float* light_cache_nodes,
                   __global float4* out, __global uint* status_word) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= scene->camera.width || y >= scene->camera.height) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | march_kinds_status(&march) |
               lobe_kinds_status(&lobe); /* unknown kinds */
  /* float4 and nv_float4 hold the same four floats (structs.h). */
  const vec3 L =
      lobe_pixel(KERNEL_ENTRY_ARG(ctx), &march, &lobe, &light_cache, (__global const nv_float4*)lobe_directions,
                 light_cache_nodes, x, y);
  out[y * scene->camera.width + x] = (float4)(L.x, L.y, L.z, 0.0f);
  if (ctx.status) atomic_or(status_word, ctx.status);
}
