/* light_distant.h: a distant light (the sun): light arriving from infinitely far along one
 * direction, or from a cone of directions of uniform radiance. The primitive's "direction" is the
 * way the light travels (world space), its emitter's albedo the irradiance E on a surface facing
 * it, and "angularDiameter" (degrees) the cone's full angle: 0 a delta light, 0.53 the sun.
 * A cone of half-angle θc with radiance L gives E = ∫ L cos θ dω = π L sin²θc, so L = E/(π sin²θc);
 * next-event estimation samples it uniformly in solid angle (pdf 1/(2π(1 − cos θc))), a ray that
 * escapes the scene inside it sees L (MIS-weighted), and a delta light is reached by next-event
 * estimation alone. Stored: corner = the unit direction of travel; edge_u = (cos θc, 1 − cos θc,
 * L/E, the scene radius); radiance = E. The real-time kernels take it as one direction (the cone's
 * axis) with irradiance E, its shadow ray running out of the medium's box. */
#ifndef NARVAL_LIGHT_DISTANT_H
#define NARVAL_LIGHT_DISTANT_H

#include "shared/light_sample.h"

static inline light_params light_distant_make(light_params l, light_placement pl) {
  const float half_angle = 0.5f * pl.parameter * (NV_PI / 180.0f);
  const float s = nv_sin(0.5f * half_angle);
  const float sin_c = nv_sin(half_angle);
  l.corner = vec3_to4(vec3_normalize(pl.vector), 0.0f);
  /* 1 − cos θc = 2 sin²(θc/2): no cancellation for the sun's 0.27°. */
  l.edge_u.x = nv_cos(half_angle);
  l.edge_u.y = 2.0f * s * s;
  l.edge_u.z = half_angle > 0.0f ? 1.0f / (NV_PI * sin_c * sin_c) : 0.0f;
  l.edge_u.w = pl.scene_radius;
  l.type = LIGHT_DISTANT;
  return l;
}

/* Unit direction from any point towards the light: against its travel. */
static inline vec3 light_distant_towards(NV_CONSTANT const light_params* l) { return vec3_scale(vec3_from4(l->corner), -1.0f); }

static inline int light_distant_sample(NV_CONSTANT const light_params* l, vec3 x, float u1, float u2,
                                       NV_PRIVATE light_sample* s) {
  (void)x;
  s->dist = NV_INFINITY;
  const float one_minus_cos = l->edge_u.y;
  if (!(one_minus_cos > 0.0f)) { /* a delta light: its one direction, the irradiance itself */
    s->dir = light_distant_towards(l);
    s->radiance = vec3_from4(l->radiance);
    s->pdf = 0.0f;
    return 1;
  }
  s->dir = sample_direction_around(light_distant_towards(l), 1.0f - u1 * one_minus_cos, u2);
  s->radiance = vec3_scale(vec3_from4(l->radiance), l->edge_u.z);
  s->pdf = 1.0f / (2.0f * NV_PI * one_minus_cos);
  return 1;
}

/* No surface: a ray meets the light only by escaping the scene (light_distant_escaped). */
static inline float light_distant_hit(NV_CONSTANT const light_params* l, vec3 o, vec3 d, float t_min,
                                      NV_PRIVATE int* front) {
  (void)l, (void)o, (void)d, (void)t_min, (void)front;
  return NV_INFINITY;
}

/* 1 when direction d lies in the cone (never for a delta light). */
static inline int light_distant_in_cone(NV_CONSTANT const light_params* l, vec3 d) {
  return l->edge_u.y > 0.0f && vec3_dot(d, light_distant_towards(l)) >= l->edge_u.x;
}

static inline float light_distant_pdf(NV_CONSTANT const light_params* l, vec3 d, float t) {
  (void)t;
  return light_distant_in_cone(l, d) ? 1.0f / (2.0f * NV_PI * l->edge_u.y) : 0.0f;
}

/* The radiance a ray escaping the scene along d sees: L inside the cone, else nothing. */
static inline vec3 light_distant_escaped(NV_CONSTANT const light_params* l, vec3 d) {
  return light_distant_in_cone(l, d) ? vec3_scale(vec3_from4(l->radiance), l->edge_u.z) : vec3_splat(0.0f);
}

static inline vec3 light_distant_axis(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE float* dist) {
  (void)x;
  *dist = NV_INFINITY;
  return light_distant_towards(l);
}

/* The axis with the irradiance E; no fall-off (range 1). */
static inline int light_distant_view_from(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE light_point_view* v) {
  (void)x;
  v->dir = light_distant_towards(l);
  v->dist = NV_INFINITY;
  v->intensity = vec3_from4(l->radiance);
  v->range = v->range2 = 1.0f;
  return 1;
}

/* The power through a disc of the scene's radius r facing it, π r² E (mean over the channels). */
static inline float light_distant_power(NV_CONSTANT const light_params* l) {
  return NV_PI * l->edge_u.w * l->edge_u.w * vec3_average(vec3_from4(l->radiance));
}

#endif
