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

#include "shared/emission.h"
#include "shared/grid.h"
#include "shared/light.h"
#include "shared/majorant.h"
#include "shared/medium.h"
#include "shared/phase.h"
#include "shared/phase_polygon.h"

/* σt at world point o + t·d of a medium segment (index-space origin and direction in `seg`). */
static inline vec3 march_sigma_t(KERNEL_CONTEXT_PARAM, NV_PRIVATE const medium_segment* seg,
                                 float t) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  const float rho = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, t));
  return vec3_scale(vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s)), rho);
}

/* Below this optical depth per step, (1 − e^{−x})/x is evaluated by its Taylor series: the direct
 * form loses |rounding of e^{−x}|/x to cancellation (≤ 3 ulp·2⁻²³/x ≈ 4e-6 relative at x = 0.1,
 * less above), the series 1 − x/2 + x²/6 − x³/24 + x⁴/120 is off by ≤ x⁵/720 ≈ 1.4e-8 below it, and
 * at x = 0 (σt = 0) it is exactly 1, so the step integral is exactly S·Δ, never 0/0. */
#define MARCH_SERIES_MAX 0.1f

/* (1 − e^{−x})/x for x ≥ 0, given e = e^{−x}: the energy-conserving step integral
 * (S − S·e^{−σtΔ})/σt = S·Δ·march_step_weight(σtΔ). */
static inline float march_step_weight(float x, float e) {
  if (x < MARCH_SERIES_MAX)
    return 1.0f - x * (0.5f - x * (1.0f / 6.0f - x * (1.0f / 24.0f - x * (1.0f / 120.0f))));
  return (1.0f - e) / x;
}

/* One step of a view march (Hillaire 2015's energy-conserving integration): with the source S
 * (radiance per unit length) and σt constant over a step of length Δ, the light it adds is
 * ∫_0^Δ S e^{−σt s} ds = (S − S·e^{−σtΔ})/σt = S·Δ·march_step_weight(σtΔ), seen through the
 * transmittance *T gathered before the step, which then falls by e^{−σtΔ}. */
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
  int k, steps;
  int whole;      /* no majorant grid (host without bounds): the segment is one piece */
  uint status;    /* the first walk's DDA status (majorant_iter.status); callers OR it into theirs.
                     The second walk repeats the first and ends no later, so it adds nothing. */
} march_iter;

/* Next occupied piece of the walk into [*a, *b]; 0 when none is left. */
static inline int march_next_piece(NV_PRIVATE march_iter* it, KERNEL_CONTEXT_PARAM, NV_PRIVATE float* a,
                                   NV_PRIVATE float* b) {
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
  it.a = it.b = it.s_a = 0.0f;
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

/* Optical depth τ from `origin` over `dist` along unit `dir`: `steps` midpoint samples over the
 * occupied part of the segment inside the box, Σ σt·Δ. 0 outside the box. The ray marcher's
 * octaves need τ itself (exp(−bⁱτ)), which survives where exp(−τ) underflows. The walk's status
 * bits (march_iter.status) go to *status; a NaN density stays in τ for the caller's pixel check.
 * The march stops early once every channel's partial τ exceeds tau_limit (NV_INFINITY: never, and
 * then the sum is the full one, bit for bit): a view transmittance that is already below
 * e^{−tau_limit} in every channel can only fall further, so what it returns is at most that and at
 * least the true value (lobe.h derives what this costs a pixel). */
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

/* Column density ∫ρ ds over the same quadrature as march_optical_depth (Σ ρ·Δ): the medium's σt
 * is σt_unit·ρ with one σt_unit per channel, so τ = σt_unit·column for every channel at once; the
 * light-transmittance cache (light_cache.h) stores this one float per node. */
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

#ifdef EMISSION
/* The medium's own light along the view segment `seg`: ∫ T(t) σa(t) Le(t) dt (emission.h) over
 * `steps` midpoint samples of its occupied cells, by the energy-conserving step with S = σa·Le
 * (exact for S and σt constant over a step: an absorbing, emitting homogeneous slab gives
 * Le·(1 − e^{−σa·d}) to float rounding). Stops after the step where every channel of T fell below
 * t_stop (0: never): what the rest would add is at most T·max(σa·Le/σt) < t_stop·max Le. For the
 * Lobe Estimator, whose estimate of the lights' light holds none; the ray marcher adds σa·Le inside
 * its own march. */
static inline vec3 march_emission(KERNEL_CONTEXT_PARAM, NV_PRIVATE const medium_segment* seg,
                                  int steps, float t_stop) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  const vec3 st_unit = vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s));
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, seg, steps);
  vec3 L = vec3_splat(0.0f), T = vec3_splat(1.0f);
  float t;
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    const vec3 p = vec3_madd(seg->o, seg->d, t);
    const float rho = grid_density(KERNEL_CONTEXT_ARG, p);
    if (!(rho > 0.0f)) { /* nothing emits or attenuates there */
      if (rho != rho) *status |= STATUS_NAN;
      continue;
    }
    march_energy_conserving_step(&L, &T, emission_source(KERNEL_CONTEXT_ARG, p, rho), vec3_scale(st_unit, rho),
                                 it.delta);
    if (vec3_max_component(T) < t_stop) break;
  }
  *status |= it.status;
  return L;
}
#endif

