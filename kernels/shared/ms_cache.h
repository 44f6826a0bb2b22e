/* ms_cache.h: the ray marcher's multiple-scattering cache (DESIGN.md "Real-time caches"). The radiance
 * arriving at x is the lights' unscattered light, which the march integrates itself with the phase
 * function (march_light_sum, through the light-transmittance cache), plus the rest: light scattered at
 * least once, and the background seen through the medium. The rest varies slowly in space and direction,
 * so this cache holds its directional average (and first moment, below) per node of a grid over the box
 * (node_grid.h),
 *   R(x) = (1/4π) ∫ L_rest(x, ω) dω,
 * estimated by the path tracer's own code (pathtrace_radiance without the first segment's emitter) from
 * paths leaving the node uniformly on the sphere (pdf 1/4π: one path's radiance is an unbiased estimate
 * of R). The march adds σs(x)·R(x) to its source term in the energy-conserving step: exactly the rest's
 * in-scattering for an isotropic phase function (p = 1/4π against the average), so march plus cache are
 * exact up to the cache's resolution and noise and the march's quadrature; for HG, its first two moments
 * (an approximation).
 *
 * Bounces: the march's sample is the first scattering, so the cache's paths take one bounce fewer (the
 * host builds with max_bounces − 1): march plus cache count the path tracer's events.
 *
 * First moment (for HG): with L(w) ≈ a + b·w over the light's propagation directions w, the in-scattering
 * towards w_out is ∫ p(w·w_out) L(w) dw = a + g·(b·w_out), since HG's first zonal coefficient is g
 * (∫ p(w·w_out) w dw = g·w_out); a = R and b = (3/4π)∫ L(w) w dw, whose one-path estimate for a path
 * looking along ω (light propagating along w = −ω, pdf 1/4π) is −3·L·ω.
 *
 * Closure (ms_cache_params.closure): what the two moments say about the in-scattering in a direction;
 * with g = 0 only R counts. MS_CACHE_CLOSURE_LINEAR: the expansion above, clamped at 0 per channel (a
 * truncation can dip below); exact for a field linear in w, but a field concentrated along its mean
 * direction (dense clouds at g 0.8–0.9, light scattered forwards a few times) has |b|/R near its bound 3,
 * so 1 − g·|b|/R ≈ 0 backwards (where front-lit clouds are seen from) and at most 1 + 3g forwards.
 * (An HG lobe of the same R and b, which convolves with an HG phase function in closed form, was a
 * closure too, removed when it did not win on enough scenes: bench/RESULTS.md.)
 * MS_CACHE_CLOSURE_CAMERA needs none: a node's paths draw their directions from the phase function about
 * w_c, the direction to the camera, so their mean radiance is the in-scattering towards the camera,
 * ∫ p(w·w_c) L(w) dw (importance sampled: p/pdf = 1). It is exact in direction up to w_c being the
 * node's, not the sample's (degrees apart with the camera far from the box), the uniform estimator for an
 * isotropic phase function, and depends on the camera: the host starts the cache over when it moves
 * (host/render/device_ms_cache.cpp).
 *
 * Interpolation: R is mixed as exp(Σ w_k ln R_k), w_k the trilinear weights, and b/R linearly. In a
 * dense medium radiance falls off exponentially with depth (a mean free path can be a fraction of a
 * cell), and a linear mix of a lit node and one many mean free paths deeper paints the deeper one
 * bright, in cell-shaped blocks (bench/RESULTS.md); the geometric mean is exact for an exponential
 * along each axis, keeps equal corners' value (the white furnace stays 1) and errs, like trilinear, at
 * second order in the node spacing. A node at 0 would pull the whole cell to 0, so R + floor is mixed,
 * floor = MS_CACHE_LOG_FLOOR × the cell's largest R, and taken off after. A linear mix of R and b, exact
 * for a field linear along each axis (which the geometric mean undershoots: the AM–GM inequality), was
 * an option too, removed when it did not win on enough scenes (bench/RESULTS.md).
 *
 * Direct (ms_cache_params.direct; closure camera or the view layout only): a node holds the whole
 * in-scattering towards the camera, unscattered light included, so the march has no light loop (no shadow
 * rays, no light cache: one lookup per sample). Each path's start is a scattering event of a camera path
 * arriving along −w_c, handled as in a path-traced pixel: the next-event estimate (pathtrace_direct:
 * ratio-tracked shadow rays, point lights included) and the emitter its first segment meets, weighted
 * against it by MIS (pathtrace_radiance's first_phase_pdf). The shadow then follows the phase's peak
 * wherever it points (back-lit clouds: march.h, march_light_column_phase), at the path tracer's variance
 * and more build time (bench/RESULTS.md).
 *
 * Storage: MS_CACHE_STRIDE floats per node. The running means of the paths so far: R (rgb), their count,
 * then b per channel (xyz, then a float: after green's MS_CACHE_SQUARE for the view filter's noise;
 * ms_cache_view.h; the view layout holds its turn where red's b is, and no b). Then, written by the
 * build after each launch so that a lookup (one per march sample) takes no logarithm or division per
 * corner: ln R (MS_CACHE_LOG_R) and b/R (MS_CACHE_RATIO; the grid layout only). Each launch
 * adds `paths` paths per node (progressive: a viewer refines it over frames), path k of node n drawing
 * from its own stream (seed, n, k) and Sobol index k, so the cache after K paths is the same whatever
 * launches it was split into (ms_cache_build.h). */
