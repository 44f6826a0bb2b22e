/* ms_cache.h: the multiple-scattering cache of the ray marcher (DESIGN.md "Real-time caches").
 * The radiance arriving at a point x splits into the unscattered light of the scene's lights,
 * which the ray marcher integrates itself with the phase function (raymarch_light_sum, through the
 * light-transmittance cache), and the rest: light scattered at least once, and the background
 * seen through the medium. The rest varies slowly in space and direction; this cache holds its
 * directional average per node of a grid over the medium's box (node_grid.h):
 *   R(x) = (1/4π) ∫ L_rest(x, ω) dω,
 * estimated by the path tracer's own code (pathtrace_radiance with the first segment's emitter
 * left out) from paths started at the node in directions uniform on the sphere (pdf 1/4π, so one
 * path's radiance is an unbiased estimate of R). The march then adds σs(x)·R(x) to its source
 * term inside the energy-conserving step: for an isotropic phase function the in-scattered
 * radiance of the rest is exactly σs·R (p = 1/4π against the average), so ray marching plus the
 * cache solves the transport exactly up to the cache's resolution, its noise and the march's
 * quadrature; for HG it is the zeroth moment of the in-scattering (an approximation).
 *
 * Bounces: the march's sample is the first scattering, so the cache's paths take one bounce
 * fewer than the scene's (the host hands the build a scene with max_bounces − 1): ray marching
 * plus the cache then counts the events the path tracer does.
 *
 * Storage: one float4 per node, xyz the running mean of the paths so far, w their count; each
 * build launch adds `paths` paths per node (progressive: a viewer refines it over frames), path k
 * of node n drawing its random numbers from its own counter-based stream (seed, n, k), so the
 * cache after K paths is the same whatever the launches it was split into (ms_cache_build.h). */
#ifndef NARVAL_MS_CACHE_H
#define NARVAL_MS_CACHE_H

#include "shared/node_grid.h"

/* R at index-space point p (inside the box [0, dims]): trilinear over the nodes' means. */
static inline vec3 ms_cache_lookup(NV_CONSTANT const node_grid_params* c, NV_GLOBAL const float* cache, vec3 dims,
                                   vec3 p) {
  const node_grid_cell cell = node_grid_locate(c, dims, p);
  return vec3_make(node_grid_interpolate(c, cache, 4, cell), node_grid_interpolate(c, cache + 1, 4, cell),
                   node_grid_interpolate(c, cache + 2, 4, cell));
}

#endif