/* A light as seen from x, as a point: unit direction to it, distance, and the intensity I (W/sr)
 * towards x, so the irradiance-like factor is I / dist². Returns 0 when it sends nothing to x. */
static inline int march_light_as_point(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE vec3* dir,
                                       NV_PRIVATE float* dist, NV_PRIVATE vec3* intensity) {
  vec3 I = vec3_from4(l->radiance);
  const vec3 to = vec3_sub(light_centre(l), x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0;
  *dist = nv_sqrt(d2);
  *dir = vec3_scale(to, 1.0f / *dist);
  switch (LIGHT_KIND(l)) {
    case LIGHT_RECTANGLE: {
      const float cos_l = -vec3_dot(*dir, vec3_from4(l->normal));
      if (!(cos_l > 0.0f)) return 0;
      I = vec3_scale(I, l->normal.w * cos_l);
      break;
    }
    case LIGHT_POINT: break;
    default: return 0; /* unknown: reported at the kernel's entry */
  }
  *intensity = I;
  return 1;
}

/* Point (i, j) of a rectangle's K×K split: the centre of that sub-rectangle. */
static inline vec3 march_light_area_point(NV_CONSTANT const light_params* l, int i, int j, int K) {
  const float inv_k = 1.0f / (float)K;
  return vec3_add(vec3_from4(l->corner), vec3_add(vec3_scale(vec3_from4(l->edge_u), ((float)i + 0.5f) * inv_k),
                                                  vec3_scale(vec3_from4(l->edge_v), ((float)j + 0.5f) * inv_k)));
}

/* Light l's unshadowed in-scattering at x per unit σs, Σ_j I_j·p(g, view_dir·dir_j)/d_j² (view_dir
 * the propagation direction before scattering, e.g. away from the camera): a point light is itself;
 * a rectangle is K×K points at the centres of a K×K split of its area, each with intensity
 * Le·(A/K²)·max(0, cos θ_j) towards x (the midpoint rule over the area, as the path tracer's area
 * light integrates exactly). Why not the centre alone (K = 1, march_light_as_point): with a
 * forward-peaked phase function the phase angle changes across the light by more than the lobe's
 * width (HG(0.8) halves within 10°; a 6-unit light 20 units away spans 17°). With the centre for
 * both phase and shadow, single scattering on the default cloud at g 0.8 sums to 0.68 of the path
 * tracer's (0.999 at g 0); 4x4 points for the phase bring it to 0.74, and the shadow averaged over
 * them as well (march_light_column, the callers' shadow) to 0.82. */
static inline vec3 march_light_phase_sum(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                         vec3 view_dir, int K) {
  const vec3 Le = vec3_from4(l->radiance);
  switch (LIGHT_KIND(l)) {
    case LIGHT_POINT: {
      const vec3 to = vec3_sub(vec3_from4(l->corner), x);
      const float d2 = vec3_dot(to, to);
      if (!(d2 > 0.0f)) return vec3_splat(0.0f);
      return vec3_scale(Le, phase_eval(phase, view_dir, vec3_scale(to, 1.0f / nv_sqrt(d2))) / d2);
    }
    case LIGHT_RECTANGLE: break; /* below */
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry */
  }
  const vec3 n = vec3_from4(l->normal);
  const float inv_k = 1.0f / (float)K;
  float sum = 0.0f;
  for (int j = 0; j < K; ++j)
    for (int i = 0; i < K; ++i) {
      const vec3 to = vec3_sub(march_light_area_point(l, i, j, K), x);
      const float d2 = vec3_dot(to, to);
      if (!(d2 > 0.0f)) continue;
      const vec3 dir = vec3_scale(to, 1.0f / nv_sqrt(d2));
      const float cos_l = -vec3_dot(dir, n);
      if (!(cos_l > 0.0f)) continue;
      sum += cos_l * phase_eval(phase, view_dir, dir) / d2;
    }
  return vec3_scale(Le, l->normal.w * inv_k * inv_k * sum);
}

/* Light l's unshadowed in-scattering at x per unit σs with the phase integrated exactly over a
 * rectangle's solid angle, Le·∫_rect p(view_dir·ω) dω (phase_polygon.h): the limit of
 * march_light_phase_sum as K → ∞, for 16–64 evaluations of a closed form per rectangle whatever
 * its size. Why: at g 0.9 HG falls to half its peak within 5°, and Listing 4.1's light (150x100
 * units, 80 behind the Disney cloud) spans 86°x64° from it: its centre alone paints a bright disc
 * wherever the view ray points at it (the phase's peak) and misses the rest (the back-lit Disney
 * cloud with the multiple-scattering cache: relMSE 1.88 against the path tracer with the centre,
 * 0.09 exact; bench/RESULTS.md); K×K points paint K² discs. A point light is itself, as in
 * march_light_phase_sum. */
static inline vec3 march_light_phase_integral(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                              vec3 view_dir) {
  switch (LIGHT_KIND(l)) {
    case LIGHT_POINT: return march_light_phase_sum(l, x, phase, view_dir, 1);
    case LIGHT_RECTANGLE: break; /* below */
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry */
  }
  const vec3 c = vec3_from4(l->corner), u = vec3_from4(l->edge_u), v = vec3_from4(l->edge_v);
  /* One-sided: x must lie on the side the light faces. */
  if (!(vec3_dot(vec3_sub(x, c), vec3_from4(l->normal)) > 0.0f)) return vec3_splat(0.0f);
  const vec3 d0 = vec3_normalize(vec3_sub(c, x)), d1 = vec3_normalize(vec3_sub(vec3_add(c, u), x));
  const vec3 d2 = vec3_normalize(vec3_sub(vec3_add(vec3_add(c, u), v), x)), d3 = vec3_normalize(vec3_sub(vec3_add(c, v), x));
  return vec3_scale(vec3_from4(l->radiance), phase_quad_integral(phase, view_dir, d0, d1, d2, d3));
}

/* The real-time kernels' phase over a light (realtime_params.area_light_phase): K×K points
 * (march_light_phase_sum) or the exact integral (march_light_phase_integral). */
static inline vec3 march_light_phase(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                     vec3 view_dir, int area_light_phase, int K) {
  switch (area_light_phase) {
    case AREA_LIGHT_POINTS: return march_light_phase_sum(l, x, phase, view_dir, K);
    case AREA_LIGHT_EXACT: return march_light_phase_integral(l, x, phase, view_dir);
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry */
  }
}

/* The effective column of weighted shadow rays, −ln(Σ w e^{−σ̄C}/Σ w)/σ̄, from Σ w, Σ w·(e^{−σ̄C} − 1)
 * and Σ w·C: through expm1 and log1p, so a thin column keeps its digits. No extinction, or every ray
 * fully shadowed: the weighted mean column (the limit σ̄ → 0, and as dark as the float allows
 * otherwise). Nothing weighted (nothing of the light faces x, or x is the point light): 0. */
static inline float march_mean_column(float w_sum, float loss_sum, float column_sum, float sigma) {
  if (!(w_sum > 0.0f)) return 0.0f;
  const float mean_loss = loss_sum / w_sum;
  if (!(sigma > 0.0f) || !(mean_loss > -1.0f)) return column_sum / w_sum;
  return -nv_log1p(mean_loss) / sigma;
}

/* A rectangle's effective column weighted by the phase towards the camera (SHADOW_WEIGHTING_PHASE):
 * T̄ = ∫ p(view_dir·ω) T(ω) dω / ∫ p(view_dir·ω) dω over the light's solid angle, so that
 * Le·T̄·∫ p dω (march_light_phase) is the single scattering ∫ Le p T dω whenever the phase and the
 * shadow vary together. They do behind a cloud lit from the back: at g 0.9 the phase is a peak a
 * few degrees wide around the view ray's continuation, the shadow along it is the thin rim's, and
 * an average over the light's area (the other weighting) takes in directions through the cloud's
 * body (bench/RESULTS.md: the back-lit Disney cloud's rim 25% dark, its core 3x bright). Both
 * integrals are estimated by two strategies combined with the balance heuristic (Veach 1997,
 * ch. 9): the K×K points of march_light_area_point (the area's midpoint rule: a solid-angle pdf of
 * d²/(A·cos θ_l)), and K×K directions drawn from the phase function about view_dir on a regular
 * grid of its two numbers (pdf p), those that meet the light's front. The first serves broad
 * phases and lights far off the view direction, the second the peak, however narrow. A sample of
 * either is weighted by p/(n·pdf_area + n·p), n = K², in both the numerator (times T) and the
 * denominator, so the ratio is exact for a shadow constant over the light and converges as K grows.
 * Deterministic: fixed patterns, no random numbers. Returns −ln T̄/σ̄ as march_light_column. */
static inline float march_light_column_phase(KERNEL_CONTEXT_PARAM, NV_CONSTANT const light_params* l, vec3 x, int K,
                                             int shadow_steps, vec3 view_dir) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  const vec3 nrm = vec3_from4(l->normal);
  const float area = l->normal.w, n = (float)(K * K);
  const float sigma = vec3_average(vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s)));
  float w_sum = 0.0f, loss_sum = 0.0f, column_sum = 0.0f; /* as march_light_column */
  for (int strategy = 0; strategy < 2; ++strategy)
    for (int j = 0; j < K; ++j)
      for (int i = 0; i < K; ++i) {
        vec3 dir;
        float d;
        if (strategy == 0) { /* the area's point (i, j) */
          const vec3 to = vec3_sub(march_light_area_point(l, i, j, K), x);
          d = vec3_length(to);
          if (!(d > 0.0f)) continue;
          dir = vec3_scale(to, 1.0f / d);
        } else { /* the phase's direction (i, j) */
          float pdf;
          int front = 0;
          dir = phase_sample(m->phase, view_dir, ((float)i + 0.5f) / (float)K, ((float)j + 0.5f) / (float)K, &pdf);
          d = intersect_rectangle(l, x, dir, 0.0f, &front);
          if (!(d < NV_INFINITY) || !front) continue;
        }
        const float cos_l = -vec3_dot(dir, nrm);
        if (!(cos_l > 0.0f)) continue;
        const float p = phase_eval(m->phase, view_dir, dir);
        const float w = p / (n * d * d / (area * cos_l) + n * p);
        if (!(w > 0.0f)) continue;
        const float column = march_column_density(KERNEL_CONTEXT_ARG, x, dir, d, shadow_steps);
        w_sum += w;
        loss_sum += w * nv_expm1(-sigma * column);
        column_sum += w * column;
      }
  return march_mean_column(w_sum, loss_sum, column_sum, sigma);
}

