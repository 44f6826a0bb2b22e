/* raymarch.h: real-time single scattering by ray marching (DESIGN.md "raymarch"; Hillaire 2015,
 * "Physically based and unified volumetric rendering in Frostbite"), with the multiple-scattering octave
 * approximation (Wrenninge et al. 2013, "Oz: the great and volumetric"; Hillaire 2016, "Physically based
 * sky, atmosphere and cloud rendering in Frostbite"). Deterministic: one ray through the pixel centre,
 * fixed quadrature, no random numbers. Parameters: march_params (structs.h).
 *
 * Per view ray o + t·d, its segment [t0, t1] inside the box (clipped at the rectangle light it hits, as
 * the path tracer does) gets `steps` samples x_k, midpoints of steps of equal true length Δ over the
 * occupied majorant cells only (march_iter, march.h: empty space costs nothing):
 *   S_k = σs(x_k) ⊙ Σ_lights (I/d²) ⊙ Σ_{i<N} aⁱ · p(g·cⁱ, μ) · exp(−bⁱ·τ(x_k → light))
 *   L  += T ⊙ (S_k − S_k ⊙ e^{−σt(x_k)·Δ}) / σt(x_k)      (energy-conserving step, exact for
 *   T  ⊙= e^{−σt(x_k)·Δ}                                     S and σt constant over the step)
 * and the pixel is L + T ⊙ L_b (L_b: march_view, what the ray sees with the medium removed). Zero density
 * changes nothing (S = 0, e^{−0} = 1) and skips the light loop. Lights: march_light_sum (march_lights.h),
 * rectangles as points at their centres with intensity Le·A·max(0, cos θ_light) as DESIGN.md allows here,
 * unless area_light_samples or area_light_phase ask for more (structs.h); other emitters do not block
 * shadow rays. μ = dot(d, direction to the light), the cosine between the light's propagation (light → x)
 * and the scattered direction (x → camera, −d), as in pathtrace_direct. τ: light_cache_optical_depth, a
 * light-cache lookup or a march of shadow_steps samples clipped to the box.
 *
 * Octaves (N = octaves): octave i scatters with σs·aⁱ, sees the light through Tr^(bⁱ) = exp(−bⁱ·τ)
 * (extinction σt·bⁱ, τ computed once) and uses the phase function with g·cⁱ; the view ray's T is not
 * scaled. Octave 0 is plain single scattering by the same arithmetic whatever N; the others are added
 * only when N > 1, so a, b, c cannot change an N = 1 image.
 * Bound: every octave term is ≥ 0, so N octaves are never darker than one. With b = c = 1 each octave is
 * octave 0 scaled by aⁱ, so (a < 1; the loader keeps a ≤ b ≤ 1)
 *   L_N = L_1 · Σ_{i<N} aⁱ = L_1 · (1 − a^N)/(1 − a) ≤ L_1/(1 − a).
 * For b < 1 or c < 1 no multiple of L_1 bounds L_N: Tr^(bⁱ) ≥ Tr can be larger by any factor deep in a
 * dense medium (the point of the octaves), and HG with a smaller |g| exceeds HG(g) away from the peak.
 * For any a, b, c, since exp(−bⁱτ) ≤ 1 and p(g', μ) ≤ p_max = (1 + |g|)/(4π(1 − |g|)²) for |g'| ≤ |g|,
 *   L_N − T ⊙ L_b ≤ p_max · Σ_{i<N} aⁱ · U ≤ p_max/(1 − a) · U,
 * U the same march with phase function and shadow transmittance replaced by 1: bounded whenever a < 1.
 * (a ≤ b keeps each octave's effective albedo σs·aⁱ/(σt·bⁱ) ≤ σs/σt.)
 *
 * In the same energy-conserving step, S_k gains σs(x_k) ⊙ (R + g·b·w_out) from the multiple-scattering
 * cache (ms_cache.h; ms_cache_params.grid.nx > 0): the in-scattering towards the camera of the radiance
 * at x_k the light sum does not hold (scattered at least once, and the background), from its directional
 * average R and first moment b; and with -DEMISSION (emission.h) σa(x_k) ⊙ Le(x_k), the medium's own
 * light (an absorbing, emitting homogeneous slab: Le·(1 − e^{−σa·d})), the bound below then taking
 * A ≥ max Le.
 *
 * Early termination (min_transmittance = ε > 0; 0 never stops): the march stops after the step where
 * every channel of T fell below ε' = ε / max(1, max channel of L_b); the pixel is L + T·L_b with the T
 * reached. Per channel, the rest of the march would have added
 *   Σ_{k'} T_{k'}·(S_{k'}/σt_{k'})·(1 − e^{−σt_{k'}Δ}) ≤ T·A·(1 − T_rest),
 * A = sup of S/σt = albedo · Σ_lights (I/d²) · Σ_i aⁱ p(g cⁱ, μ) e^{−bⁱτ} over the rest of the segment,
 * and the L_b term changes from T·T_rest·L_b to T·L_b, by T·(1 − T_rest)·L_b; of opposite signs, so
 * |ΔL| ≤ T·max(A, L_b) < ε·max(A, L_b)/max(1, L_b) ≤ ε·max(A, 1). Scaling ε by L_b keeps a dark pixel
 * before a bright emitter (Listing 4.1's light behind the cloud, L_b = 20) from showing ε·L_b of light
 * the medium hides: an absolute error ε = 10⁻³ is under ΔL* = 1 even at black (L* = 903.3·Y below
 * Y = 0.0089). A bound the host can evaluate: A ≤ max albedo · Σ_lights I/d_min² · p_max · Σ_{i<N} aⁱ,
 * d_min the light's distance from the box (tests/render/light_cache_render_test.cpp).
 *
 * Status word: STATUS_NAN for a non-finite pixel (written as 0) or a NaN density or ray met on the way;
 * STATUS_ITERATION_CAP when a DDA walk spends its budget (majorant_dda.h); no pdf, never STATUS_NEGATIVE_PDF. */
