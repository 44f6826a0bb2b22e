/* light_rectangle_area.h: a rectangle light's area in the real-time kernels (light_kinds.h's area
 * column; march.h dispatches here): its phase over K×K points or exact, its shadow over K×K points. */
#ifndef NARVAL_LIGHT_RECTANGLE_AREA_H
#define NARVAL_LIGHT_RECTANGLE_AREA_H

#include "shared/light.h"
#include "shared/march_quadrature.h"
#include "shared/phase.h"
#include "shared/phase_polygon.h"

/* Point (i, j) of a rectangle's K×K split: the centre of that sub-rectangle. */
static inline vec3 light_rectangle_area_point(NV_CONSTANT const light_params* l, int i, int j, int K) {
  const float inv_k = 1.0f / (float)K;
  return vec3_add(vec3_from4(l->corner), vec3_add(vec3_scale(vec3_from4(l->edge_u), ((float)i + 0.5f) * inv_k),
                                                  vec3_scale(vec3_from4(l->edge_v), ((float)j + 0.5f) * inv_k)));
}

/* Light l's unshadowed in-scattering at x per unit σs over K×K points at the centres of a K×K split
 * of its area, Σ_j I_j·p(view_dir·dir_j)/d_j², I_j = Le·(A/K²)·max(0, cos θ_j), view_dir the
 * propagation before scattering (the midpoint rule; the path tracer integrates exactly). Why not the
 * centre alone (K = 1): across the light the phase angle changes by more than a forward lobe's width
 * (HG(0.8) halves within 10°; a 6-unit light 20 units away spans 17°); K×K points for phase and shadow
 * (march_light_column) recover most of the single scattering the centre loses (bench/RESULTS.md,
 * "Rectangle lights as K×K points"). */
static inline vec3 light_rectangle_phase_sum(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                         vec3 view_dir, int K) {
  const vec3 Le = vec3_from4(l->radiance);
  const vec3 n = vec3_from4(l->normal);
  const float inv_k = 1.0f / (float)K;
  float sum = 0.0f;
  for (int j = 0; j < K; ++j)
    for (int i = 0; i < K; ++i) {
      const vec3 to = vec3_sub(light_rectangle_area_point(l, i, j, K), x);
      const float d2 = vec3_dot(to, to);
      if (!(d2 > 0.0f)) continue;
      const vec3 dir = vec3_scale(to, 1.0f / nv_sqrt(d2));
      const float cos_l = -vec3_dot(dir, n);
      if (!(cos_l > 0.0f)) continue;
      sum += cos_l * phase_eval(phase, view_dir, dir) / d2;
    }
  return vec3_scale(Le, l->normal.w * inv_k * inv_k * sum);
}

/* The same with the phase integrated exactly over the solid angle, Le·∫_rect p(view_dir·ω) dω
 * (phase_polygon.h): the limit K → ∞, 16–64 closed-form evaluations per rectangle whatever its size.
 * Why: at g 0.9 HG halves within 5° and Listing 4.1's light spans 86°x64° from the Disney cloud: its
 * centre paints a bright disc where the view ray points at it and misses the rest, K×K points paint
 * K² discs (bench/RESULTS.md: the back-lit Disney cloud with the multiple-scattering cache). */
static inline vec3 light_rectangle_phase_integral(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                              vec3 view_dir) {
  const vec3 c = vec3_from4(l->corner), u = vec3_from4(l->edge_u), v = vec3_from4(l->edge_v);
  /* One-sided: x must lie on the side the light faces. */
  if (!(vec3_dot(vec3_sub(x, c), vec3_from4(l->normal)) > 0.0f)) return vec3_splat(0.0f);
  const vec3 d0 = vec3_normalize(vec3_sub(c, x)), d1 = vec3_normalize(vec3_sub(vec3_add(c, u), x));
  const vec3 d2 = vec3_normalize(vec3_sub(vec3_add(vec3_add(c, u), v), x)), d3 = vec3_normalize(vec3_sub(vec3_add(c, v), x));
  return vec3_scale(vec3_from4(l->radiance), phase_quad_integral(phase, view_dir, d0, d1, d2, d3));
}

/* The effective column of weighted shadow rays, −ln(Σ w e^{−σ̄C}/Σ w)/σ̄, from Σ w, Σ w·(e^{−σ̄C} − 1)
 * and Σ w·C via expm1 and log1p, so a thin column keeps its digits. No extinction, or every ray fully
 * shadowed: the weighted mean column (the limit σ̄ → 0; else as dark as float allows). Nothing
 * weighted (nothing of the light faces x, or x is the point light): 0. */
static inline float march_mean_column(float w_sum, float loss_sum, float column_sum, float sigma) {
  if (!(w_sum > 0.0f)) return 0.0f;
  const float mean_loss = loss_sum / w_sum;
  if (!(sigma > 0.0f) || !(mean_loss > -1.0f)) return column_sum / w_sum;
  return -nv_log1p(mean_loss) / sigma;
}

