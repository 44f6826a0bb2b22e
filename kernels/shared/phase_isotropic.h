/* phase_isotropic.h: the isotropic phase function, p = 1/(4π): the phase registry's operations
 * (phase_kinds.h; phase.h dispatches to them). It has no constants. */
#ifndef NARVAL_PHASE_ISOTROPIC_H
#define NARVAL_PHASE_ISOTROPIC_H

#include "shared/structs.h"

static inline float phase_isotropic_clamp(float unused) { return unused; }

static inline phase_params phase_isotropic_make(float unused) {
  phase_params p;
  p.coef.x = p.coef.y = p.coef.z = p.coef.w = 0.0f;
  p.kind = PHASE_ISOTROPIC;
  p.pad0 = p.pad1 = p.pad2 = 0;
  (void)unused;
  return p;
}

static inline float phase_isotropic_eval_mu(phase_params p, float mu) {
  (void)p;
  (void)mu;
  return NV_INV_4PI;
}

static inline float phase_isotropic_sample_mu(phase_params p, float u) {
  (void)p;
  return 1.0f - 2.0f * u;
}

static inline float phase_isotropic_mean_cosine(phase_params p) {
  (void)p;
  return 0.0f;
}

/* G(μ)/(1 − μ²) of the cap integral (phase_polygon.h): G = (1 − μ)/(4π). */
static inline float phase_isotropic_cap_over_sin2(phase_params p, float mu, float one_plus) {
  (void)p;
  (void)mu;
  return NV_INV_4PI / one_plus;
}

/* The angle (rad) over which p changes appreciably: none, so a whole radian (phase_polygon.h). */
static inline float phase_isotropic_width(phase_params p) {
  (void)p;
  return 1.0f;
}

static inline phase_params phase_isotropic_scaled(phase_params p, float c) {
  (void)c;
  return p;
}

#endif
