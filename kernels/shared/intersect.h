/* intersect.h: a ray against the medium's box (the lights' surfaces: light.h, light_hit). */
#ifndef NARVAL_INTERSECT_H
#define NARVAL_INTERSECT_H

#include "shared/structs.h"

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

#endif
