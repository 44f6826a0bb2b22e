/* intersect.h: ray against the medium box and the rectangle lights. */
#ifndef NARVAL_INTERSECT_H
#define NARVAL_INTERSECT_H

#include "shared/structs.h"

/* Light kinds (LIGHT_RECTANGLE, LIGHT_POINT), dispatched by switch on LIGHT_KIND; an unknown kind
 * sends no light and is reported at the kernel's entry (scene_kinds.h). Scene specialisation
 * (host/render/kernel_features.h): -DLIGHTS_POINT_ONLY when the scene has no rectangle light (point
 * lights or none), -DLIGHTS_RECT_ONLY when all its lights are rectangles; the switches fold and,
 * with points only, intersect_lights returns "no hit" without looping. Same arithmetic as the
 * generic kernel. Neither: the runtime light_params.type. */
#if defined(LIGHTS_POINT_ONLY)
#define LIGHT_KIND(l) LIGHT_POINT
#elif defined(LIGHTS_RECT_ONLY)
#define LIGHT_KIND(l) LIGHT_RECTANGLE
#else
#define LIGHT_KIND(l) ((l)->type)
#endif
/* Only rectangles can be hit by a ray (a point light has no area). */
#define LIGHT_IS_RECT(l) (LIGHT_KIND(l) == LIGHT_RECTANGLE)

/* Slab test of o + t·d against the box [0, hi]. Returns 1 and the parametric interval when the ray
 * line meets the box. A zero direction component gives ±inf slab bounds (IEEE); fmin/fmax discard
 * the NaN that 0·inf produces for an origin exactly on a slab plane. */
static inline int intersect_box(vec3 o, vec3 d, vec3 hi, NV_PRIVATE float* t_near, NV_PRIVATE float* t_far) {
  const vec3 inv = vec3_make(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
  const vec3 t0 = vec3_mul(vec3_scale(o, -1.0f), inv);
  const vec3 t1 = vec3_mul(vec3_sub(hi, o), inv);
  const vec3 tmin = vec3_min(t0, t1), tmax = vec3_max(t0, t1);
  *t_near = nv_fmax(tmin.x, nv_fmax(tmin.y, tmin.z));
  *t_far = nv_fmin(tmax.x, nv_fmin(tmax.y, tmax.z));
  return *t_near <= *t_far;
}

/* Ray against the parallelogram corner + s·edge_u + t·edge_v, s,t in [0,1]. Returns the distance
 * (> t_min) or NV_INFINITY; *front is 1 when the ray arrives on the emitting side. */
static inline float intersect_rectangle(NV_CONSTANT const light_params* l, vec3 o, vec3 d, float t_min,
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

/* The nearest rectangle hit along the ray beyond t_min (index or -1), skipping light `skip`. */
static inline int intersect_lights(NV_CONSTANT const light_params* lights, int num_lights, vec3 o, vec3 d,
                                   float t_min, int skip, NV_PRIVATE float* t_hit, NV_PRIVATE int* front) {
  int hit = -1;
  *t_hit = NV_INFINITY;
#ifndef LIGHTS_POINT_ONLY /* else no rectangles: nothing to hit */
  for (int i = 0; i < num_lights; ++i) {
    if (i == skip) continue;
    if (!LIGHT_IS_RECT(&lights[i])) continue;
    int f = 0;
    const float t = intersect_rectangle(&lights[i], o, d, t_min, &f);
    if (t < *t_hit) {
      *t_hit = t;
      *front = f;
      hit = i;
    }
  }
#endif
  return hit;
}

#endif
