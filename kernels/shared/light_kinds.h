/* light_kinds.h: the light kinds, one line each. The ids, the scene's primitive type names, the
 * unknown-kind checks (scene_kinds.h, render/kernel_features.cpp), the specialisation flag
 * (-DLIGHT_FIXED=id) and light.h's dispatch are all generated from this list; each kind's
 * mathematics lives in its own header, light_<prefix>.h, included by light.h.
 * Columns: id, value, the scene's primitive "type", header prefix; how many of the primitive's
 * transform.scale components must be non-zero (the rectangle's quad spans local X and Y; 0: only
 * the position is used; -1: no transform at all); 1 for an area the real-time kernels split into
 * K×K points or integrate the phase over (light_rectangle_area.h); the kind's own primitive keys:
 * a required non-zero vector (0: none) and a number in [lo, hi] with its default (0: none), handed
 * to light_<prefix>_make as light_placement.vector and .parameter. */
#ifndef NARVAL_LIGHT_KINDS_H
#define NARVAL_LIGHT_KINDS_H

#define LIGHT_KINDS(X)                                \
  X(LIGHT_RECTANGLE, 0, "rectangle", rectangle, 2, 1, 0, 0, 0.0f, 0.0f, 0.0f) \
  X(LIGHT_POINT, 1, "point", point, 0, 0, 0, 0, 0.0f, 0.0f, 0.0f) \
  X(LIGHT_DISTANT, 2, "distant", distant, -1, 0, "direction", "angularDiameter", 0.0f, 180.0f, 0.0f)

#define LIGHT_KIND_ID(id, value, name, prefix, scaled, area, vkey, key, lo, hi, fallback) id = value,
enum light_kind { LIGHT_KINDS(LIGHT_KIND_ID) };
#undef LIGHT_KIND_ID

/* 1 for a kind of the list: the kernels' entry check (scene_kinds.h) and the host's. */
#define LIGHT_KIND_KNOWN(id, value, name, prefix, scaled, area, vkey, key, lo, hi, fallback) case id:
static inline int light_known(int kind) {
  switch (kind) {
    LIGHT_KINDS(LIGHT_KIND_KNOWN) return 1;
    default: return 0;
  }
}
#undef LIGHT_KIND_KNOWN

#endif
