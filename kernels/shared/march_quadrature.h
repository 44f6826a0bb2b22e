/* march_quadrature.h: the real-time kernels' deterministic quadrature along a ray: the energy-conserving
 * step, midpoint samples over a segment's occupied cells (majorant_dda.h DDA), and the optical depth and
 * column density of march.h, the light caches and light_rectangle_area.h. Steps keep their true length (DESIGN.md). */
#ifndef NARVAL_MARCH_QUADRATURE_H
#define NARVAL_MARCH_QUADRATURE_H

#include "shared/grid.h"
#include "shared/majorant_dda.h"
#include "shared/medium.h"

/* σt at world point o + t·d of a medium segment (index-space origin and direction in `seg`). */
static inline vec3 march_sigma_t(KERNEL_CONTEXT_PARAM, NV_PRIVATE const medium_segment* seg,
                                 float t) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  const float rho = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, t));
  return vec3_scale(medium_sigma_t(m), rho);
}

/* Below this optical depth per step, (1 − e^{−x})/x is evaluated by its Taylor series: the direct
 * form loses |rounding of e^{−x}|/x to cancellation (≤ 3 ulp·2⁻²³/x ≈ 4e-6 relative at x = 0.1,
 * less above), the series 1 − x/2 + x²/6 − x³/24 + x⁴/120 is off by ≤ x⁵/720 ≈ 1.4e-8 below it, and
 * at x = 0 (σt = 0) it is exactly 1, so the step integral is exactly S·Δ, never 0/0. */
#define MARCH_SERIES_MAX 0.1f

/* (1 − e^{−x})/x for x ≥ 0, given e = e^{−x}: the step integral's weight (below). */
static inline float march_step_weight(float x, float e) {
  if (x < MARCH_SERIES_MAX)
    return 1.0f - x * (0.5f - x * (1.0f / 6.0f - x * (1.0f / 24.0f - x * (1.0f / 120.0f))));
  return (1.0f - e) / x;
}

/* One view-march step (Hillaire 2015's energy-conserving integration): with the source S (radiance
 * per unit length) and σt constant over a step Δ it adds ∫_0^Δ S e^{−σt s} ds = (S − S·e^{−σtΔ})/σt
 * = S·Δ·march_step_weight(σtΔ), seen through the *T before the step, which then falls by e^{−σtΔ}. */
static inline void march_energy_conserving_step(NV_PRIVATE vec3* L, NV_PRIVATE vec3* T, vec3 S, vec3 sigma_t, float dt) {
  const vec3 x = vec3_scale(sigma_t, dt);
  const vec3 e = vec3_exp_neg(x);
  const vec3 w = vec3_make(march_step_weight(x.x, e.x), march_step_weight(x.y, e.y), march_step_weight(x.z, e.z));
  *L = vec3_add(*L, vec3_mul(*T, vec3_scale(vec3_mul(S, w), dt)));
  *T = vec3_mul(*T, e);
}

/* Midpoint samples over the occupied part of a segment: `steps` samples at compressed positions
 * (k + 0.5)·Δ, Δ = occupied length / steps, mapped back to t through the occupied cells in order.
 * With one cell (a homogeneous medium) this is exactly t0 + (k + 0.5)·(t1 − t0)/steps. */
typedef struct march_iter {
  majorant_iter dda;
  float a, b;     /* current occupied piece [a, b] */
  float s_a;      /* compressed position of a */
  float delta;    /* step length, world units */
  float majorant; /* the current piece's majorant density (1 for a whole segment) */
  int k, steps;
  int whole;      /* no majorant grid (host without bounds): the segment is one piece */
  uint status;    /* the first walk's DDA status (majorant_iter.status); callers OR it into theirs.
                     The second walk repeats the first and ends no later, so it adds nothing. */
} march_iter;

/* Next occupied piece of the walk into [*a, *b]; 0 when none is left. */
static inline int march_next_piece(NV_PRIVATE march_iter* it, KERNEL_CONTEXT_PARAM, NV_PRIVATE float* a,
                                   NV_PRIVATE float* b) {
  if (it->whole) {
    if (!(it->dda.t < it->dda.t_end)) return 0;
    *a = it->dda.t;
    *b = it->dda.t_end;
    it->dda.t = it->dda.t_end;
    it->majorant = 1.0f;
    return 1;
  }
  while (majorant_iter_next(&it->dda, GRID_MAJORANTS, a, b, &it->majorant))
    if (it->majorant > 0.0f) return 1;
  return 0;
}

