/* tracking.h: null-collision free-flight and transmittance estimators (dissertation §4.2) against
 * a global majorant σ̄ >= max σt over the box and channels.
 *
 * Free flight: delta tracking (Algorithm 1). For a grey medium (σt equal in all channels) it is
 * the analogue walk: at a tentative collision, absorb with P = σa/σ̄, scatter with P = σs/σ̄, else
 * continue; the path throughput never changes. For chromatic σ it becomes spectral tracking (Kutz
 * et al. 2017, §4.2, history-aware average collision probabilities): P_x ∝ avg(σ_x ⊙ β) for
 * x in {a, s, n} and β ⊙= σ_x / (σ̄ P_x) on the chosen event, which is unbiased per channel and
 * reduces to the analogue walk when σ is grey.
 * Transmittance: ratio tracking (Algorithm 2), Tr ⊙= 1 − σt(x)/σ̄, per channel; closed form for a
 * homogeneous medium. */
#ifndef NARVAL_TRACKING_H
#define NARVAL_TRACKING_H

#include "shared/grid.h"
#include "shared/rng.h"
#include "shared/sampling.h"
#include "shared/structs.h"

/* A guard against endless walks (σ̄·length of ~10⁷ mean free paths); flagged in the status word. */
#define TRACKING_MAX_STEPS 10000000

#define TRACK_ESCAPED 0
#define TRACK_SCATTERED 1
#define TRACK_ABSORBED 2

/* Walks o + t·d (index-space origin and direction; t is the world-space ray parameter because d is
 * the world direction mapped by the same affine map) from t to t_max. On TRACK_SCATTERED, *t_out
 * is the collision and *beta has been reweighted (chromatic media only). */
static inline int tracking_delta(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 o, vec3 d, float t,
                                 float t_max, NV_PRIVATE rng_state* rng, NV_PRIVATE vec3* beta,
                                 NV_PRIVATE float* t_out, NV_PRIVATE uint* status) {
  const float sigma_bar = m->majorant;
  if (!(sigma_bar > 0.0f)) return TRACK_ESCAPED;
  const vec3 sa = vec3_from4(m->sigma_a), ss = vec3_from4(m->sigma_s);
  const int grey = m->grey;
  for (int step = 0; step < TRACKING_MAX_STEPS; ++step) {
    t += sample_exponential(rng_uniform(rng), sigma_bar);
    if (t >= t_max) return TRACK_ESCAPED;
    const float rho = grid_density(GRID_ARG, vec3_madd(o, d, t));
    const float u = rng_uniform(rng);
    if (grey) {
      const float pa = sa.x * rho / sigma_bar, ps = ss.x * rho / sigma_bar;
      if (u < pa) return TRACK_ABSORBED;
      if (u < pa + ps) {
        *t_out = t;
        return TRACK_SCATTERED;
      }
      continue;
    }
    const vec3 b = *beta;
    const vec3 sig_a = vec3_scale(sa, rho), sig_s = vec3_scale(ss, rho);
    const vec3 sig_n = vec3_sub(vec3_splat(sigma_bar), vec3_add(sig_a, sig_s));
    const float wa = vec3_average(vec3_mul(sig_a, b));
    const float ws = vec3_average(vec3_mul(sig_s, b));
    const float wn = vec3_average(vec3_mul(sig_n, b));
    const float c = wa + ws + wn;
    if (!(c > 0.0f)) return TRACK_ABSORBED; /* zero throughput: nothing left to carry */
    const float x = u * c;
    if (x < wa) return TRACK_ABSORBED;
    if (x < wa + ws) {
      *beta = vec3_scale(vec3_mul(b, sig_s), c / (sigma_bar * ws));
      *t_out = t;
      return TRACK_SCATTERED;
    }
    *beta = vec3_scale(vec3_mul(b, sig_n), c / (sigma_bar * wn));
  }
  *status |= STATUS_ITERATION_CAP;
  return TRACK_ABSORBED;
}

/* Ratio-tracking estimate of the transmittance along o + t·d over [t, t_max]. */
static inline vec3 tracking_ratio(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 o, vec3 d, float t,
                                  float t_max, NV_PRIVATE rng_state* rng, NV_PRIVATE uint* status) {
  vec3 tr = vec3_splat(1.0f);
  const float sigma_bar = m->majorant;
  if (!(sigma_bar > 0.0f)) return tr;
  const vec3 st = vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s));
  /* A homogeneous medium has the closed form: Beer-Lambert, no variance. */
  if (GRID_IS_HOMOGENEOUS(GRID_ARG)) return vec3_exp_neg(vec3_scale(st, nv_fmax(0.0f, t_max - t)));
  const float inv_bar = 1.0f / sigma_bar;
  for (int step = 0; step < TRACKING_MAX_STEPS; ++step) {
    t += sample_exponential(rng_uniform(rng), sigma_bar);
    if (t >= t_max) return tr;
    const float rho = grid_density(GRID_ARG, vec3_madd(o, d, t));
    tr = vec3_mul(tr, vec3_sub(vec3_splat(1.0f), vec3_scale(st, rho * inv_bar)));
    if (vec3_is_zero(tr)) return tr;
  }
  *status |= STATUS_ITERATION_CAP;
  return vec3_splat(0.0f);
}

#endif
