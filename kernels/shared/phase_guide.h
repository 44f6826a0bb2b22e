/* phase_guide.h: a scattering event whose next direction is drawn from a one-sample mixture of the
 * phase function and a guide, HG lobes about the directions towards the scene's lights:
 *   pdf(ω) = (1 − share)·p(w_in·ω) + share·(1/n)·Σ_k p_HG(g_guide, a_k·ω),
 * over the scene's n lights, a_k the unit direction from the event towards light k's centre. The
 * path's weight is then p(w_in·ω)/pdf(ω) instead of 1, and every MIS weight that names the
 * direction-sampling density uses pdf(ω) (the next-event estimate at the event and the emitter the
 * next segment hits): the estimate stays unbiased for any share < 1 (the phase's own share covers
 * every direction it scatters into).
 * Why: where a cloud is lit from the camera's side, the in-scattering towards the camera is mostly
 * light that a point between the event and the light scattered forwards (towards the event), which
 * arrives from the light's side; the phase function about the camera ray sends the path away from
 * it (a back-scatter of p ≈ 0.002 at g 0.9), so those paths are rare and heavy. A lobe about a_k
 * is where such light arrives from, broadened by the scattering on the way (the caller picks its g:
 * ms_cache_build.h). share = 0 is the phase function alone, with its arithmetic unchanged (the path
 * tracer's events). */
#ifndef NARVAL_PHASE_GUIDE_H
#define NARVAL_PHASE_GUIDE_H

#include "shared/light.h"
#include "shared/phase.h"

typedef struct phase_guide {
  vec3 x;      /* the event's point (the axes a_k run from it to the lights' centres) */
  float share; /* the guide's share of the mixture, in [0, 1); 0: none */
  float g;     /* the guide lobes' HG parameter */
} phase_guide;

/* The guide that draws nothing: the phase function alone. */
static inline phase_guide phase_guide_none(void) {
  phase_guide gd;
  gd.x = vec3_splat(0.0f);
  gd.share = 0.0f;
  gd.g = 0.0f;
  return gd;
}

/* Unit direction from x to light l's centre (a point light's position); 0 when x is there. */
static inline vec3 phase_guide_axis(NV_CONSTANT const light_params* l, vec3 x) {
  float d;
  return light_axis(l, x, &d);
}

/* The guide's own density at ω: (1/n)·Σ_k p_HG(g, a_k·ω). */
static inline float phase_guide_lobes_pdf(NV_CONSTANT const light_params* lights, int num_lights, phase_guide gd,
                                          vec3 w) {
  float q = 0.0f;
  for (int k = 0; k < num_lights; ++k) q += phase_hg_eval(gd.g, vec3_dot(phase_guide_axis(&lights[k], gd.x), w));
  return q / (float)num_lights;
}

/* The mixture's density at ω for a phase value f = p(w_in·ω) there; f itself without a guide (and
 * without lights, where the guide has nothing to aim at). */
static inline float phase_guide_pdf(NV_CONSTANT const light_params* lights, int num_lights, phase_guide gd, float f,
                                    vec3 w) {
  if (!(gd.share > 0.0f) || num_lights < 1) return f;
  return (1.0f - gd.share) * f + gd.share * phase_guide_lobes_pdf(lights, num_lights, gd, w);
}

/* Draws ω from the mixture with (u1, u2) (u1 picks the component and is stretched back to [0, 1),
 * so stratified numbers stay stratified within each) and u3 (the light, for the guide); writes the
 * phase value *f = p(w_in·ω) and the mixture's density *pdf. */
static inline vec3 phase_guide_sample(NV_CONSTANT const light_params* lights, int num_lights, phase_params phase,
                                      vec3 w_in, phase_guide gd, float u1, float u2, float u3, NV_PRIVATE float* f,
                                      NV_PRIVATE float* pdf) {
  vec3 w;
  const int guided = gd.share > 0.0f && num_lights > 0;
  if (guided && u1 < gd.share) {
    const int k = (int)nv_fmin((float)(num_lights - 1), u3 * (float)num_lights);
    /* HG about a_k whatever the medium's phase kind (PHASE_KIND may fix it): phase_guide_lobes_pdf's */
    w = sample_direction_around(phase_guide_axis(&lights[k], gd.x), phase_hg_sample_cos(gd.g, u1 / gd.share), u2);
    *f = phase_eval(phase, w_in, w);
  } else {
    const float v1 = guided ? (u1 - gd.share) / (1.0f - gd.share) : u1;
    w = phase_sample(phase, w_in, v1, u2, f);
  }
  *pdf = phase_guide_pdf(lights, num_lights, gd, *f, w);
  return w;
}

#endif
