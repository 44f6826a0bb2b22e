/* scene_kinds.h: every kind the kernels dispatch on by switch, checked once at each kernel's entry.
 * The switches (phase.h, light.h, march.h, emission.h, pathtrace.h) give an unknown kind no contribution; this check makes it
 * visible: STATUS_UNKNOWN_KIND in the status word, which the host reports. The host validates kinds
 * before it uploads a scene (render/kernel_features.h), so the bit means host and kernels out of
 * step, never bad input. */
#ifndef NARVAL_SCENE_KINDS_H
#define NARVAL_SCENE_KINDS_H

#include "shared/structs.h"

static inline uint scene_kinds_status(NV_CONSTANT const scene_params* s, NV_CONSTANT const light_params* lights) {
  uint status = 0u;
  if (s->has_medium) {
    if (!phase_known(s->medium.phase.kind)) status |= STATUS_UNKNOWN_KIND;
    const int emits = emission_emits(s->medium.emission.kind);
    if (emits < 0) status |= STATUS_UNKNOWN_KIND;
#ifndef EMISSION
    if (emits > 0) status |= STATUS_UNKNOWN_KIND; /* an emitting medium in a kernel built without emission */
#endif
  }
  switch (s->light_sampling) {
    case LIGHT_SAMPLING_ALL:
    case LIGHT_SAMPLING_ONE: break;
    default: status |= STATUS_UNKNOWN_KIND;
  }
  for (int i = 0; i < s->num_lights; ++i) {
    if (!light_known(lights[i].type)) status |= STATUS_UNKNOWN_KIND;
  }
  return status;
}

/* The real-time kernels' own kinds, per parameter block (structs.h): STATUS_UNKNOWN_KIND for a value
 * no switch knows. The host never uploads one; a kernel built against other headers would. */
static inline uint march_kinds_status(NV_PRIVATE const march_params* mp) {
  uint status = 0u;
  switch (mp->area_light_phase) {
    case AREA_LIGHT_POINTS:
    case AREA_LIGHT_EXACT: break;
    default: status |= STATUS_UNKNOWN_KIND;
  }
  switch (mp->shadow_weighting) {
    case SHADOW_WEIGHTING_AREA:
    case SHADOW_WEIGHTING_PHASE: break;
    default: status |= STATUS_UNKNOWN_KIND;
  }
  return status;
}

static inline uint lobe_kinds_status(NV_PRIVATE const lobe_params* lp) {
  switch (lp->variant) {
    case LOBE_EQ7:
    case LOBE_CORRECTED: return 0u;
    default: return STATUS_UNKNOWN_KIND;
  }
}

static inline uint ms_cache_kinds_status(NV_PRIVATE const ms_cache_params* mc) {
  uint status = 0u;
  switch (mc->closure) {
    case MS_CACHE_CLOSURE_LINEAR:
    case MS_CACHE_CLOSURE_CAMERA: break;
    default: status |= STATUS_UNKNOWN_KIND;
  }
  switch (mc->layout) {
    case MS_CACHE_LAYOUT_GRID:
    case MS_CACHE_LAYOUT_VIEW: break;
    default: status |= STATUS_UNKNOWN_KIND;
  }
  return status;
}

#endif
