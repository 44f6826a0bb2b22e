/* raymarch.cl: thin entry point over shared/raymarch.h. One work-item per pixel writes (L, 0); the
 * global size is padded to a multiple of the work-group size, so items past the image return.
 * lobe_directions is part of the signature the real-time kernels share and is not read here;
 * light_cache and ms_cache hold the light-transmittance and multiple-scattering caches (a one-float
 * placeholder when off). */
#include "shared/scene_kinds.h"
#include "shared/raymarch.h"

__kernel void raymarch(KERNEL_SCENE_ARGS,
                       __constant realtime_params* params, __global const float4* lobe_directions,
                       __global const float* light_cache, __global const float* ms_cache, __global float4* out,
                       __global uint* status_word) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= scene->camera.width || y >= scene->camera.height) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | realtime_kinds_status(params); /* unknown kinds */
  const vec3 L = raymarch_pixel(KERNEL_ENTRY_ARG(ctx), params, light_cache, ms_cache, x, y);
  out[y * scene->camera.width + x] = (float4)(L.x, L.y, L.z, 0.0f);
  if (ctx.status) atomic_or(status_word, ctx.status);
}
