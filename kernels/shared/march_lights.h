/* march_lights.h: the real-time kernels' light loop (raymarch.h; both lobe variants, lobe.h). The
 * light of every light arriving at x and scattered along view_dir (pointing away from whoever
 * looks: the camera, or the lobe's centre), per unit σs:
 *   Σ_lights (I/d²) ⊙ Σ_{i<N} aⁱ p(g cⁱ, μ) exp(−bⁱ τ),
 * N = mp->octaves (Wrenninge et al. 2013; 1 for the lobe), τ the shadow ray's optical depth
 * (light_cache_optical_depth: a cache lookup or the exact march). A rectangle with K > 1 points or
 * the exact phase takes march_light_phase, one shadow for all its points. Each light's term is
 * added into *sum in turn.
 *
 * A point light's product is formed in one of two orders, each the one its algorithm used before
 * their loops were merged, so that the merge moved no pixel: MARCH_LIGHTS_RAYMARCH forms
 * (I/d²) ⊙ (e^{−τ}·p); MARCH_LIGHTS_LOBE forms (e^{−τ} ⊙ I)·(p/d²) and skips a light with p ≤ 0
 * (a NaN p sets STATUS_NAN instead of reaching the pixel). */
#ifndef NARVAL_MARCH_LIGHTS_H
#define NARVAL_MARCH_LIGHTS_H

#include "shared/light_cache.h"
#include "shared/phase.h"

#define MARCH_LIGHTS_RAYMARCH 0
#define MARCH_LIGHTS_LOBE 1

static inline void march_light_sum(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                   NV_PRIVATE const node_grid_params* lc, NV_GLOBAL const float* light_cache, vec3 x,
                                   vec3 view_dir, int order, NV_PRIVATE vec3* sum) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  NV_CONSTANT const medium_params* m = &s->medium;
  for (int l = 0; l < s->num_lights; ++l) {
    light_point_view v;
    if (!light_view_from(&lights[l], x, &v)) continue;
    const vec3 tau = light_cache_optical_depth(KERNEL_CONTEXT_ARG, mp, lc, light_cache, l, x, v.dir, v.dist, view_dir);
    float ai = 1.0f, bi = 1.0f, ci = 1.0f;
    if (mp->area_light_samples > 1 || mp->area_light_phase != AREA_LIGHT_POINTS) {
      const int K = mp->area_light_samples, mode = mp->area_light_phase;
      vec3 lit = vec3_mul(vec3_exp_neg(tau), march_light_phase(&lights[l], x, m->phase, view_dir, mode, K));
      for (int i = 1; i < mp->octaves; ++i) {
        ai *= mp->octave_a;
        bi *= mp->octave_b;
        ci *= mp->octave_c;
        lit = vec3_add(lit, vec3_scale(vec3_mul(vec3_exp_neg(vec3_scale(tau, bi)),
                                                march_light_phase(&lights[l], x, phase_scaled(m->phase, ci), view_dir,
                                                                  mode, K)),
                                       ai));
      }
      *sum = vec3_add(*sum, lit);
      continue;
    }
    /* K = 1: the centre alone, the dissertation's point light. */
    const float p = phase_eval(m->phase, view_dir, v.dir);
    if (order == MARCH_LIGHTS_LOBE) {
      if (!(p > 0.0f)) {
        if (p != p) ctx->status |= STATUS_NAN; /* e.g. a NaN g: not dropped silently */
        continue;
      }
      *sum = vec3_add(*sum, vec3_scale(vec3_mul(vec3_exp_neg(tau), v.intensity), p / (v.range * v.range)));
      continue;
    }
    vec3 oct = vec3_scale(vec3_exp_neg(tau), p); /* octave 0: plain single scattering */
    for (int i = 1; i < mp->octaves; ++i) {
      ai *= mp->octave_a;
      bi *= mp->octave_b;
      ci *= mp->octave_c;
      const float pi = phase_eval(phase_scaled(m->phase, ci), view_dir, v.dir);
      oct = vec3_add(oct, vec3_scale(vec3_exp_neg(vec3_scale(tau, bi)), ai * pi));
    }
    *sum = vec3_add(*sum, vec3_mul(vec3_scale(v.intensity, 1.0f / (v.range * v.range)), oct));
  }
}

#endif