#ifndef NARVAL_RAYMARCH_H
#define NARVAL_RAYMARCH_H

#include "shared/camera.h"
#include "shared/march_lights.h"
#include "shared/ms_cache.h"
#include "shared/ms_cache_view.h"
#include "shared/phase.h"

/* What a march has gathered so far: in-scattered radiance L and view-ray transmittance T. */
typedef struct raymarch_accum {
  vec3 L, T;
} raymarch_accum;

/* The multiple-scattering cache's in-scattering towards the camera per unit σs for the march step at
 * index-space point p (its middle), grey optical depth tau to tau + dtau: the grid layout's at p
 * (ms_cache.h), the view layout's over the step for the pixel's columns `cols` (ms_cache_view.h). */
static inline vec3 raymarch_ms_cache(NV_PRIVATE const ms_cache_params* mc, NV_CONSTANT const medium_params* m,
                                     NV_GLOBAL const float* ms_cache, NV_PRIVATE const ms_view_columns* cols, vec3 p,
                                     float tau, float dtau, vec3 dir) {
  switch (mc->layout) {
    case MS_CACHE_LAYOUT_GRID:
      return ms_cache_lookup(&mc->grid, ms_cache, vec3_from4(m->dims), p, phase_mean_cosine(m->phase), mc->closure,
                             vec3_scale(dir, -1.0f));
    case MS_CACHE_LAYOUT_VIEW: return ms_view_lookup(&mc->grid, ms_cache, cols, tau, dtau);
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry */
  }
}

/* Marches the view ray origin + t·dir over its box segment `seg` until every channel of T is below t_stop
 * (0: never; "Early termination"); `cols`: the pixel's view-cache columns. Loops: `steps` samples
 * (march_next, its piece walk capped by the DDA budget), each with num_lights shadow marches of
 * shadow_steps samples and `octaves` (≤ 16) terms: bounded by the scene's parameters, no cap of their own. */
