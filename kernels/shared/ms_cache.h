/* ms_cache.h: the multiple-scattering cache of the ray marcher (DESIGN.md "Real-time caches").
 * The radiance arriving at a point x splits into the unscattered light of the scene's lights,
 * which the ray marcher integrates itself with the phase function (march_light_sum, through the
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
 * Closure (ms_cache_params.closure): what the two moments say about the
 * in-scattering in a direction. MS_CACHE_CLOSURE_LINEAR is the truncated expansion above,
 * R·(1 + g·(b/R)·w_out) clamped at 0. It is exact for a field linear in w, but a field concentrated
 * along its mean direction, as dense clouds at g 0.8–0.9 hold (light scattered forwards a few
 * times), has |b|/R near its bound 3 and the expansion sends 1 − g·|b|/R ≈ 0 backwards (where
 * front-lit clouds are seen from) and at most 1 + 3g forwards. MS_CACHE_CLOSURE_HG takes the field
 * of the same R and b that is an HG lobe about b: L(w) = 4πR·p_HG(μ, w·b̂) with mean cosine
 * μ = |b|/(3R) (then (3/4π)∫L w dw = 3Rμ·b̂ = b). HG lobes convolve exactly, their Legendre
 * coefficients multiplying (gˡ·μˡ = (gμ)ˡ), so the in-scattering is again an HG lobe, of g·μ:
 *   ∫ p_HG(g, w·w_out) L(w) dw = 4πR·p_HG(gμ, b̂·w_out) = R·(1 − k²)/(1 + k² − 2k·b̂·w_out)^{3/2},  k = gμ,
 * positive in every direction, equal to the linear closure to first order in μ, and R for an
 * isotropic field (μ = 0). μ is kept below 0.99 (a noisy b can exceed its bound).
 * Neither is right everywhere: the default cloud's dark front, a broad one-sided field, wants the
 * linear one, its sunlit rim, a field peaked around several directions, more than HG gives.
 * MS_CACHE_CLOSURE_CAMERA asks no closure: each node's paths draw their directions from the phase
 * function about the direction from the node to the camera (w_c), so that their mean radiance
 * estimates the in-scattering towards the camera itself, ∫ p(w·w_c) L(w) dw (importance sampled:
 * the weight p/pdf is 1), which the lookup returns as it is. Exact in direction up to w_c being
 * the node's and not the sample's (the camera far from the box: degrees apart), it is the same
 * estimator as the uniform one for an isotropic phase function, and it depends on where the camera
 * is: the host starts the cache over when the camera moves (host/render/device_ms_cache.cpp).
 *
 * Interpolation: R is interpolated geometrically, exp(Σ w_k ln R_k) with the trilinear weights
 * w_k, and the moment per unit R, b/R, linearly. In a dense medium the radiance falls off
 * exponentially with depth (the Disney cloud at density 10 has a mean free path of a tenth of a
 * cache cell): a linear mix of a lit node and a node ten mean free paths deeper paints the deeper
 * one bright, in blocks the shape of the cells (on the Disney cloud, against the path-traced
 * reference: bench/RESULTS.md); the geometric mean is exact for an exponential along each axis.
 * It keeps every property the tests check: equal corners give that value, so the white furnace
 * stays 1, and for a smooth field it errs, like trilinear, at second order in the node spacing.
 * A node at 0 would pull the whole cell to 0, so R + floor is interpolated instead, floor =
 * MS_CACHE_LOG_FLOOR × the cell's largest R, and floor taken off after.
 * MS_CACHE_INTERPOLATION_LINEAR (ms_cache_params.interpolation) mixes R and b linearly
 * instead (b/R = Σ w_k b_k / Σ w_k R_k): exact for a field linear along each axis, where the
 * geometric mean falls short of it (by the AM–GM inequality: 6% at the middle of two nodes a factor
 * 2 apart). Which is nearer depends on the medium (bench/RESULTS.md): the default cloud, where the
 * camera-aimed cache varies gently, reads dark throughout with the geometric mean and nearer with
 * the linear one; the back-lit Disney cloud paints blocks with the linear one.
 *
 * Direct (ms_cache_params.direct; closure camera or the view layout only): a node holds
 * the whole in-scattering towards the camera, the lights' unscattered light included, and the march
 * makes no light loop (no shadow rays, no light cache): a frame is the view march and one lookup per
 * sample. Each path treats its start as a scattering event of a camera path arriving along −w_c:
 * the path tracer's next-event estimate there (pathtrace_direct: shadow rays by ratio tracking,
 * point lights included), and the emitter its first segment meets weighted against it by MIS
 * (pathtrace_radiance's first_phase_pdf), as at any event of a path-traced pixel. So the shadow
 * follows the phase's peak wherever it points (a cloud lit from behind: march.h,
 * march_light_column_phase) at the cost of the path tracer's variance. On the back-lit Disney
 * cloud two cache seeds agree better with the next-event estimate than with the phase sampling
 * alone, for more build time (bench/RESULTS.md).
 *
 * Guide (ms_cache_params.guide; closure camera or the view layout only): a share of each
 * path's first directions is drawn from HG lobes about the directions to the lights instead of
 * from the phase function about −w_c (phase_guide.h), the path weighted by phase/mixture density
 * and both MIS weights at its start using the mixture's density: the node's expectation is the
 * same. Where a cloud is lit from the camera's side, the light a node sends towards the camera
 * arrives mostly from the lights' side, which the phase function about −w_c points away from.
 * At share 0.15 and lobes of g 0.6 it lowers the relMSE between two cache seeds most on the
 * front-lit Disney cloud (filtered too, at the same build time), a little on the back-lit one and
 * the default cloud (bench/RESULTS.md).
 *
 * Storage: MS_CACHE_STRIDE floats per node: the running means of the paths so far, R (rgb) then
 * their count, then b for red, green and blue (xyz each, then a float: after red's the view layout's
 * budget, after green's the mean of the grey L², MS_CACHE_SQUARE, for the view filter's noise, after
 * blue's the view column's background, ms_cache_view.h); then what the
 * lookup reads, derived from them by the build after each launch: ln R (rgb, at MS_CACHE_LOG_R)
 * and b/R (at MS_CACHE_RATIO), so that a lookup takes no logarithm or division per corner (the
 * ray marcher makes one lookup per sample); each build launch
 * adds `paths` paths per node (progressive: a viewer refines it over frames), path k of node n
 * drawing its random numbers from its own counter-based stream (seed, n, k) and its leading
 * coordinates from node n's scrambled Sobol pairs at index k, so the cache after K paths is the same
 * whatever the launches it was split into (ms_cache_build.h). */
