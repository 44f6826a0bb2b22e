/* ms_cache.h: the multiple-scattering cache of the ray marcher (DESIGN.md "Real-time caches").
 * The radiance arriving at a point x splits into the unscattered light of the scene's lights,
 * which the ray marcher integrates itself with the phase function (raymarch_light_sum, through the
 * light-transmittance cache), and the rest: light scattered at least once, and the background
 * seen through the medium. The rest varies slowly in space and direction; this cache holds its
 * directional average (and first moment, below) per node of a grid over the medium's box
 * (node_grid.h):
 *   R(x) = (1/4π) ∫ L_rest(x, ω) dω,
 * estimated by the path tracer's own code (pathtrace_radiance with the first segment's emitter
 * left out) from paths started at the node in directions uniform on the sphere (pdf 1/4π, so one
 * path's radiance is an unbiased estimate of R). The march then adds σs(x)·R(x) to its source
 * term inside the energy-conserving step: for an isotropic phase function the in-scattered
 * radiance of the rest is exactly σs·R (p = 1/4π against the average), so ray marching plus the
 * cache solves the transport exactly up to the cache's resolution, its noise and the march's
 * quadrature; for HG it keeps the first two moments of the in-scattering (an approximation).
 *
 * Bounces: the march's sample is the first scattering, so the cache's paths take one bounce
 * fewer than the scene's (the host hands the build a scene with max_bounces − 1): ray marching
 * plus the cache then counts the events the path tracer does.
 *
 * First moment (for HG): with L(w) ≈ a + b·w over the light's propagation directions w, the
 * in-scattering towards w_out is ∫ p(w·w_out) L(w) dw = a + g·(b·w_out), since HG's first zonal
 * coefficient is g (∫ p(w·w_out) w dw = g·w_out); a = R and b = (3/4π)∫ L(w) w dw, whose one-path
 * estimate for a path looking along ω (light propagating along w = −ω, pdf 1/4π) is −3·L·ω. The
 * lookup clamps a + g·(b·w_out) at 0 per channel (a truncated expansion can dip below). For an
 * isotropic phase function g = 0 and only R counts.
 *
 * Storage: MS_CACHE_STRIDE floats per node: the running means of the paths so far, R (rgb) then
 * their count, then b for red, green and blue (xyz each, then an unused float); each build launch
 * adds `paths` paths per node (progressive: a viewer refines it over frames), path k of node n
 * drawing its random numbers from its own counter-based stream (seed, n, k), so the cache after K
 * paths is the same whatever the launches it was split into (ms_cache_build.h). */
#ifndef NARVAL_MS_CACHE_H
#define NARVAL_MS_CACHE_H

#include "shared/node_grid.h"

#define MS_CACHE_STRIDE 16

/* The in-scattered radiance of the rest at index-space point p (inside the box [0, dims]) towards
 * w_out (the propagation direction after scattering), per unit σs: R + g·(b·w_out), trilinear over
 * the nodes, at least 0. */
static inline vec3 ms_cache_lookup(NV_CONSTANT const node_grid_params* c, NV_GLOBAL const float* cache, vec3 dims,
                                   vec3 p, float g, vec3 w_out) {
  const node_grid_cell cell = node_grid_locate(c, dims, p);
  float out[3];
  for (int ch = 0; ch < 3; ++ch) {
    float v = node_grid_interpolate(c, cache + ch, MS_CACHE_STRIDE, cell);
    if (g != 0.0f) {
      NV_GLOBAL const float* b = cache + 4 + 4 * ch;
      const vec3 moment = vec3_make(node_grid_interpolate(c, b, MS_CACHE_STRIDE, cell),
                                    node_grid_interpolate(c, b + 1, MS_CACHE_STRIDE, cell),
                                    node_grid_interpolate(c, b + 2, MS_CACHE_STRIDE, cell));
      v = nv_fmax(0.0f, v + g * vec3_dot(moment, w_out));
    }
    out[ch] = v;
  }
  return vec3_make(out[0], out[1], out[2]);
}

#endif
