/* march.h: deterministic quadrature shared by the real-time kernels (raymarch.cl, lobe.cl).
 * Transmittance by midpoint sampling with true step lengths, all three channels (DESIGN.md:
 * "every step uses its true length"), and lights as points: a rectangle becomes a point at its
 * centre with intensity Le·A·max(0, cos θ_light), the approximation DESIGN.md allows for these
 * kernels (the path tracer always integrates the true area light). */
#ifndef NARVAL_MARCH_H
#define NARVAL_MARCH_H

#include "shared/grid.h"
#include "shared/medium.h"

/* σt at world point o + t·d of a medium segment (index-space origin and direction in `seg`). */
static inline vec3 march_sigma_t(NV_CONSTANT const medium_params* m, GRID_PARAM, NV_PRIVATE const medium_segment* seg,
                                 float t) {
  const float rho = grid_density(GRID_ARG, vec3_madd(seg->o, seg->d, t));
  return vec3_scale(vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s)), rho);
}

/* Optical depth τ from `origin` over `dist` along unit `dir`: `steps` equal steps over the part of
 * the segment inside the box, σt sampled at each step's midpoint, Σ σt·Δ. 0 outside the box. The
 * ray marcher's octaves need τ itself (exp(−bⁱτ)), which survives where exp(−τ) underflows. */
static inline vec3 march_optical_depth(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 origin, vec3 dir,
                                       float dist, int steps) {
  medium_segment seg;
  if (!medium_intersect(m, origin, dir, 0.0f, dist, &seg)) return vec3_splat(0.0f);
  const float dt = (seg.t1 - seg.t0) / (float)steps;
  vec3 tau = vec3_splat(0.0f);
  for (int i = 0; i < steps; ++i)
    tau = vec3_add(tau, march_sigma_t(m, GRID_ARG, &seg, seg.t0 + ((float)i + 0.5f) * dt));
  return vec3_scale(tau, dt);
}

/* Transmittance exp(−τ) over the same quadrature (1 outside the box). */
static inline vec3 march_transmittance(NV_CONSTANT const medium_params* m, GRID_PARAM, vec3 origin, vec3 dir,
                                       float dist, int steps) {
  return vec3_exp_neg(march_optical_depth(m, GRID_ARG, origin, dir, dist, steps));
}

/* A light as seen from x, as a point: unit direction to it, distance, and the intensity I (W/sr)
 * towards x, so the irradiance-like factor is I / dist². Returns 0 when it sends nothing to x. */
static inline int march_light_as_point(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE vec3* dir,
                                       NV_PRIVATE float* dist, NV_PRIVATE vec3* intensity) {
  vec3 p = vec3_from4(l->corner);
  vec3 I = vec3_from4(l->radiance);
  if (l->type == LIGHT_RECTANGLE)
    p = vec3_add(p, vec3_scale(vec3_add(vec3_from4(l->edge_u), vec3_from4(l->edge_v)), 0.5f));
  const vec3 to = vec3_sub(p, x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0;
  *dist = nv_sqrt(d2);
  *dir = vec3_scale(to, 1.0f / *dist);
  if (l->type == LIGHT_RECTANGLE) {
    const float cos_l = -vec3_dot(*dir, vec3_from4(l->normal));
    if (!(cos_l > 0.0f)) return 0;
    I = vec3_scale(I, l->normal.w * cos_l);
  }
  *intensity = I;
  return 1;
}

/* L_b for the real-time kernels: what the view ray would see with the medium removed, i.e. the
 * front of the nearest rectangle light it hits (black from behind), else the background. */
static inline vec3 march_background(NV_CONSTANT const scene_params* s, NV_CONSTANT const light_params* lights,
                                    vec3 origin, vec3 dir) {
  float t;
  int front = 0;
  const int hit = intersect_lights(lights, s->num_lights, origin, dir, 0.0f, -1, &t, &front);
  if (hit < 0) return vec3_from4(s->background);
  return front ? vec3_from4(lights[hit].radiance) : vec3_splat(0.0f);
}

#endif