#ifndef NARVAL_MS_CACHE_H
#define NARVAL_MS_CACHE_H

#include "shared/node_grid.h"

#define MS_CACHE_STRIDE 32
#define MS_CACHE_SQUARE 11 /* the running mean of ((L_r + L_g + L_b)/3)² (ms_cache_filter.h) */
#define MS_CACHE_LOG_R 16 /* ln R per channel (−∞ where R = 0), written by the build */
#define MS_CACHE_RATIO 20 /* b/R per channel (xyz each; 0 where R = 0), written by the build */
/* Interpolation: log(R + floor), floor this fraction of the cell's largest R (a node at 0 then
 * pulls its neighbours down continuously instead of to 0 at once). */
#define MS_CACHE_LOG_FLOOR 1e-4f

/* R·(the closure's factor) towards w_out for the moment per unit R, m = b/R ("Closure"). */
static inline float ms_cache_closure(int closure, float R, float g, vec3 m, vec3 w_out) {
  switch (closure) {
    case MS_CACHE_CLOSURE_LINEAR: return nv_fmax(0.0f, R * (1.0f + g * vec3_dot(m, w_out)));
    case MS_CACHE_CLOSURE_HG: {
      const float len = vec3_length(m);
      if (!(len > 0.0f)) return R;
      const float k = g * nv_fmin(0.99f, len / 3.0f);
      const float d = 1.0f + k * k - 2.0f * k * (vec3_dot(m, w_out) / len);
      return R * (1.0f - k * k) / (d * nv_sqrt(d));
    }
    case MS_CACHE_CLOSURE_CAMERA: return R; /* the node's R is the in-scattering towards the camera */
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
}

/* Node `node`'s first moment b of channel ch, from its running means ("Storage"). */
static inline vec3 ms_cache_node_moment(NV_GLOBAL const float* node, int ch) {
  return vec3_make(node[4 + 4 * ch], node[5 + 4 * ch], node[6 + 4 * ch]);
}

/* Channel ch's R at the point whose corners and trilinear weights are at[] and w[], mixed
 * geometrically ("Interpolation"), and its moment per unit R mixed linearly (*ratio, read only when
 * want_ratio): from the nodes' ln R and b/R when every corner has R > 0 (the build stores them: no
 * log or division here), else from the running means with R + floor. */
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

/* The same with R and b mixed linearly, b/R = Σ w_k b_k / Σ w_k R_k ("Interpolation"). */
static inline float ms_cache_mix_linear(NV_GLOBAL const float* cache, NV_PRIVATE const size_t* at,
                                        NV_PRIVATE const float* w, int ch, int want_ratio, NV_PRIVATE vec3* ratio) {
  float R = 0.0f;
  for (int k = 0; k < 8; ++k) {
    NV_GLOBAL const float* node = cache + at[k];
    R += w[k] * node[ch];
    if (want_ratio) *ratio = vec3_add(*ratio, vec3_scale(ms_cache_node_moment(node, ch), w[k]));
  }
  R = nv_fmax(R, 0.0f);
  *ratio = R > 0.0f ? vec3_scale(*ratio, 1.0f / R) : vec3_splat(0.0f);
  return R;
}

/* The in-scattered radiance of the rest at index-space point p (inside the box [0, dims]) towards
 * w_out (the propagation direction after scattering), per unit σs: R over the cell's eight nodes
 * ("Interpolation", geometric or linear) times the closure's factor for g and b/R ("Closure"). */
static inline vec3 ms_cache_lookup(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* cache, vec3 dims,
                                   vec3 p, float g, int closure, int interpolation, vec3 w_out) {
  float w[8];
  size_t at[8];
  node_grid_corners(c, node_grid_locate(c, dims, p), MS_CACHE_STRIDE, at, w);
  float out[3];
  const int want_ratio = g != 0.0f && closure != MS_CACHE_CLOSURE_CAMERA; /* b/R read only for a closure */
  for (int ch = 0; ch < 3; ++ch) {
    vec3 ratio = vec3_splat(0.0f);
    float R;
    switch (interpolation) {
      case MS_CACHE_INTERPOLATION_GEOMETRIC: R = ms_cache_mix_geometric(cache, at, w, ch, want_ratio, &ratio); break;
      case MS_CACHE_INTERPOLATION_LINEAR: R = ms_cache_mix_linear(cache, at, w, ch, want_ratio, &ratio); break;
      default: R = 0.0f; break; /* unknown: reported at the kernel's entry */
    }
    out[ch] = g != 0.0f ? ms_cache_closure(closure, R, g, ratio, w_out) : R;
  }
  return vec3_make(out[0], out[1], out[2]);
}

#endif
