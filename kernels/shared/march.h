/* march.h: deterministic quadrature shared by the real-time kernels (raymarch.cl, lobe.cl).
 * Transmittance by midpoint sampling with true step lengths, all three channels (DESIGN.md:
 * "every step uses its true length"), and lights as points: a rectangle becomes a point at its
 * centre with intensity Le·A·max(0, cos θ_light), the approximation DESIGN.md allows for these
 * kernels (the path tracer always integrates the true area light).
 * Empty space: a march places its samples only in majorant cells whose density bound is above 0
 * (majorant.h DDA), spread evenly over their total length, so time follows the medium, not the box;
 * the skipped cells have density exactly 0 there, so skipping them changes nothing but the spacing. */
#ifndef NARVAL_MARCH_H
#define NARVAL_MARCH_H

#include "shared/grid.h"
#include "shared/majorant.h"
#include "shared/medium.h"

/* σt at world point o + t·d of a medium segment (index-space origin and direction in `seg`). */
static inline vec3 march_sigma_t(NV_CONSTANT const medium_params* m, GRID_PARAM, NV_PRIVATE const medium_segment* seg,
                                 float t) {
  const float rho = grid_density(GRID_ARG, vec3_madd(seg->o, seg->d, t));
  return vec3_scale(vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s)), rho);
}

/* Midpoint samples over the occupied part of a segment: `steps` samples at compressed positions
 * (k + 0.5)·Δ, Δ = occupied length / steps, mapped back to t through the occupied cells in order.
 * With one cell (a homogeneous medium) this is exactly t0 + (k + 0.5)·(t1 − t0)/steps. */
typedef struct march_iter {
  majorant_iter dda;
  float a, b;     /* current occupied piece [a, b] */
  float s_a;      /* compressed position of a */
  float delta;    /* step length, world units */
  int k, steps;
  int whole;      /* no majorant grid (host without bounds): the segment is one piece */
  uint status;    /* the first walk's DDA status (majorant_iter.status); callers OR it into theirs.
                     The second walk repeats the first and ends no later, so it adds nothing. */
} march_iter;

/* Next occupied piece of the walk into [*a, *b]; 0 when none is left. */
static inline int march_next_piece(NV_PRIVATE march_iter* it, GRID_PARAM, NV_PRIVATE float* a, NV_PRIVATE float* b) {
  float mx;
  if (it->whole) {
    if (!(it->dda.t < it->dda.t_end)) return 0;
    *a = it->dda.t;
    *b = it->dda.t_end;
    it->dda.t = it->dda.t_end;
    return 1;
  }
  while (majorant_iter_next(&it->dda, GRID_MAJORANTS, a, b, &mx))
    if (mx > 0.0f) return 1;
  return 0;
}

static inline march_iter march_begin(NV_CONSTANT const medium_params* m, GRID_PARAM,
                                     NV_PRIVATE const medium_segment* seg, int steps) {
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
  while (march_next_piece(&probe, GRID_ARG, &a, &b)) len += b - a;
  it.status = probe.dda.status;
  it.a = it.b = it.s_a = 0.0f;
  it.steps = steps > 0 ? steps : 1;
  it.delta = len / (float)it.steps;
  it.k = 0;
  return it;
}

