/* medium.h: where a world-space ray meets the medium box. The box is [0, dims] in grid index space;
 * the ray is mapped there once (origin and direction by the same affine map), which keeps the
 * world-space parameter t, so distances and σ stay in world units (DESIGN.md: a rotated or scaled
 * box is intersected in its local space). */
#ifndef NARVAL_MEDIUM_H
#define NARVAL_MEDIUM_H

#include "shared/intersect.h"

/* σt = σa + σs per unit density, per channel: the medium's extinction before the density. */
static inline vec3 medium_sigma_t(NV_CONSTANT const medium_params* m) {
  return vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s));
}

typedef struct medium_segment {
  vec3 o, d;      /* index-space origin and direction */
  float t0, t1;   /* world-parameter interval inside the box, clipped to [t_min, t_max] */
} medium_segment;

static inline int medium_intersect(NV_CONSTANT const medium_params* m, vec3 origin, vec3 dir, float t_min,
                                   float t_max, NV_PRIVATE medium_segment* seg) {
  seg->o = affine_point(m->world_to_index, origin);
  seg->d = affine_vector(m->world_to_index, dir);
  float t0, t1;
  if (!intersect_box(seg->o, seg->d, vec3_from4(m->dims), &t0, &t1)) return 0;
  seg->t0 = nv_fmax(t0, t_min);
  seg->t1 = nv_fmin(t1, t_max);
  return seg->t0 < seg->t1;
}

#endif
