/* light_point.h: a point light: `corner` is its position, `radiance` its intensity I (W/sr),
 * isotropic. A delta light: next-event estimation alone reaches it, and no ray hits it. */
#ifndef NARVAL_LIGHT_POINT_H
#define NARVAL_LIGHT_POINT_H

#include "shared/light_sample.h"

static inline light_params light_point_make(light_params l, light_placement pl) {
  l.corner = vec3_to4(pl.position, 0.0f);
  l.type = LIGHT_POINT;
  return l;
}

static inline int light_point_sample(NV_CONSTANT const light_params* l, vec3 x, float u1, float u2,
                                     NV_PRIVATE light_sample* s) {
  (void)u1;
  (void)u2;
  const float d2 = light_aim(vec3_from4(l->corner), x, s);
  if (!(d2 > 0.0f)) return 0;
  s->radiance = vec3_scale(vec3_from4(l->radiance), 1.0f / d2);
  s->pdf = 0.0f;
  return 1;
}

static inline float light_point_hit(NV_CONSTANT const light_params* l, vec3 o, vec3 d, float t_min,
                                    NV_PRIVATE int* front) {
  (void)l, (void)o, (void)d, (void)t_min, (void)front;
  return NV_INFINITY;
}

static inline float light_point_pdf(NV_CONSTANT const light_params* l, vec3 d, float t) {
  (void)l, (void)d, (void)t;
  return 0.0f;
}

/* Nothing reaches a ray that escapes the scene: the light is met at a point of the scene or not at all. */
static inline vec3 light_point_escaped(NV_CONSTANT const light_params* l, vec3 d) {
  (void)l, (void)d;
  return vec3_splat(0.0f);
}

static inline vec3 light_point_axis(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE float* dist) {
  return light_axis_to(vec3_from4(l->corner), x, dist);
}

static inline int light_point_view_from(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE light_point_view* v) {
  const vec3 to = vec3_sub(vec3_from4(l->corner), x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0;
  v->dist = v->range = nv_sqrt(d2);
  v->range2 = d2;
  v->dir = vec3_scale(to, 1.0f / v->dist);
  v->intensity = vec3_from4(l->radiance);
  return 1;
}

/* Emitted power, 4π·I (mean over the channels): light selection by power. */
static inline float light_point_power(NV_CONSTANT const light_params* l) {
  return 4.0f * NV_PI * vec3_average(vec3_from4(l->radiance));
}

#endif
