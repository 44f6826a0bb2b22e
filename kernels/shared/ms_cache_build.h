/* ms_cache_build.h: estimating the multiple-scattering cache (ms_cache.h) with the path tracer's
 * own code; kept apart from the lookup so the ray marcher does not compile the path tracer. */
#ifndef NARVAL_MS_CACHE_BUILD_H
#define NARVAL_MS_CACHE_BUILD_H

#include "shared/ms_cache.h"
#include "shared/pathtrace.h"
#include "shared/sampling.h"

/* The stream the cache's paths draw from: the scene's seed offset, so that node n's paths never
 * share the numbers of pixel n's camera samples. */
#define MS_CACHE_SEED_OFFSET 0x6d73u

/* Path k's estimate at node `node`: the radiance of the rest arriving from a uniform direction,
 * and the direction ω it looked along. */
static inline vec3 ms_cache_path(KERNEL_CONTEXT_PARAM,
                                 NV_CONSTANT const node_grid_params* c, int node, uint k, NV_PRIVATE vec3* omega) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE uint* status = &ctx->status;
  const vec3 x = affine_point(c->index_to_world, node_grid_point(c, vec3_from4(s->medium.dims), node));
  rng_state rng = rng_init(s->seed + MS_CACHE_SEED_OFFSET, (uint)node, k);
  const float u1 = rng_uniform(&rng), u2 = rng_uniform(&rng);
  *omega = sample_uniform_sphere(u1, u2);
  const vec3 L = pathtrace_radiance(KERNEL_CONTEXT_ARG, x, *omega, 0, &rng);
  if (!vec3_is_finite(L)) {
    *status |= STATUS_NAN;
    return vec3_splat(0.0f);
  }
  return L;
}

/* Adds paths [first, first + count) to node `node`'s running means (ms_cache.h, "Storage"):
 * v[0..2] R, v[3] the count, v[4 + 4ch .. 6 + 4ch] b of channel ch; then ln R and b/R. */
static inline void ms_cache_refine_node(KERNEL_CONTEXT_PARAM, NV_CONSTANT const node_grid_params* c, int node,
                                        NV_GLOBAL float* v, uint first, uint count) {
  for (uint k = first; k < first + count; ++k) {
    vec3 omega;
    const vec3 L = ms_cache_path(KERNEL_CONTEXT_ARG, c, node, k, &omega);
    const float n = (float)(k + 1u);
    const float Lc[3] = {L.x, L.y, L.z};
    const float w[3] = {-3.0f * omega.x, -3.0f * omega.y, -3.0f * omega.z}; /* 3·w, w = −ω */
    for (int ch = 0; ch < 3; ++ch) {
      v[ch] += (Lc[ch] - v[ch]) / n;
      for (int a = 0; a < 3; ++a) v[4 + 4 * ch + a] += (Lc[ch] * w[a] - v[4 + 4 * ch + a]) / n;
    }
    v[3] = n;
  }
  /* What the lookup reads (ms_cache.h, "Storage"). */
  for (int ch = 0; ch < 3; ++ch) {
    const float R = v[ch];
    v[MS_CACHE_LOG_R + ch] = R > 0.0f ? nv_log(R) : -NV_INFINITY;
    for (int a = 0; a < 3; ++a) v[MS_CACHE_RATIO + 3 * ch + a] = R > 0.0f ? v[4 + 4 * ch + a] / R : 0.0f;
  }
}

#endif
