/* light_rectangle_area.h: what the real-time kernels do with a rectangle light's area
 * (light_kinds.h's area column; march.h dispatches here): the phase function summed over K×K points
 * of it or integrated over its solid angle exactly (phase_polygon.h), and its shadow averaged over
 * those points, weighted by their share of the light or by the phase towards the camera. */
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

/* Light l's unshadowed in-scattering at x per unit σs, Σ_j I_j·p(g, view_dir·dir_j)/d_j² (view_dir
 * the propagation direction before scattering, e.g. away from the camera): a point light is itself;
 * a rectangle is K×K points at the centres of a K×K split of its area, each with intensity
 * Le·(A/K²)·max(0, cos θ_j) towards x (the midpoint rule over the area, as the path tracer's area
 * light integrates exactly). Why not the centre alone (K = 1, light_view_from): with a
 * forward-peaked phase function the phase angle changes across the light by more than the lobe's
 * width (HG(0.8) halves within 10°; a 6-unit light 20 units away spans 17°): the centre for both
 * phase and shadow loses much of the single scattering at g 0.8, and K×K points for the phase and
 * the shadow (march_light_column) recover most of it (bench/RESULTS.md, "Rectangle lights as K×K
 * points"). */
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

/* Light l's unshadowed in-scattering at x per unit σs with the phase integrated exactly over a
 * rectangle's solid angle, Le·∫_rect p(view_dir·ω) dω (phase_polygon.h): the limit of
 * light_rectangle_phase_sum as K → ∞, for 16–64 evaluations of a closed form per rectangle whatever
 * its size. Why: at g 0.9 HG falls to half its peak within 5°, and Listing 4.1's light (150x100
 * units, 80 behind the Disney cloud) spans 86°x64° from it: its centre alone paints a bright disc
 * wherever the view ray points at it (the phase's peak) and misses the rest (the back-lit Disney
 * cloud with the multiple-scattering cache, bench/RESULTS.md); K×K points paint K² discs. */
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
 * body (bench/RESULTS.md: the back-lit Disney cloud's rim too dark, its core too bright). Both
 * integrals are estimated by two strategies combined with the balance heuristic (Veach 1997,
 * ch. 9): the K×K points of light_rectangle_area_point (the area's midpoint rule: a solid-angle pdf of
 * d²/(A·cos θ_l)), and K×K directions drawn from the phase function about view_dir on a regular
 * grid of its two numbers (pdf p), those that meet the light's front. The first serves broad
 * phases and lights far off the view direction, the second the peak, however narrow. A sample of
 * either is weighted by p/(n·pdf_area + n·p), n = K², in both the numerator (times T) and the
 * denominator, so the ratio is exact for a shadow constant over the light and converges as K grows.
 * Deterministic: fixed patterns, no random numbers. Returns −ln T̄/σ̄ as march_light_column. */
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

/* A rectangle's effective shadow column over its K×K points (march_light_phase_sum's):
 * C = −ln(Σ_j w_j e^{−σ̄ C_j} / Σ_j w_j) / σ̄, w_j = cos θ_j / d_j² (each point's share of the light
 * reaching x), σ̄ the medium's mean σt per unit density. Why: the path tracer's shadow rays go to
 * every point of the light, and the transmittance averaged over them is above the transmittance to
 * the centre (e^{−τ} is convex): through a dense cloud the centre alone makes the light's soft
 * shadow hard and dark. With one σt for all channels (a grey medium) σt_unit·C gives each channel's
 * averaged transmittance exactly; for a coloured one it is the average for the mean σt.
 * SHADOW_WEIGHTING_PHASE weights it by the phase for view_dir instead (light_rectangle_column_phase). */
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
