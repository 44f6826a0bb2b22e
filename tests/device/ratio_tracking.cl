/* Test kernel: ratio-tracking transmittance along world-space rays through the medium, n samples
 * per ray, returning the mean and the sample variance of the red channel. */
#include "shared/medium.h"
#include "shared/tracking.h"

/* The medium's context: the grid in the context, or (image storage) beside it. */
#if GRID_STORAGE_IN_CONTEXT
#define TEST_CONTEXT(ctx)                                   \
  kernel_context ctx = kernel_context_of_medium(m, grid_majorants); \
  ctx.grid = grid
#define TEST_ARG(ctx) &ctx
#else
#define TEST_CONTEXT(ctx) kernel_context ctx = kernel_context_of_medium(m, grid_majorants)
#define TEST_ARG(ctx) &ctx, grid, grid
#endif

__kernel void ratio_tracking_stats(__constant medium_params* m, GRID_STORAGE grid, __global const float* grid_majorants,
                                   __global const float4* rays,
                                   uint n, __global float* out_mean, __global float* out_var,
                                   __global uint* status_word) {
  const int i = get_global_id(0);
  const vec3 o = rays[2 * i].xyz;
  const vec3 d = rays[2 * i + 1].xyz;
  TEST_CONTEXT(ctx);
  medium_segment seg;
  float mean = 0.0f, m2 = 0.0f;
  if (medium_intersect(m, o, d, 0.0f, NV_INFINITY, &seg)) {
    for (uint s = 0u; s < n; ++s) {
      rng_state rng = rng_init(1234u, (uint)i, s);
      const float tr = tracking_ratio(TEST_ARG(ctx), seg.o, seg.d, seg.t0, seg.t1, 0.0f, &rng).x;
      /* Welford's running mean and variance */
      const float delta = tr - mean;
      mean += delta / (float)(s + 1u);
      m2 += delta * (tr - mean);
    }
  } else {
    mean = 1.0f;
  }
  out_mean[i] = mean;
  out_var[i] = n > 1u ? m2 / (float)(n - 1u) : 0.0f;
  if (ctx.status) atomic_or(status_word, ctx.status);
}

/* Delta tracking on the same rays: the fraction of n walks (absorption-only view: any real
 * collision ends the walk) that escape the box, the free-flight estimate of the transmittance. */
__kernel void delta_escape_fraction(__constant medium_params* m, GRID_STORAGE grid,
                                    __global const float* grid_majorants,
                                    __global const float4* rays,
                                    uint n, __global float* out_fraction, __global uint* status_word) {
  const int i = get_global_id(0);
  const vec3 o = rays[2 * i].xyz;
  const vec3 d = rays[2 * i + 1].xyz;
  TEST_CONTEXT(ctx);
  medium_segment seg;
  uint escaped = n;
  if (medium_intersect(m, o, d, 0.0f, NV_INFINITY, &seg)) {
    escaped = 0u;
    for (uint s = 0u; s < n; ++s) {
      rng_state rng = rng_init(4321u, (uint)i, s);
      vec3 beta = vec3_splat(1.0f);
      float t_hit;
      escaped += tracking_delta(TEST_ARG(ctx), seg.o, seg.d, seg.t0, seg.t1, &rng, &beta, &t_hit) == TRACK_ESCAPED;
    }
  }
  out_fraction[i] = (float)escaped / (float)n;
  if (ctx.status) atomic_or(status_word, ctx.status);
}
