/* sampling.h: warps from uniform numbers to distributions, each with its pdf. */
#ifndef NARVAL_SAMPLING_H
#define NARVAL_SAMPLING_H

#include "shared/vec3.h"

/* Exponential free flight with rate sigma: pdf sigma·exp(-sigma·t). u in [0,1) keeps log finite. */
static inline float sample_exponential(float u, float sigma) { return -nv_log(1.0f - u) / sigma; }

/* Uniform direction on the unit sphere, pdf 1/(4π). */
static inline vec3 sample_uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = nv_sqrt(nv_fmax(0.0f, 1.0f - z * z));
  const float phi = 2.0f * NV_PI * u2;
  return vec3_make(r * nv_cos(phi), r * nv_sin(phi), z);
}

/* Concentric map of the unit square onto the unit disk (Shirley & Chiu 1997), pdf 1/π. */
static inline void sample_concentric_disk(float u1, float u2, NV_PRIVATE float* x, NV_PRIVATE float* y) {
  const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) {
    *x = 0.0f;
    *y = 0.0f;
    return;
  }
  float r, phi;
  if (nv_fabs(a) > nv_fabs(b)) {
    r = a;
    phi = (NV_PI / 4.0f) * (b / a);
  } else {
    r = b;
    phi = (NV_PI / 2.0f) - (NV_PI / 4.0f) * (a / b);
  }
  *x = r * nv_cos(phi);
  *y = r * nv_sin(phi);
}

/* Direction with cosine `cos_theta` to unit axis `w` and azimuth 2π·u. */
static inline vec3 sample_direction_around(vec3 w, float cos_theta, float u) {
  const float sin_theta = nv_sqrt(nv_fmax(0.0f, 1.0f - cos_theta * cos_theta));
  const float phi = 2.0f * NV_PI * u;
  vec3 t, b;
  vec3_basis(w, &t, &b);
  return vec3_add(vec3_add(vec3_scale(t, sin_theta * nv_cos(phi)), vec3_scale(b, sin_theta * nv_sin(phi))),
                  vec3_scale(w, cos_theta));
}

/* Power heuristic, β = 2 (Veach 1997), one sample per strategy; both pdfs 0 gives weight 0, not 0/0. */
static inline float mis_power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

#endif
