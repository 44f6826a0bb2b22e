/* light.h: next-event estimation towards rectangle and point lights. */
#ifndef NARVAL_LIGHT_H
#define NARVAL_LIGHT_H

#include "shared/intersect.h"
#include "shared/sampling.h"

typedef struct light_sample {
  vec3 dir;       /* unit, from the shading point towards the light */
  float dist;     /* to the sampled point */
  vec3 radiance;  /* Le (rectangle) or I/d² (point), before transmittance and phase */
  float pdf;      /* solid-angle pdf; 0 for a point light (a delta: no MIS) */
} light_sample;

/* Aims s at y from x (unit direction, distance); returns d², or 0 when y is x (or NaN). */
static inline float light_aim(vec3 y, vec3 x, NV_PRIVATE light_sample* s) {
  const vec3 to = vec3_sub(y, x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) return 0.0f;
  s->dist = nv_sqrt(d2);
  s->dir = vec3_scale(to, 1.0f / s->dist);
  return d2;
}

/* Samples light `l` as seen from x; returns 0 when it cannot contribute (back side, degenerate, an
 * unknown kind). */
static inline int light_sample_point(NV_CONSTANT const light_params* l, vec3 x, float u1, float u2,
                                     NV_PRIVATE light_sample* s) {
  switch (LIGHT_KIND(l)) {
    case LIGHT_POINT: {
      const float d2 = light_aim(vec3_from4(l->corner), x, s);
      if (!(d2 > 0.0f)) return 0;
      s->radiance = vec3_scale(vec3_from4(l->radiance), 1.0f / d2);
      s->pdf = 0.0f;
      return 1;
    }
    case LIGHT_RECTANGLE: {
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
    default: return 0; /* unknown: reported at the kernel's entry */
  }
}

/* Solid-angle pdf with which light_sample_point would pick the point hit at distance t along the
 * unit direction d (for MIS on phase-sampled rays that hit a rectangle light). */
static inline float light_pdf_rectangle(NV_CONSTANT const light_params* l, vec3 d, float t) {
  const float cos_l = -vec3_dot(d, vec3_from4(l->normal));
  return cos_l > 0.0f ? t * t / (cos_l * l->normal.w) : 0.0f;
}

/* A light's one point: a point light's position, a rectangle's centre (an unknown kind: its corner;
 * it sends nothing). Where the real-time kernels put a light (march_light_as_point) and where the
 * cache's guide aims (phase_guide.h). */
static inline vec3 light_centre(NV_CONSTANT const light_params* l) {
  const vec3 p = vec3_from4(l->corner);
  switch (LIGHT_KIND(l)) {
    case LIGHT_RECTANGLE: return vec3_add(p, vec3_scale(vec3_add(vec3_from4(l->edge_u), vec3_from4(l->edge_v)), 0.5f));
    case LIGHT_POINT: return p;
    default: return p;
  }
}

#endif