static inline march_iter march_begin(KERNEL_CONTEXT_PARAM,
                                     NV_PRIVATE const medium_segment* seg, int steps) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  march_iter it;
  it.whole = GRID_MAJORANTS == 0;
  it.dda = majorant_iter_begin(m->majorant_grid, seg->o, seg->d, seg->t0, seg->t1);
  if (it.whole) {
    it.dda.t = seg->t0;
    it.dda.t_end = seg->t1;
  }
  /* First walk: the occupied length. */
  march_iter probe = it;
  float a, b, len = 0.0f;
  while (march_next_piece(&probe, KERNEL_CONTEXT_ARG, &a, &b)) len += b - a;
  it.status = probe.dda.status;
  it.a = it.b = it.s_a = it.majorant = 0.0f;
  it.steps = steps > 0 ? steps : 1;
  it.delta = len / (float)it.steps;
  it.k = 0;
  return it;
}

/* The next sample's t (each sample stands for it->delta of path); 0 when all are placed. */
static inline int march_next(NV_PRIVATE march_iter* it, KERNEL_CONTEXT_PARAM, NV_PRIVATE float* t) {
  if (it->k >= it->steps || !(it->delta > 0.0f)) return 0;
  const float s = ((float)it->k + 0.5f) * it->delta;
  while (!(s < it->s_a + (it->b - it->a))) {
    float a, b;
    it->s_a += it->b - it->a;
    if (!march_next_piece(it, KERNEL_CONTEXT_ARG, &a, &b)) return 0;
    it->a = a;
    it->b = b;
  }
  *t = it->a + (s - it->s_a);
  it->k += 1;
  return 1;
}

/* The part of the ray origin + t·dir, t in [0, dist], inside the medium's box, into *seg; 0 when
 * there is none. A NaN ray misses every box: it is flagged rather than passed off as clear air. */
static inline int march_clip(NV_CONSTANT const medium_params* m, vec3 origin, vec3 dir, float dist,
                             NV_PRIVATE medium_segment* seg, NV_PRIVATE uint* status) {
  if (medium_intersect(m, origin, dir, 0.0f, dist, seg)) return 1;
  if (!(vec3_is_finite(origin) && vec3_is_finite(dir) && dist == dist)) *status |= STATUS_NAN;
  return 0;
}

/* Optical depth τ from `origin` over `dist` along unit `dir`: Σ σt·Δ over `steps` midpoint samples of
 * the occupied part inside the box; 0 outside. The ray marcher's octaves need τ itself (exp(−bⁱτ)),
 * which survives where exp(−τ) underflows. Status bits go to *status; a NaN density stays in τ for the
 * caller's pixel check. Stops once every channel's partial τ exceeds tau_limit (NV_INFINITY: never,
 * the full sum bit for bit): a view transmittance already below e^{−tau_limit} can only fall, so the
 * result lies between the true value and that (lobe.h derives what this costs a pixel). */
static inline vec3 march_optical_depth_limited(KERNEL_CONTEXT_PARAM, vec3 origin, vec3 dir,
                                               float dist, int steps, float tau_limit) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  medium_segment seg;
  if (!march_clip(m, origin, dir, dist, &seg, status)) return vec3_splat(0.0f);
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, &seg, steps);
  const float sum_limit = tau_limit / it.delta; /* on Σσt, before the scaling by Δ */
  vec3 tau = vec3_splat(0.0f);
  float t;
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    tau = vec3_add(tau, march_sigma_t(KERNEL_CONTEXT_ARG, &seg, t));
    if (nv_fmin(tau.x, nv_fmin(tau.y, tau.z)) > sum_limit) break;
  }
  *status |= it.status;
  return vec3_scale(tau, it.delta);
}

static inline vec3 march_optical_depth(KERNEL_CONTEXT_PARAM, vec3 origin, vec3 dir,
                                       float dist, int steps) {
  return march_optical_depth_limited(KERNEL_CONTEXT_ARG, origin, dir, dist, steps, NV_INFINITY);
}

/* Transmittance exp(−τ) over the same quadrature (1 outside the box). */
static inline vec3 march_transmittance(KERNEL_CONTEXT_PARAM, vec3 origin, vec3 dir,
                                       float dist, int steps) {
  return vec3_exp_neg(march_optical_depth(KERNEL_CONTEXT_ARG, origin, dir, dist, steps));
}

/* Column density ∫ρ ds by march_optical_depth's quadrature (Σ ρ·Δ): σt = σt_unit·ρ, so
 * τ = σt_unit·column in every channel at once; the light cache (light_cache.h) stores it per node. */
static inline float march_column_density(KERNEL_CONTEXT_PARAM, vec3 origin, vec3 dir,
                                         float dist, int steps) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  medium_segment seg;
  if (!march_clip(m, origin, dir, dist, &seg, status)) return 0.0f;
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, &seg, steps);
  float column = 0.0f, t;
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t))
    column += grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg.o, seg.d, t));
  *status |= it.status;
  return column * it.delta;
}

#endif