static inline void raymarch_segment(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                    NV_PRIVATE const node_grid_params* lc, NV_PRIVATE const ms_cache_params* mc,
                                    NV_GLOBAL const float* light_cache, NV_GLOBAL const float* ms_cache,
                                    NV_PRIVATE const medium_segment* seg, NV_PRIVATE const ms_view_columns* cols,
                                    vec3 origin, vec3 dir, int steps, float t_stop, NV_PRIVATE raymarch_accum* acc) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE uint* status = &ctx->status;
  NV_CONSTANT const medium_params* m = &s->medium;
  const vec3 sa = vec3_from4(m->sigma_a), ss = vec3_from4(m->sigma_s);
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, seg, steps);
  const float dt = it.delta, sigma_grey = ms_view_sigma_t(m);
  float t, tau = 0.0f; /* grey optical depth from the camera, for the view-space cache */
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    const float rho = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, t));
    if (!(rho > 0.0f)) { /* S = 0 and e^{−0} = 1: the step would change nothing */
      if (rho != rho) *status |= STATUS_NAN; /* a NaN density must not pass as empty space */
      continue;
    }
    const vec3 sigma_t = vec3_scale(vec3_add(sa, ss), rho); /* as march_sigma_t */
    const vec3 sigma_s = vec3_scale(ss, rho);
    const float dtau = sigma_grey * rho * dt;
    vec3 S = vec3_splat(0.0f);
    if (!vec3_is_zero(sigma_s)) {
      /* The lights' unscattered light, unless the cache holds it too (ms_cache.h, "Direct"). */
      vec3 Li = vec3_splat(0.0f);
      if (!(mc->grid.nx > 0 && mc->direct))
        march_light_sum(KERNEL_CONTEXT_ARG, mp, lc, light_cache, vec3_madd(origin, dir, t), dir, MARCH_LIGHTS_RAYMARCH,
                        &Li);
      if (mc->grid.nx > 0) /* the rest of the radiance arriving there (ms_cache.h), over the step */
        Li = vec3_add(Li, raymarch_ms_cache(mc, m, ms_cache, cols, vec3_madd(seg->o, seg->d, t), tau, dtau, dir));
      S = vec3_mul(sigma_s, Li);
    }
    tau += dtau;
#ifdef EMISSION
    S = vec3_add(S, emission_source(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, t), rho)); /* σa·Le (emission.h) */
#endif
    march_energy_conserving_step(&acc->L, &acc->T, S, sigma_t, dt);
    if (vec3_max_component(acc->T) < t_stop) break; /* early termination (above) */
  }
  *status |= it.status;
}

/* Radiance through the centre of pixel (px, py). Pinhole: the ray leaves the lens centre. */
static inline vec3 raymarch_pixel(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                  NV_PRIVATE const node_grid_params* lc, NV_PRIVATE const ms_cache_params* mc,
                                  NV_GLOBAL const float* light_cache, NV_GLOBAL const float* ms_cache, int px, int py) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  NV_PRIVATE uint* status = &ctx->status;
  const ray3 r = camera_pixel_centre_ray(&s->camera, px, py);
  vec3 Lb;
  medium_segment seg;
  vec3 L;
  if (march_view(s, lights, r.origin, r.dir, &Lb, &seg)) {
    raymarch_accum acc;
    acc.L = vec3_splat(0.0f);
    acc.T = vec3_splat(1.0f);
    const float t_stop = mp->min_transmittance / nv_fmax(1.0f, vec3_max_component(Lb));
    const ms_view_columns cols = ms_view_locate(mc, px, py);
    raymarch_segment(KERNEL_CONTEXT_ARG, mp, lc, mc, light_cache, ms_cache, &seg, &cols, r.origin, r.dir, mp->steps,
                     t_stop, &acc);
    L = vec3_add(acc.L, vec3_mul(acc.T, Lb));
  } else {
    L = Lb;
  }
  return status_finite_or_zero(status, L);
}

#endif