/* Column density from x to light l, ∫ρ ds over shadow_steps midpoint samples: to the light itself
 * (a point light; a rectangle with K = 1: its centre), or for a rectangle with K > 1 the effective
 * column of its K×K points (march_light_phase_sum's): C = −ln(Σ_j w_j e^{−σ̄ C_j} / Σ_j w_j) / σ̄,
 * w_j = cos θ_j / d_j² (each point's share of the light reaching x), σ̄ the medium's mean σt per
 * unit density. Why: the path tracer's shadow rays go to every point of the light, and the
 * transmittance averaged over them is above the transmittance to the centre (e^{−τ} is convex):
 * through a dense cloud the centre alone makes the light's soft shadow hard and dark. With one σt
 * for all channels (a grey medium) σt_unit·C gives each channel's averaged transmittance exactly;
 * for a coloured one it is the average for the mean σt. `weighting` SHADOW_WEIGHTING_PHASE weights a
 * rectangle's shadow by the phase for view_dir instead (march_light_column_phase). */
static inline float march_light_column(KERNEL_CONTEXT_PARAM, NV_CONSTANT const light_params* l,
                                       vec3 x, int K, int shadow_steps, int weighting, vec3 view_dir) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  int area = 0; /* a rectangle's K×K points, else the light's one point */
  switch (LIGHT_KIND(l)) {
    case LIGHT_RECTANGLE: area = K > 1; break;
    case LIGHT_POINT: break;
    default: return 0.0f; /* unknown: sends nothing (march_light_as_point), reported at the entry */
  }
  switch (weighting) {
    case SHADOW_WEIGHTING_AREA: break;
    case SHADOW_WEIGHTING_PHASE:
      if (area) return march_light_column_phase(KERNEL_CONTEXT_ARG, l, x, K, shadow_steps, view_dir);
      break; /* one point: nothing to weight */
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
  const vec3 n = vec3_from4(l->normal);
  const int k_side = area ? K : 1;
  const float sigma = vec3_average(vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s)));
  float w_sum = 0.0f, loss_sum = 0.0f, column_sum = 0.0f; /* loss: Σ w (e^{−σ̄C} − 1), no cancellation */
  for (int j = 0; j < k_side; ++j)
    for (int i = 0; i < k_side; ++i) {
      const vec3 to = vec3_sub(area ? march_light_area_point(l, i, j, K) : light_centre(l), x);
      const float d2 = vec3_dot(to, to);
      if (!(d2 > 0.0f)) {
        if (d2 != d2) *status |= STATUS_NAN;
        continue;
      }
      const float d = nv_sqrt(d2);
      const vec3 dir = vec3_scale(to, 1.0f / d);
      const float column = march_column_density(KERNEL_CONTEXT_ARG, x, dir, d, shadow_steps);
      if (!area) return column;
      const float cos_l = -vec3_dot(dir, n);
      if (!(cos_l > 0.0f)) continue;
      const float w = cos_l / d2;
      w_sum += w;
      loss_sum += w * nv_expm1(-sigma * column);
      column_sum += w * column;
    }
  return march_mean_column(w_sum, loss_sum, column_sum, sigma);
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

/* The view ray's segment through the medium's box into *seg, stopped at the first rectangle light it
 * meets (the medium behind an emitter is hidden by it: the path tracer's rule); 0 when there is none.
 * The real-time kernels' view rays and the view-space cache's columns (ms_cache_view.h) start here. */
static inline int march_view_segment(NV_CONSTANT const scene_params* s, NV_CONSTANT const light_params* lights,
                                     vec3 origin, vec3 dir, NV_PRIVATE medium_segment* seg) {
  float t_surf;
  int front = 0;
  intersect_lights(lights, s->num_lights, origin, dir, 0.0f, -1, &t_surf, &front);
  return medium_intersect(&s->medium, origin, dir, 0.0f, t_surf, seg);
}

#endif