#ifndef NARVAL_MS_CACHE_H
#define NARVAL_MS_CACHE_H

#include "shared/node_grid.h"

#define MS_CACHE_STRIDE 32
#define MS_CACHE_SQUARE 11 /* the running mean of ((L_r + L_g + L_b)/3)² (ms_cache_filter.h) */
#define MS_CACHE_LOG_R 16 /* ln R per channel (−∞ where R = 0), written by the build */
#define MS_CACHE_RATIO 20 /* b/R per channel (xyz each; 0 where R = 0), written by the build */
/* The geometric mix's floor, a fraction of the cell's largest R ("Interpolation"). */
#define MS_CACHE_LOG_FLOOR 1e-4f

/* R·(the closure's factor) towards w_out for the moment per unit R, m = b/R ("Closure"). */
static inline float ms_cache_closure(int closure, float R, float g, vec3 m, vec3 w_out) {
  switch (closure) {
    case MS_CACHE_CLOSURE_LINEAR: return nv_fmax(0.0f, R * (1.0f + g * vec3_dot(m, w_out)));
    case MS_CACHE_CLOSURE_CAMERA: return R; /* the node's R is the in-scattering towards the camera */
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
}

/* Node `node`'s first moment b of channel ch, from its running means ("Storage"). */
static inline vec3 ms_cache_node_moment(NV_GLOBAL const float* node, int ch) {
  return vec3_make(node[4 + 4 * ch], node[5 + 4 * ch], node[6 + 4 * ch]);
}

/* Channel ch's R mixed geometrically over corners at[] with trilinear weights w[] ("Interpolation"),
 * and b/R linearly into *ratio (read only when want_ratio): from the stored ln R and b/R when every
 * corner has R > 0, else from the running means with R + floor. */
static inline float ms_cache_mix_geometric(NV_GLOBAL const float* cache, NV_PRIVATE const size_t* at,
                                           NV_PRIVATE const float* w, int ch, int want_ratio,
                                           NV_PRIVATE vec3* ratio) {
  int all_lit = 1;
  for (int k = 0; k < 8; ++k) all_lit &= cache[at[k] + MS_CACHE_LOG_R + (size_t)ch] > -NV_INFINITY;
  float log_r = 0.0f, floor = 0.0f;
  if (all_lit) {
    for (int k = 0; k < 8; ++k) {
      log_r += w[k] * cache[at[k] + MS_CACHE_LOG_R + (size_t)ch];
      if (want_ratio) {
        NV_GLOBAL const float* q = cache + at[k] + MS_CACHE_RATIO + 3 * ch;
        *ratio = vec3_add(*ratio, vec3_scale(vec3_make(q[0], q[1], q[2]), w[k]));
      }
    }
  } else {
    float top = 0.0f;
    for (int k = 0; k < 8; ++k) top = nv_fmax(top, cache[at[k] + (size_t)ch]);
    if (!(top > 0.0f)) return 0.0f;
    floor = MS_CACHE_LOG_FLOOR * top;
    for (int k = 0; k < 8; ++k) {
      NV_GLOBAL const float* node = cache + at[k];
      const float r = nv_fmax(node[ch], 0.0f) + floor;
      log_r += w[k] * nv_log(r);
      *ratio = vec3_add(*ratio, vec3_scale(ms_cache_node_moment(node, ch), w[k] / r));
    }
  }
  return nv_fmax(nv_exp(log_r) - floor, 0.0f);
}

/* The rest's in-scattered radiance per unit σs at index-space point p (in [0, dims]) towards w_out
 * (propagation after scattering): R mixed over the cell's eight nodes, times the closure's factor. */
static inline vec3 ms_cache_lookup(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* cache, vec3 dims,
                                   vec3 p, float g, int closure, vec3 w_out) {
  float w[8];
  size_t at[8];
  node_grid_corners(c, node_grid_locate(c, dims, p), MS_CACHE_STRIDE, at, w);
  float out[3];
  const int want_ratio = g != 0.0f && closure != MS_CACHE_CLOSURE_CAMERA; /* b/R read only for a closure */
  for (int ch = 0; ch < 3; ++ch) {
    vec3 ratio = vec3_splat(0.0f);
    const float R = ms_cache_mix_geometric(cache, at, w, ch, want_ratio, &ratio);
    out[ch] = g != 0.0f ? ms_cache_closure(closure, R, g, ratio, w_out) : R;
  }
  return vec3_make(out[0], out[1], out[2]);
}

#endif
