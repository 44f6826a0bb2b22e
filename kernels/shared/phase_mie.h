/* phase_mie.h: Mie scattering by water droplets of diameter d (µm), approximated as in Jendersie
 * and d'Eon, "An Approximate Mie Scattering Function for Fog and Cloud Rendering" (SIGGRAPH 2023
 * Talks): a blend of Henyey-Greenstein and Draine's phase function,
 *   p(μ) = (1 − w_D)·p_HG(μ; g_HG) + w_D·p_D(μ; g_D, α),
 *   p_D(μ; g, α) = p_HG(μ; g)·(1 + αμ²)/N,  N = 1 + α(1 + 2g²)/3,
 * whose four constants the paper fits to Lorenz-Mie theory as functions of d (valid for
 * 0.1 ≤ d ≤ 50 µm, the registry's range). coef = (g_HG, g_D, α, w_D); both lobes are normalised
 * over the sphere, so the blend is. */
#ifndef NARVAL_PHASE_MIE_H
#define NARVAL_PHASE_MIE_H

#include "shared/phase_hg.h"

/* The paper's fits (its eqs. 4-7), in three ranges of d. */
static inline phase_params phase_mie_make(float d) {
  float g_hg, g_d, alpha, w_d;
  if (d >= 5.0f) {
    g_hg = nv_exp(-0.0990567f / (d - 1.67154f));
    g_d = nv_exp(-2.20679f / (d + 3.91029f) - 0.428934f);
    alpha = nv_exp(3.62489f - 8.29288f / (d + 5.52825f));
    w_d = nv_exp(-0.599085f / (d - 0.641583f) - 0.665888f);
  } else {
    const float l = nv_log(d);
    if (d >= 1.5f) {
      const float ll = nv_log(l);
      g_hg = 0.0604931f * ll + 0.940256f;
      g_d = 0.500411f - 0.081287f / (-2.0f * l + nv_tan(l) + 1.27551f);
      alpha = 7.30354f * l + 6.31675f;
      w_d = 0.026914f * (l - nv_cos(5.68947f * (ll - 0.0292149f))) + 0.376475f;
    } else {
      g_hg = 0.862f - 0.143f * l * l;
      g_d = 0.379685f * nv_cos(1.19692f * nv_cos((l - 0.238604f) * (l + 1.00667f) / (0.507522f - 0.15677f * l)) +
                               1.37932f * l + 0.0625835f) +
            0.344213f;
      alpha = 250.0f;
      w_d = 0.146209f * nv_cos(3.38707f * l + 2.11193f) + 0.316072f + 0.0778917f * l;
    }
  }
  phase_params p;
  p.coef.x = g_hg;
  p.coef.y = g_d;
  p.coef.z = alpha;
  p.coef.w = w_d;
  p.kind = PHASE_MIE;
  p.pad0 = p.pad1 = p.pad2 = 0;
  return p;
}

/* The fits hold d inside its range; nothing to clamp. */
static inline float phase_mie_clamp(float d) { return d; }

static inline float phase_mie_draine_norm(float g, float alpha) { return 1.0f + alpha * (1.0f + 2.0f * g * g) / 3.0f; }

static inline float phase_mie_draine_eval(float g, float alpha, float mu) {
  return phase_hg_eval(g, mu) * (1.0f + alpha * mu * mu) / phase_mie_draine_norm(g, alpha);
}

static inline float phase_mie_eval_mu(phase_params p, float mu) {
  const float w = p.coef.w;
  return (1.0f - w) * phase_hg_eval(p.coef.x, mu) + w * phase_mie_draine_eval(p.coef.y, p.coef.z, mu);
}

/* Draine's cap integral relative to HG's: S_D(μ) = 2π∫_μ^1 p_D = S_HG(μ)·(1 + αQ/12)/N with
 * S_HG(μ) = (1 + g)(1 − μ)/(s(s + 1 − g)), s = √(1 + g² − 2gμ). Integrating μ'²·p_HG by parts and
 * writing 1 − μ' through q = 2(1 − μ)/(s + 1 − g) (so that 1 − μ = q(s + 1 − g)/2 carries no
 * cancellation) gives Q = (1 − g)g q³ + 4(1 − g)²q² − 12(1 − g)q + 12; g = 0 gives the
 * isotropic-times-(1 + αμ²) integral (1 − μ) + α(1 − μ³)/3, and μ = −1 gives Q = 4 + 8g², S = 1. */
