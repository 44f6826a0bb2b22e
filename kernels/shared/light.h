/* light.h: the lights, dispatched over the registry (light_kinds.h) to each kind's header. An unknown
 * kind sends no light; every kernel's entry reports it (scene_kinds.h, STATUS_UNKNOWN_KIND) and the host
 * never uploads one (render/kernel_features.h). Scene specialisation (host/render/kernel_features.h):
 * -DLIGHT_FIXED=<id> when every light is of that kind, so the switches fold (a kind no ray can hit leaves
 * light_hit_nearest nothing to do); same arithmetic as the generic kernel. */
#ifndef NARVAL_LIGHT_H
#define NARVAL_LIGHT_H

#include "shared/light_distant.h"
#include "shared/light_point.h"
#include "shared/light_rectangle.h"

#ifdef LIGHT_FIXED
#define LIGHT_KIND(l) LIGHT_FIXED
#else
#define LIGHT_KIND(l) ((l)->type)
#endif

#define LIGHT_CASE_MAKE(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_make(l, pl);
#define LIGHT_CASE_SAMPLE(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_sample(l, x, u1, u2, s);
#define LIGHT_CASE_HIT(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_hit(l, o, d, t_min, front);
#define LIGHT_CASE_PDF(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_pdf(l, d, t);
#define LIGHT_CASE_AXIS(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_axis(l, x, dist);
#define LIGHT_CASE_AREA(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return ar;
#define LIGHT_CASE_VIEW(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_view_from(l, x, v);
#define LIGHT_CASE_ESCAPED(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_escaped(l, d);
#define LIGHT_CASE_POWER(id, val, nm, k, sc, ar, vk, key, lo, hi, fb) case id: return light_##k##_power(l);

/* A `kind` light of `radiance` (its emitter's albedo) placed by pl (light_sample.h); unknown kinds keep their id. */
static inline light_params light_make(int kind, vec3 radiance, light_placement pl) {
  light_params l;
  l.corner = l.edge_u = l.edge_v = l.normal = vec3_to4(vec3_splat(0.0f), 0.0f);
  l.radiance = vec3_to4(radiance, 0.0f);
  l.type = kind;
  l.select_prob = 0.0f;
  l.pad0 = l.pad1 = 0;
  switch (kind) {
    LIGHT_KINDS(LIGHT_CASE_MAKE)
    default: return l;
  }
}

/* Samples light l from x for next-event estimation; 0 when it cannot contribute (back side, degenerate, unknown). */
static inline int light_sample_point(NV_CONSTANT const light_params* l, vec3 x, float u1, float u2,
                                     NV_PRIVATE light_sample* s) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_SAMPLE)
    default: return 0; /* unknown: reported at the kernel's entry */
  }
}

/* Where o + t·d (t > t_min) meets l's surface, else NV_INFINITY (delta: always); *front: 1 on the emitting side. */
static inline float light_hit(NV_CONSTANT const light_params* l, vec3 o, vec3 d, float t_min, NV_PRIVATE int* front) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_HIT)
    default: return NV_INFINITY;
  }
}

/* The solid-angle pdf with which light_sample_point picks the direction d that meets the light at
 * distance t (MIS for the phase-sampled rays that hit it); 0 for a delta light. */
static inline float light_pdf(NV_CONSTANT const light_params* l, vec3 d, float t) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_PDF)
    default: return 0.0f;
  }
}

/* The radiance of light l that a ray escaping the scene along d sees (a light at infinity). */
static inline vec3 light_escaped(NV_CONSTANT const light_params* l, vec3 d) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_ESCAPED)
    default: return vec3_splat(0.0f);
  }
}

/* Unit direction from x to the light's centre (0 when x is there) and *dist, the distance: the
 * real-time shadow ray of a light taken as one point. */
static inline vec3 light_axis(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE float* dist) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_AXIS)
    default: *dist = 0.0f; return vec3_splat(0.0f);
  }
}

/* 1 for a light with an area the real-time kernels split (light_rectangle_area.h). */
static inline int light_has_area(NV_CONSTANT const light_params* l) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_AREA)
    default: return 0;
  }
}

/* The light as one point seen from x (light_point_view); 0 when it sends nothing to x. */
static inline int light_view_from(NV_CONSTANT const light_params* l, vec3 x, NV_PRIVATE light_point_view* v) {
  switch (LIGHT_KIND(l)) {
    LIGHT_KINDS(LIGHT_CASE_VIEW)
    default: return 0; /* unknown: reported at the kernel's entry */
  }
}

/* Emitted power (mean over the channels), for light selection by power (render/light_selection). */
static inline float light_power(NV_CONSTANT const light_params* l) {
  switch (l->type) {
    LIGHT_KINDS(LIGHT_CASE_POWER)
    default: return 0.0f;
  }
}

/* The nearest light surface along the ray beyond t_min (index or -1), skipping light `skip`. */
static inline int light_hit_nearest(NV_CONSTANT const light_params* lights, int num_lights, vec3 o, vec3 d,
                                    float t_min, int skip, NV_PRIVATE float* t_hit, NV_PRIVATE int* front) {
  int hit = -1;
  *t_hit = NV_INFINITY;
  for (int i = 0; i < num_lights; ++i) {
    if (i == skip) continue;
    int f = 0;
    const float t = light_hit(&lights[i], o, d, t_min, &f);
    if (t < *t_hit) {
      *t_hit = t;
      *front = f;
      hit = i;
    }
  }
  return hit;
}

#endif
