/* phase_hg.h: Henyey-Greenstein, p(μ) = (1 − g²) / (4π (1 + g² − 2gμ)^{3/2}), normalised over the sphere;
 * coef.x = g. The dissertation's printed form (§2.6.2) drops the 3/2 exponent: a typo. Sampling inverts the
 * CDF exactly (pdf == eval, weight 1). The raw functions of g (phase_hg_eval, phase_hg_sample_cos) also
 * serve Mie's forward lobe. */
#ifndef NARVAL_PHASE_HG_H
#define NARVAL_PHASE_HG_H

#include "shared/sampling.h"
#include "shared/structs.h"

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

/* HG's cap integral over sin²θ, G(μ)/(1 − μ²) with G(μ) = ∫_μ^1 p (phase_polygon.h derives it):
 * (1 + g)/(2π·s·(s + 1 − g)·(1 + μ)), s = √(1 + g² − 2gμ); one_plus = max(1 + μ, 1e-7). */
static inline float phase_hg_cap_over_sin2_g(float g, float mu, float one_plus) {
  const float s = nv_sqrt(phase_hg_denominator(g, mu));
  return (1.0f + g) / (2.0f * NV_PI * s * (s + 1.0f - g) * one_plus);
}

/* ±1 would make HG a delta function (its density 0 except at μ = ±1): held just inside. */
static inline float phase_hg_clamp(float g) { return nv_fabs(g) >= 1.0f ? (g > 0.0f ? 0.9999f : -0.9999f) : g; }

static inline phase_params phase_hg_make(float g) {
  phase_params p;
  p.coef.x = g;
  p.coef.y = p.coef.z = p.coef.w = 0.0f;
  p.kind = PHASE_HG;
  p.pad0 = p.pad1 = p.pad2 = 0;
  return p;
}

static inline float phase_hg_eval_mu(phase_params p, float mu) { return phase_hg_eval(p.coef.x, mu); }
static inline float phase_hg_sample_mu(phase_params p, float u) { return phase_hg_sample_cos(p.coef.x, u); }
static inline float phase_hg_mean_cosine(phase_params p) { return p.coef.x; }
static inline float phase_hg_cap_over_sin2(phase_params p, float mu, float one_plus) {
  return phase_hg_cap_over_sin2_g(p.coef.x, mu, one_plus);
}
/* HG falls to half its peak within about 1 − |g| rad. */
static inline float phase_hg_width(phase_params p) { return 1.0f - nv_fabs(p.coef.x); }
/* The anisotropy times c: the octaves' g·cⁱ (raymarch.h), and −1 mirrors (phase_polygon.h). */
static inline phase_params phase_hg_scaled(phase_params p, float c) {
  p.coef.x = p.coef.x * c;
  return p;
}

#endif
