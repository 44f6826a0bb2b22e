/* phase.h: phase functions, dispatched over the registry (phase_kinds.h) to each kind's header. θ is the
 * angle between the propagation directions before (w_in) and after (w_out) scattering: g > 0 scatters forward
 * (DESIGN.md, physics conventions). Each kind samples μ = cos θ exactly (pdf = value, eval/pdf = 1). An unknown
 * kind scatters nothing; each kernel's entry reports it (scene_kinds.h, STATUS_UNKNOWN_KIND) and the host never
 * uploads one (render/kernel_features.h). -DPHASE_FIXED=<id> (scene specialisation, DESIGN.md) fixes the kind
 * so the switches fold; the host sets it only to the scene's kind (bit for bit as generic). */
#ifndef NARVAL_PHASE_H
#define NARVAL_PHASE_H

#include "shared/phase_hg.h"
#include "shared/phase_isotropic.h"
#include "shared/phase_mie.h"
#include "shared/sampling.h"

#ifdef PHASE_FIXED
#define PHASE_KIND(kind) PHASE_FIXED
#else
#define PHASE_KIND(kind) (kind)
#endif

/* One switch case per kind for each operation, generated from the list. */
#define PHASE_CASE_CLAMP(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_clamp(x);
#define PHASE_CASE_MAKE(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_make(x);
#define PHASE_CASE_EVAL(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_eval_mu(p, mu);
#define PHASE_CASE_SAMPLE(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_sample_mu(p, u);
#define PHASE_CASE_MEAN(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_mean_cosine(p);
#define PHASE_CASE_CAP(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_cap_over_sin2(p, mu, one_plus);
#define PHASE_CASE_WIDTH(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_width(p);
#define PHASE_CASE_SCALED(id, v, n, k, key, lo, hi, d) case id: return phase_##k##_scaled(p, c);

/* The kind's parameter (its registry key's value) as the kind uses it. */
static inline float phase_clamp(int kind, float x) {
  switch (kind) {
    PHASE_KINDS(PHASE_CASE_CLAMP)
    default: return x;
  }
}

/* The `kind` phase function with parameter x (phase_kinds.h); an unknown kind keeps its id for the checks. */
static inline phase_params phase_make(int kind, float x) {
  switch (kind) {
    PHASE_KINDS(PHASE_CASE_MAKE)
    default: {
      phase_params p = phase_isotropic_make(0.0f);
      p.kind = kind;
      return p;
    }
  }
}

/* p(μ), μ = cos θ. */
static inline float phase_eval_mu(phase_params p, float mu) {
  switch (PHASE_KIND(p.kind)) {
    PHASE_KINDS(PHASE_CASE_EVAL)
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
}

/* d ln p / dμ by central differences (one-sided at μ = ±1), for any kind: the score of a direction drawn
 * from p about an axis, as the axis turns (ms_cache_reproject.h, "Direction"). */
static inline float phase_log_slope(phase_params p, float mu) {
  const float h = 1e-3f, lo = nv_fmax(-1.0f, mu - h), hi = nv_fmin(1.0f, mu + h), here = phase_eval_mu(p, mu);
  return here > 0.0f ? (phase_eval_mu(p, hi) - phase_eval_mu(p, lo)) / ((hi - lo) * here) : 0.0f;
}

/* μ drawn from p with one uniform number u. */
static inline float phase_sample_mu(phase_params p, float u) {
  switch (PHASE_KIND(p.kind)) {
    PHASE_KINDS(PHASE_CASE_SAMPLE)
    default: return 1.0f;
  }
}

/* The mean cosine (the first zonal coefficient): g for HG, 0 for isotropic (and an unknown kind).
 * Where a method needs one g (the Lobe Estimator's lobe, the cache's HG closure), this is it. */
static inline float phase_mean_cosine(phase_params p) {
  switch (PHASE_KIND(p.kind)) {
    PHASE_KINDS(PHASE_CASE_MEAN)
    default: return 0.0f;
  }
}

/* The cap integral G(μ) = ∫_μ^1 p(μ') dμ' over 1 − μ² (phase_polygon.h), μ clamped to [−1, 1] and
 * one_plus = max(1 + μ, 1e-7): finite at the pole, unbounded only at μ = −1. */
static inline float phase_cap_over_sin2(phase_params p, float mu) {
  mu = nv_fmin(1.0f, nv_fmax(-1.0f, mu));
  const float one_plus = nv_fmax(1.0f + mu, 1e-7f);
  switch (PHASE_KIND(p.kind)) {
    PHASE_KINDS(PHASE_CASE_CAP)
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
}

/* The angle (rad) within which p falls to about half its peak (phase_polygon.h's panels). */
static inline float phase_width(phase_params p) {
  switch (PHASE_KIND(p.kind)) {
    PHASE_KINDS(PHASE_CASE_WIDTH)
    default: return 1.0f;
  }
}

/* The same kind with its anisotropy scaled by c (each lobe's g times c): the ray marcher's octaves
 * (g·cⁱ, Wrenninge et al. 2013), and c = −1 mirrors it, p'(μ) = p(−μ) (phase_polygon.h). */
static inline phase_params phase_scaled(phase_params p, float c) {
  switch (PHASE_KIND(p.kind)) {
    PHASE_KINDS(PHASE_CASE_SCALED)
    default: return p;
  }
}

static inline float phase_eval(phase_params p, vec3 w_in, vec3 w_out) { return phase_eval_mu(p, vec3_dot(w_in, w_out)); }

/* Samples w_out given the propagation direction w_in; returns it and writes its pdf (0 for an unknown
 * kind: the path goes on unscattered and no MIS weight uses it). The pdf is evaluated at the returned
 * direction: for a peak a few float steps of μ wide (HG at |g| near 1), MIS needs phase_pdf's value. */
static inline vec3 phase_sample(phase_params p, vec3 w_in, float u1, float u2, NV_PRIVATE float* pdf) {
  if (!phase_known(PHASE_KIND(p.kind))) {
    *pdf = 0.0f;
    return w_in;
  }
  const vec3 w_out = sample_direction_around(w_in, phase_sample_mu(p, u1), u2);
  *pdf = phase_eval(p, w_in, w_out);
  return w_out;
}

static inline float phase_pdf(phase_params p, vec3 w_in, vec3 w_out) { return phase_eval(p, w_in, w_out); }

#endif
