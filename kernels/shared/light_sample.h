/* light_sample.h: what a light kind answers (light_<kind>.h; light.h dispatches): a sampled
 * direction for next-event estimation, and the light as one point for the real-time kernels. */
#ifndef NARVAL_LIGHT_SAMPLE_H
#define NARVAL_LIGHT_SAMPLE_H

#include "shared/sampling.h"
#include "shared/structs.h"

typedef struct light_sample {
  vec3 dir;       /* unit, from the shading point towards the light */
  float dist;     /* to the sampled point: the shadow ray's length */
  vec3 radiance;  /* Le (an area light) or the irradiance (a delta light), before Tr and phase */
  float pdf;      /* solid-angle pdf; 0 for a delta light (no MIS) */
} light_sample;

/* The light as one point seen from x (the real-time kernels' light, dissertation §4.2): unit direction,
 * shadow ray length, and intensity I towards x, falling off as I/r²: r² = range·range in the ray marcher's
 * and lobe's own sums, range2 (the squared distance as computed) in the area sums, so each keeps its arithmetic. */
typedef struct light_point_view {
  vec3 dir;
  float dist;
  vec3 intensity;
  float range;
  float range2;
} light_point_view;

/* Where the host places a light: the primitive's transform on the unit quad [-0.5, 0.5]² in local XY (corner,
 * edges), its unit -Z through the rotation alone (normal, the emitting side) and position; the kind's own keys
 * (light_kinds.h: vector, parameter); the radius of a sphere around the medium (power of a light at infinity).
 * Each kind takes what it needs (light_<kind>_make). */
typedef struct light_placement {
  vec3 position, corner, edge_u, edge_v, normal, vector;
  float area, parameter, scene_radius;
} light_placement;

/* Aims s at y from x (unit direction, distance); returns d², or 0 when y is x (or NaN). */
static inline float light_aim(vec3 y, vec3 x, NV_PRIVATE light_sample* s) {
  const vec3 to = vec3_sub(y, x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0.0f;
  s->dist = nv_sqrt(d2);
  s->dir = vec3_scale(to, 1.0f / s->dist);
  return d2;
}

/* Unit direction from x to y (0 when y is x) and *dist = |y − x|. */
static inline vec3 light_axis_to(vec3 y, vec3 x, NV_PRIVATE float* dist) {
  const vec3 to = vec3_sub(y, x);
  const float d = vec3_length(to);
  *dist = d;
  return d > 0.0f ? vec3_scale(to, 1.0f / d) : vec3_splat(0.0f);
}

#endif
