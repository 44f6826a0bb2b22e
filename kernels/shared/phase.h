/* phase.h: phase functions. θ is the angle between the propagation directions before (w_in) and
 * after (w_out) scattering, so g > 0 scatters forward (DESIGN.md, physics conventions).
 * Henyey-Greenstein: p(μ) = (1 − g²) / (4π (1 + g² − 2gμ)^{3/2}), normalised over the sphere. The
 * dissertation's printed form (§2.6.2) drops the 3/2 exponent: a typo. Sampling inverts the CDF
 * exactly, so pdf == eval and the sample weight eval/pdf is 1. */
#ifndef NARVAL_PHASE_H
#define NARVAL_PHASE_H

#include "shared/sampling.h"
#include "shared/structs.h" /* PHASE_* kinds */

/* Below this |g| HG is evaluated and sampled as isotropic: the inverse-CDF formula divides by g,
 * and |p_HG − 1/(4π)| <= 3|g|/(4π)·(1+O(g)) is then under 1e-3 relative. */
#define PHASE_HG_ISOTROPIC_EPS 1e-4f

/* 1 + g² − 2gμ without cancellation near g → ±1, μ → ±1: (1−g)² + 2g(1−μ) for g ≥ 0 and
 * (1+g)² − 2g(1+μ) for g < 0 (both expand to the same polynomial). */
static inline float phase_hg_denominator(float g, float mu) {
  return g >= 0.0f ? (1.0f - g) * (1.0f - g) + 2.0f * g * (1.0f - mu)
                   : (1.0f + g) * (1.0f + g) - 2.0f * g * (1.0f + mu);
}

static inline float phase_hg_eval(float g, float mu) {
  if (nv_fabs(g) < PHASE_HG_ISOTROPIC_EPS) return NV_INV_4PI;
  /* A cosine rebuilt from unit vectors can exceed 1 by a few ulps; near |g| = 1 that would turn the
   * denominator, (1−|g|)² + 2|g|(1∓μ), negative. */
  const float d = phase_hg_denominator(g, nv_fmin(1.0f, nv_fmax(-1.0f, mu)));
  return NV_INV_4PI * (1.0f - g) * (1.0f + g) / (d * nv_sqrt(d));
}

/* μ = cos θ drawn from HG by inverting its CDF (pbrt-v4 §11.3.1 form). */
static inline float phase_hg_sample_cos(float g, float u) {
  if (nv_fabs(g) < PHASE_HG_ISOTROPIC_EPS) return 1.0f - 2.0f * u;
  const float s = (1.0f - g) * (1.0f + g) / (1.0f - g + 2.0f * g * u);
  const float mu = (1.0f + g * g - s * s) / (2.0f * g);
  return nv_fmin(1.0f, nv_fmax(-1.0f, mu));
}

/* Kinds (PHASE_ISOTROPIC, PHASE_HG from structs.h) are dispatched by switch. An unknown kind gives
 * no scattering here; every kernel's entry reports it (scene_kinds.h, STATUS_UNKNOWN_KIND) and the
 * host never uploads one (render/kernel_features.h checks).
 * Scene specialisation (DESIGN.md "model only what a scene needs"; host/render/kernel_features.h):
 * -DPHASE_FIXED_ISOTROPIC or -DPHASE_FIXED_HG fixes the kind at build time, so the compiler folds
 * the switch (the host sets one only when the scene's medium has that phase function: the
 * arithmetic is the generic kernel's, bit for bit). Neither: the runtime `kind`. */
#if defined(PHASE_FIXED_ISOTROPIC)
#define PHASE_KIND(kind) PHASE_ISOTROPIC
#elif defined(PHASE_FIXED_HG)
#define PHASE_KIND(kind) PHASE_HG
#else
#define PHASE_KIND(kind) (kind)
#endif

static inline float phase_eval(int kind, float g, vec3 w_in, vec3 w_out) {
  switch (PHASE_KIND(kind)) {
    case PHASE_ISOTROPIC: return NV_INV_4PI;
    case PHASE_HG: return phase_hg_eval(g, vec3_dot(w_in, w_out));
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
}

/* Samples w_out given the propagation direction w_in; returns it and writes its pdf (0 for an
 * unknown kind: the path goes on unscattered and no MIS weight uses it). */
static inline vec3 phase_sample(int kind, float g, vec3 w_in, float u1, float u2, NV_PRIVATE float* pdf) {
  switch (PHASE_KIND(kind)) {
    case PHASE_ISOTROPIC: {
      const vec3 w_out = sample_direction_around(w_in, 1.0f - 2.0f * u1, u2);
      *pdf = NV_INV_4PI;
      return w_out;
    }
    case PHASE_HG: {
      const vec3 w_out = sample_direction_around(w_in, phase_hg_sample_cos(g, u1), u2);
      /* The pdf of the direction actually returned: for |g| near 1 the HG peak is a few float steps
       * of μ wide, and MIS needs the same value phase_pdf gives for this direction. */
      *pdf = phase_hg_eval(g, vec3_dot(w_in, w_out));
      return w_out;
    }
    default: *pdf = 0.0f; return w_in;
  }
}

/* The phase function's mean cosine (its first zonal coefficient): g for HG, 0 for isotropic (and an
 * unknown kind). */
static inline float phase_mean_cosine(int kind, float g) {
  switch (PHASE_KIND(kind)) {
    case PHASE_HG: return g;
    case PHASE_ISOTROPIC: return 0.0f;
    default: return 0.0f;
  }
}

static inline float phase_pdf(int kind, float g, vec3 w_in, vec3 w_out) {
  return phase_eval(kind, g, w_in, w_out);
}

#endif
