/* light_select.h: which light the path tracer's next-event estimation aims at. With
 * LIGHT_SAMPLING_ALL every light gets a shadow ray at every scattering event; with
 * LIGHT_SAMPLING_ONE one light is picked with probability P_i = light_params.select_prob and its
 * estimate divided by P_i (pbrt-v4's light samplers, §12.6): unbiased for any P_i > 0 on every
 * light that can contribute, and one shadow ray per event instead of N. The host chooses P_i
 * (host/render/light_selection.h: in proportion to power or to the light's estimated fluence
 * over the medium). MIS against phase sampling then weighs the light strategy's density P_i·pdf_i
 * (pathtrace.h), so a rectangle hit by a phase-sampled ray uses the same P_i. */
#ifndef NARVAL_LIGHT_SELECT_H
#define NARVAL_LIGHT_SELECT_H

#include "shared/structs.h"

/* The light whose [cdf_{i-1}, cdf_i) holds u, cdf_i = P_0 + … + P_i summed here; the last light with
 * a positive probability when rounding leaves u at or above the last cdf. -1 when no light has a
 * positive probability. */
static inline int light_select(NV_CONSTANT const light_params* lights, int num_lights, float u) {
  int last = -1;
  float cdf = 0.0f;
  for (int i = 0; i < num_lights; ++i) {
    if (!(lights[i].select_prob > 0.0f)) continue;
    cdf += lights[i].select_prob;
    if (u < cdf) return i;
    last = i;
  }
  return last;
}

/* The probability with which next-event estimation aims at light i: 1 when every light gets a
 * shadow ray (each is its own strategy), else its selection probability. */
static inline float light_select_prob(NV_CONSTANT const scene_params* s, NV_CONSTANT const light_params* lights,
                                      int i) {
  switch (s->light_sampling) {
    case LIGHT_SAMPLING_ALL: return 1.0f;
    case LIGHT_SAMPLING_ONE: return lights[i].select_prob;
    default: return 0.0f; /* unknown: reported at the kernel's entry (scene_kinds.h) */
  }
}

#endif
