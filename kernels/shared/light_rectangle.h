/* light_rectangle.h: a one-sided rectangle light corner + s·edge_u + t·edge_v, s, t in [0, 1], emitting
 * `radiance` along `normal` (normal.w: the area). Next-event estimation samples its area uniformly; a ray
 * meeting its front sees Le (MIS-weighted by light_pdf). Real-time K×K points, exact phase: light_rectangle_area.h. */
#ifndef NARVAL_LIGHT_RECTANGLE_H
#define NARVAL_LIGHT_RECTANGLE_H

#include "shared/light_sample.h"

static inline light_params light_rectangle_make(light_params l, light_placement pl) {
  l.corner = vec3_to4(pl.corner, 0.0f);
  l.edge_u = vec3_to4(pl.edge_u, 0.0f);
  l.edge_v = vec3_to4(pl.edge_v, 0.0f);
  l.normal = vec3_to4(pl.normal, pl.area);
  l.type = LIGHT_RECTANGLE;
  return l;
}

static inline int light_rectangle_sample(NV_CONSTANT const light_params* l, vec3 x, float u1, float u2,
                                         NV_PRIVATE light_sample* s) {
  const vec3 y = vec3_add(vec3_from4(l->corner), vec3_add(vec3_scale(vec3_from4(l->edge_u), u1),
                                                           vec3_scale(vec3_from4(l->edge_v), u2)));
  const float d2 = light_aim(y, x, s);
  if (!(d2 > 0.0f)) return 0;
  /* Uniform on the area A, converted to solid angle: pdf = d² / (cos θ_l · A). */
  const float cos_l = -vec3_dot(s->dir, vec3_from4(l->normal));
  if (!(cos_l > 0.0f)) return 0;
  s->radiance = vec3_from4(l->radiance);
  s->pdf = d2 / (cos_l * l->normal.w);
  return 1;
}

/* Ray o + t·d against the parallelogram: the distance (> t_min) or NV_INFINITY; *front: 1 on the emitting side. */
static inline float light_rectangle_hit(NV_CONSTANT const light_params* l, vec3 o, vec3 d, float t_min,
                                        NV_PRIVATE int* front) {
  const vec3 n = vec3_from4(l->normal);
  const float denom = vec3_dot(d, n);
  if (denom == 0.0f) return NV_INFINITY;
  const vec3 corner = vec3_from4(l->corner);
  const float t = vec3_dot(vec3_sub(corner, o), n) / denom;
  if (!(t > t_min)) return NV_INFINITY;
  const vec3 rel = vec3_sub(vec3_madd(o, d, t), corner);
  const vec3 eu = vec3_from4(l->edge_u), ev = vec3_from4(l->edge_v);
  const float s = vec3_dot(rel, eu) / vec3_dot(eu, eu);
  const float r = vec3_dot(rel, ev) / vec3_dot(ev, ev);
  if (s < 0.0f || s > 1.0f || r < 0.0f || r > 1.0f) return NV_INFINITY;
  *front = denom < 0.0f;
  return t;
}

/* The solid-angle pdf with which light_rectangle_sample picks the point hit at distance t along d. */
static inline float light_rectangle_pdf(NV_CONSTANT const light_params* l, vec3 d, float t) {
  const float cos_l = -vec3_dot(d, vec3_from4(l->normal));
  return cos_l > 0.0f ? t * t / (cos_l * l->normal.w) : 0.0f;
}

static inline vec3 light_rectangle_centre(NV_CONSTANT const light_params* l) {
  return vec3_add(vec3_from4(l->corner), vec3_scale(vec3_add(vec3_from4(l->edge_u), vec3_from4(l->edge_v)), 0.5f));
}

/* Nothing reaches a ray that escapes the scene: the light is met at a point of the scene or not at all. */
static inline vec3 light_rectangle_escaped(NV_CONSTANT const light_params* l, vec3 d) {
  (void)l, (void)d;
  return vec3_splat(0.0f);
}

static inline vec3 light_rectangle_axis(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE float* dist) {
  return light_axis_to(light_rectangle_centre(l), x, dist);
}

/* The centre, with the intensity Le·A·cos θ_l of the whole rectangle towards x (0 behind it). */
static inline int light_rectangle_view_from(NV_CONSTANT const light_params* l, vec3 x,
                                            NV_PRIVATE light_point_view* v) {
  const vec3 to = vec3_sub(light_rectangle_centre(l), x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0;
  v->dist = v->range = nv_sqrt(d2);
  v->range2 = d2;
  v->dir = vec3_scale(to, 1.0f / v->dist);
  const float cos_l = -vec3_dot(v->dir, vec3_from4(l->normal));
  if (!(cos_l > 0.0f)) return 0;
  v->intensity = vec3_scale(vec3_from4(l->radiance), l->normal.w * cos_l);
  return 1;
}

/* Emitted power, π·A·Le (mean over the channels): light selection by power. */
static inline float light_rectangle_power(NV_CONSTANT const light_params* l) {
  return NV_PI * l->normal.w * vec3_average(vec3_from4(l->radiance));
}

#endif