/* The next sample's t (each sample stands for it->delta of path); 0 when all are placed. */
static inline int march_next(NV_PRIVATE march_iter* it, GRID_PARAM, NV_PRIVATE float* t) {
  if (it->k >= it->steps || !(it->delta > 0.0f)) return 0;
  const float s = ((float)it->k + 0.5f) * it->delta;
  while (!(s < it->s_a + (it->b - it->a))) {
    float a, b;
    it->s_a += it->b - it->a;
    if (!march_next_piece(it, GRID_ARG, &a, &b)) return 0;
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

/* Optical depth τ from `origin` over `dist` along unit `dir`: `steps` midpoint samples over the
 * occupied part of the segment inside the box, Σ σt·Δ. 0 outside the box. The ray marcher's
 * octaves need τ itself (exp(−bⁱτ)), which survives where exp(−τ) underflows. The walk's status
 * bits (march_iter.status) go to *status; a NaN density stays in τ for the caller's pixel check.
 * The march stops early once every channel's partial τ exceeds tau_limit (NV_INFINITY: never, and
 * then the sum is the full one, bit for bit): a view transmittance that is already below
 * e^{−tau_limit} in every channel can only fall further, so what it returns is at most that and at
 * least the true value (lobe.h derives what this costs a pixel). */
static inline vec3 march_optical_depth_limited(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 origin, vec3 dir,
                                               float dist, int steps, float tau_limit, NV_PRIVATE uint* status) {
  medium_segment seg;
  if (!march_clip(m, origin, dir, dist, &seg, status)) return vec3_splat(0.0f);
  march_iter it = march_begin(m, GRID_ARG, &seg, steps);
  const float sum_limit = tau_limit / it.delta; /* on Σσt, before the scaling by Δ */
  vec3 tau = vec3_splat(0.0f);
  float t;
  while (march_next(&it, GRID_ARG, &t)) {
    tau = vec3_add(tau, march_sigma_t(m, GRID_ARG, &seg, t));
    if (nv_fmin(tau.x, nv_fmin(tau.y, tau.z)) > sum_limit) break;
  }
  *status |= it.status;
  return vec3_scale(tau, it.delta);
}

static inline vec3 march_optical_depth(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 origin, vec3 dir,
                                       float dist, int steps, NV_PRIVATE uint* status) {
  return march_optical_depth_limited(m, GRID_ARG, origin, dir, dist, steps, NV_INFINITY, status);
}

/* Transmittance exp(−τ) over the same quadrature (1 outside the box). */
static inline vec3 march_transmittance(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 origin, vec3 dir,
                                       float dist, int steps, NV_PRIVATE uint* status) {
  return vec3_exp_neg(march_optical_depth(m, GRID_ARG, origin, dir, dist, steps, status));
}

/* Column density ∫ρ ds over the same quadrature as march_optical_depth (Σ ρ·Δ): the medium's σt
 * is σt_unit·ρ with one σt_unit per channel, so τ = σt_unit·column for every channel at once; the
 * light-transmittance cache (light_cache.h) stores this one float per node. */
static inline float march_column_density(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 origin, vec3 dir,
                                         float dist, int steps, NV_PRIVATE uint* status) {
  medium_segment seg;
  if (!march_clip(m, origin, dir, dist, &seg, status)) return 0.0f;
  march_iter it = march_begin(m, GRID_ARG, &seg, steps);
  float column = 0.0f, t;
  while (march_next(&it, GRID_ARG, &t)) column += grid_density(GRID_ARG, vec3_madd(seg.o, seg.d, t));
  *status |= it.status;
  return column * it.delta;
}

/* Where the real-time kernels put a light: a point light's position, a rectangle's centre. */
static inline vec3 march_light_position(NV_CONSTANT const light_params* l) {
  const vec3 p = vec3_from4(l->corner);
  if (LIGHT_IS_RECT(l)) return vec3_add(p, vec3_scale(vec3_add(vec3_from4(l->edge_u), vec3_from4(l->edge_v)), 0.5f));
  return p;
}

/* A light as seen from x, as a point: unit direction to it, distance, and the intensity I (W/sr)
 * towards x, so the irradiance-like factor is I / dist². Returns 0 when it sends nothing to x. */
static inline int march_light_as_point(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE vec3* dir,
                                       NV_PRIVATE float* dist, NV_PRIVATE vec3* intensity) {
  vec3 I = vec3_from4(l->radiance);
  const vec3 to = vec3_sub(march_light_position(l), x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0;
  *dist = nv_sqrt(d2);
  *dir = vec3_scale(to, 1.0f / *dist);
  if (LIGHT_IS_RECT(l)) {
    const float cos_l = -vec3_dot(*dir, vec3_from4(l->normal));
    if (!(cos_l > 0.0f)) return 0;
    I = vec3_scale(I, l->normal.w * cos_l);
  }
  *intensity = I;
  return 1;
}

/* L_b for the real-time kernels: what the view ray would see with the medium removed, i.e. the
 * front of the nearest rectangle light it hits (black from behind), else the background. */
static inline vec3 march_background(NV_CONSTANT const scene_params* s, NV_CONSTANT const light_params* lights,
                                    vec3 origin, vec3 dir) {
  float t;
  int front = 0;
  const int hit = intersect_lights(lights, s->num_lights, origin, dir, 0.0f, -1, &t, &front);
  if (hit < 0) return vec3_from4(s->background);
  return front ? vec3_from4(lights[hit].radiance) : vec3_splat(0.0f);
}

#endif