static inline float phase_mie_draine_cap_factor(float g, float alpha, float mu) {
  const float s = nv_sqrt(phase_hg_denominator(g, mu));
  const float q = 2.0f * (1.0f - mu) / (s + 1.0f - g);
  const float h = 1.0f - g;
  const float Q = ((h * g * q + 4.0f * h * h) * q - 12.0f * h) * q + 12.0f;
  return (1.0f + alpha * Q / 12.0f) / phase_mie_draine_norm(g, alpha);
}

/* S_D(μ), the probability that a Draine sample lies above μ. */
static inline float phase_mie_draine_above(float g, float alpha, float mu) {
  const float s = nv_sqrt(phase_hg_denominator(g, mu));
  return (1.0f + g) * (1.0f - mu) / (s * (s + 1.0f - g)) * phase_mie_draine_cap_factor(g, alpha, mu);
}

/* μ from Draine's phase function with the uniform u: solves S_D(μ) = 1 − u (μ grows with u, as
 * HG's sampler does) by Newton's method kept inside a shrinking bracket [lo, hi], starting from
 * HG's inverse for the same g; a step that leaves the bracket bisects. The paper inverts the CDF
 * in closed form (a quartic); this root finder reaches the μ whose CDF is u to a few float steps
 * (24 iterations at most; far fewer on average: bench/RESULTS.md), without the quartic's cancellation in float, and
 * the pdf a caller uses is the phase function's value at the μ returned. */
static inline float phase_mie_draine_sample(float g, float alpha, float u) {
  const float target = 1.0f - u;
  float lo = -1.0f, hi = 1.0f;
  float mu = phase_hg_sample_cos(g, u);
  for (int i = 0; i < 24; ++i) {
    const float f = phase_mie_draine_above(g, alpha, mu) - target; /* decreasing in μ */
    if (nv_fabs(f) <= 3.0e-7f) break; /* a few float steps of the CDF: as close as it resolves */
    if (f > 0.0f)
      lo = mu;
    else
      hi = mu;
    const float slope = 2.0f * NV_PI * phase_mie_draine_eval(g, alpha, mu); /* −dS_D/dμ */
    float next = slope > 0.0f ? mu + f / slope : 0.5f * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5f * (lo + hi);
    const float step = nv_fabs(next - mu);
    mu = next;
    if (step < 2.384185791e-7f) break; /* 2^-22 */
  }
  return mu;
}

/* The blend is sampled by picking a lobe with u, then reusing u's remainder inside it: u < w_D
 * draws from Draine with u/w_D, else HG with (u − w_D)/(1 − w_D) (so w_D = 0 is HG bit for bit). */
static inline float phase_mie_sample_mu(phase_params p, float u) {
  const float w = p.coef.w;
  if (u < w) return phase_mie_draine_sample(p.coef.y, p.coef.z, u / w);
  return phase_hg_sample_cos(p.coef.x, nv_fmin((u - w) / (1.0f - w), 1.0f));
}

/* The blend's mean cosine; Draine's is g(1 + α(3 + 2g²)/5)/N. */
static inline float phase_mie_mean_cosine(phase_params p) {
  const float g = p.coef.y, alpha = p.coef.z;
  const float draine = g * (1.0f + alpha * (3.0f + 2.0f * g * g) / 5.0f) / phase_mie_draine_norm(g, alpha);
  return (1.0f - p.coef.w) * p.coef.x + p.coef.w * draine;
}

static inline float phase_mie_cap_over_sin2(phase_params p, float mu, float one_plus) {
  const float hg = phase_hg_cap_over_sin2_g(p.coef.x, mu, one_plus);
  const float draine = phase_hg_cap_over_sin2_g(p.coef.y, mu, one_plus) * phase_mie_draine_cap_factor(p.coef.y, p.coef.z, mu);
  return (1.0f - p.coef.w) * hg + p.coef.w * draine;
}

/* The forward peak is HG's: it falls to half within about 1 − |g_HG| rad. */
static inline float phase_mie_width(phase_params p) { return 1.0f - nv_fabs(p.coef.x); }

/* Both lobes' anisotropy times c (the octaves' g·cⁱ; −1 mirrors: Draine's 1 + αμ² is even). */
static inline phase_params phase_mie_scaled(phase_params p, float c) {
  p.coef.x = p.coef.x * c;
  p.coef.y = p.coef.y * c;
  return p;
}

#endif
