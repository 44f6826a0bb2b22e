/* march.h: what the real-time kernels (raymarch.cl, lobe.cl) take from the lights and the view: the
 * medium's own light, a light's in-scattering and shadow column (any light as its one point,
 * light_view_from; area lights: light_rectangle_area.h, the approximation DESIGN.md allows these
 * kernels, the path tracer integrating the true light), the view ray's background and segment. */
#ifndef NARVAL_MARCH_H
#define NARVAL_MARCH_H

#include "shared/emission.h"
#include "shared/light.h"
#include "shared/light_rectangle_area.h"
#include "shared/march_quadrature.h"
#include "shared/phase.h"

#ifdef EMISSION
/* The medium's own light along view segment `seg`, ∫ T(t) σa(t) Le(t) dt (emission.h), by the
 * energy-conserving step with S = σa·Le over `steps` midpoint samples of its occupied cells (exact for
 * S and σt constant over a step: an absorbing, emitting homogeneous slab gives Le·(1 − e^{−σa·d}) to
 * rounding). Stops after the step where every channel of T fell below t_stop (0: never): the rest adds
 * at most T·max(σa·Le/σt) < t_stop·max Le. For the Lobe Estimator, whose light estimate holds none;
 * the ray marcher adds σa·Le inside its own march. */
static inline vec3 march_emission(KERNEL_CONTEXT_PARAM, NV_PRIVATE const medium_segment* seg,
                                  int steps, float t_stop) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  const vec3 st_unit = medium_sigma_t(m);
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, seg, steps);
  vec3 L = vec3_splat(0.0f), T = vec3_splat(1.0f);
  float t;
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    const vec3 p = vec3_madd(seg->o, seg->d, t);
    const float rho = grid_density(KERNEL_CONTEXT_ARG, p);
    if (!(rho > 0.0f)) { /* nothing emits or attenuates there */
      if (rho != rho) *status |= STATUS_NAN;
      continue;
    }
    march_energy_conserving_step(&L, &T, emission_source(KERNEL_CONTEXT_ARG, p, rho), vec3_scale(st_unit, rho),
                                 it.delta);
    if (vec3_max_component(T) < t_stop) break;
  }
  *status |= it.status;
  return L;
}
#endif

/* Light l's unshadowed in-scattering at x per unit σs, Σ_j I_j·p(view_dir·dir_j)/d_j² (view_dir the
 * propagation before scattering): an area light over K×K points, any other as its one point. */
static inline vec3 march_light_phase_sum(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                         vec3 view_dir, int K) {
  if (light_has_area(l)) return light_rectangle_phase_sum(l, x, phase, view_dir, K);
  light_point_view v;
  if (!light_view_from(l, x, &v)) return vec3_splat(0.0f);
  return vec3_scale(v.intensity, phase_eval(phase, view_dir, v.dir) / v.range2);
}

/* The same with an area light's phase integrated exactly over its solid angle (K → ∞). */
static inline vec3 march_light_phase_integral(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                              vec3 view_dir) {
  if (light_has_area(l)) return light_rectangle_phase_integral(l, x, phase, view_dir);
  return march_light_phase_sum(l, x, phase, view_dir, 1);
}

/* The phase over a light per march_params.area_light_phase: K×K points or the exact integral. */
static inline vec3 march_light_phase(NV_CONSTANT const light_params* l, vec3 x, phase_params phase,
                                     vec3 view_dir, int area_light_phase, int K) {
  switch (area_light_phase) {
    case AREA_LIGHT_POINTS: return march_light_phase_sum(l, x, phase, view_dir, K);
    case AREA_LIGHT_EXACT: return march_light_phase_integral(l, x, phase, view_dir);
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry */
  }
}

/* Column density ∫ρ ds from x to light l over shadow_steps midpoint samples: an area light's effective
 * column over K×K points when K > 1 (light_rectangle_column), else to its one point (a rectangle's centre). */
static inline float march_light_column(KERNEL_CONTEXT_PARAM, NV_CONSTANT const light_params* l,
                                       vec3 x, int K, int shadow_steps, int weighting, vec3 view_dir) {
  NV_PRIVATE uint* status = &ctx->status;
  if (!light_known(LIGHT_KIND(l))) return 0.0f; /* unknown: sends nothing, reported at the entry */
  if (light_has_area(l) && K > 1)
    return light_rectangle_column(KERNEL_CONTEXT_ARG, l, x, K, shadow_steps, weighting, view_dir);
  switch (weighting) {
    case SHADOW_WEIGHTING_AREA:
    case SHADOW_WEIGHTING_PHASE: break; /* one point: nothing to weight */
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
  float d;
  const vec3 dir = light_axis(l, x, &d);
  if (!(d > 0.0f)) {
    if (d != d) *status |= STATUS_NAN;
    return 0.0f;
  }
  return march_column_density(KERNEL_CONTEXT_ARG, x, dir, d, shadow_steps);
}

/* A view ray's start, for the real-time kernels and the view cache's columns (ms_cache_view.h): *Lb,
 * what it sees with the medium removed (the front of the nearest light surface hit, black from behind,
 * else the background and the lights at infinity along it), and *seg, its segment through the box up to
 * that surface (an emitter hides the medium behind it: the path tracer's rule). 0: no medium on it. */
static inline int march_view(NV_CONSTANT const scene_params* s, NV_CONSTANT const light_params* lights, vec3 origin,
                             vec3 dir, NV_PRIVATE vec3* Lb, NV_PRIVATE medium_segment* seg) {
  float t_surf;
  int front = 0;
  const int hit = light_hit_nearest(lights, s->num_lights, origin, dir, 0.0f, -1, &t_surf, &front);
  if (hit >= 0) {
    *Lb = front ? vec3_from4(lights[hit].radiance) : vec3_splat(0.0f);
  } else {
    *Lb = vec3_from4(s->background);
    for (int i = 0; i < s->num_lights; ++i) *Lb = vec3_add(*Lb, light_escaped(&lights[i], dir));
  }
  return s->has_medium && medium_intersect(&s->medium, origin, dir, 0.0f, t_surf, seg);
}

#endif