/* A rectangle's effective column weighted by the phase towards the camera (SHADOW_WEIGHTING_PHASE):
 * T̄ = ∫ p(view_dir·ω) T(ω) dω / ∫ p dω over its solid angle, so Le·T̄·∫ p dω (march_light_phase) is the
 * single scattering ∫ Le p T dω when phase and shadow vary together, as behind a back-lit cloud: at g 0.9
 * the phase peaks within degrees of the view ray's continuation, shadowed by the thin rim, while the
 * area average looks through the body (bench/RESULTS.md: the back-lit Disney cloud's rim too dark, core
 * too bright). Both integrals combine by the balance heuristic (Veach 1997, ch. 9) K×K area points
 * (light_rectangle_area_point, solid-angle pdf d²/(A·cos θ_l): broad phases, lights off the view) and
 * K×K phase samples about view_dir on a regular grid (pdf p, those meeting the light's front: the peak,
 * however narrow), each weighing p/(n·pdf_area + n·p), n = K², in numerator (times T) and denominator:
 * exact for a shadow constant over the light, converging as K grows. Deterministic (fixed patterns).
 * Returns −ln T̄/σ̄ as march_light_column. */
static inline float light_rectangle_column_phase(KERNEL_CONTEXT_PARAM, NV_CONSTANT const light_params* l, vec3 x, int K,
                                             int shadow_steps, vec3 view_dir) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  const vec3 nrm = vec3_from4(l->normal);
  const float area = l->normal.w, n = (float)(K * K);
  const float sigma = vec3_average(medium_sigma_t(m));
  float w_sum = 0.0f, loss_sum = 0.0f, column_sum = 0.0f; /* as march_light_column */
  for (int strategy = 0; strategy < 2; ++strategy)
    for (int j = 0; j < K; ++j)
      for (int i = 0; i < K; ++i) {
        vec3 dir;
        float d;
        if (strategy == 0) { /* the area's point (i, j) */
          const vec3 to = vec3_sub(light_rectangle_area_point(l, i, j, K), x);
          d = vec3_length(to);
          if (!(d > 0.0f)) continue;
          dir = vec3_scale(to, 1.0f / d);
        } else { /* the phase's direction (i, j) */
          float pdf;
          int front = 0;
          dir = phase_sample(m->phase, view_dir, ((float)i + 0.5f) / (float)K, ((float)j + 0.5f) / (float)K, &pdf);
          d = light_rectangle_hit(l, x, dir, 0.0f, &front);
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

/* A rectangle's effective shadow column over its K×K points: C = −ln(Σ_j w_j e^{−σ̄ C_j}/Σ_j w_j)/σ̄,
 * w_j = cos θ_j/d_j² (each point's share of the light reaching x), σ̄ the mean σt per unit density.
 * Why: the path tracer's shadow rays go to every point of the light, and their mean transmittance
 * exceeds the centre's (e^{−τ} is convex): the centre alone makes a soft shadow through a dense cloud
 * hard and dark. σt_unit·C is exact per channel for a grey medium, the mean σt's for a coloured one. */
static inline float light_rectangle_column(KERNEL_CONTEXT_PARAM, NV_CONSTANT const light_params* l,
                                       vec3 x, int K, int shadow_steps, int weighting, vec3 view_dir) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  switch (weighting) {
    case SHADOW_WEIGHTING_AREA: break;
    case SHADOW_WEIGHTING_PHASE: return light_rectangle_column_phase(KERNEL_CONTEXT_ARG, l, x, K, shadow_steps, view_dir);
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
  const vec3 n = vec3_from4(l->normal);
  const float sigma = vec3_average(medium_sigma_t(m));
  float w_sum = 0.0f, loss_sum = 0.0f, column_sum = 0.0f; /* loss: Σ w (e^{−σ̄C} − 1), no cancellation */
  for (int j = 0; j < K; ++j)
    for (int i = 0; i < K; ++i) {
      const vec3 to = vec3_sub(light_rectangle_area_point(l, i, j, K), x);
      const float d2 = vec3_dot(to, to);
      if (!(d2 > 0.0f)) {
        if (d2 != d2) *status |= STATUS_NAN;
        continue;
      }
      const float d = nv_sqrt(d2);
      const vec3 dir = vec3_scale(to, 1.0f / d);
      const float column = march_column_density(KERNEL_CONTEXT_ARG, x, dir, d, shadow_steps);
      const float cos_l = -vec3_dot(dir, n);
      if (!(cos_l > 0.0f)) continue;
      const float w = cos_l / d2;
      w_sum += w;
      loss_sum += w * nv_expm1(-sigma * column);
      column_sum += w * column;
    }
  return march_mean_column(w_sum, loss_sum, column_sum, sigma);
}

#endif
