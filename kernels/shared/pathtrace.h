/* pathtrace.h: one path-traced sample of a pixel (DESIGN.md "pathtrace"; dissertation §4.2-4.3).
 * Free flight by delta/spectral tracking; next-event estimation at every real scattering event
 * (ratio-tracked shadow rays to every light or one picked per event, light_select.h; lights with an
 * extent MIS-combined with phase sampling by the power heuristic, delta lights by NEE alone: light.h);
 * Russian roulette on shadow rays as the scene asks; `max_bounces` real events. A ray adds the light
 * surface it hits (opaque: a rectangle's back is black), or on escaping the background and the lights
 * at infinity along it. No Russian roulette on the throughput (pbrt-v4 has one): it could never play,
 * as the grey walk keeps β = 1 and spectral tracking avg(β) = 1 (an event multiplies β by
 * σ_x·c/(σ̄·avg(σ_x ⊙ β)), c = σ̄·avg(β)), so β is never below 1 in every channel; absorption already
 * ends paths in proportion to the energy they lose. Status bits, majorants, counters: tracking.h,
 * plus STATUS_NAN for a non-finite sample (written as 0) or phase value and STATUS_NEGATIVE_PDF for a
 * phase-sampled direction without positive pdf. Emission (-DEMISSION) seen after k scattering events
 * is added by that segment's walk (tracking.h): light of k bounces, as an emitter or background reached. */
#ifndef NARVAL_PATHTRACE_H
#define NARVAL_PATHTRACE_H

#include "shared/camera.h"
#include "shared/light.h"
#include "shared/light_select.h"
#include "shared/medium.h"
#include "shared/phase.h"
#include "shared/tracking.h"

/* Transmittance from x to the light point at distance `dist` along unit dir: 0 if another
 * rectangle is in the way, else ratio tracking through the medium. */
static inline vec3 pathtrace_shadow(KERNEL_CONTEXT_PARAM, int light_index, vec3 x, vec3 dir, float dist,
                                    NV_PRIVATE rng_state* rng) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  float t_block;
  int front;
  if (light_hit_nearest(lights, s->num_lights, x, dir, 0.0f, light_index, &t_block, &front) >= 0 &&
      t_block < dist)
    return vec3_splat(0.0f);
  medium_segment seg;
  if (!s->has_medium || !medium_intersect(&s->medium, x, dir, 0.0f, dist, &seg)) return vec3_splat(1.0f);
  return tracking_ratio(KERNEL_CONTEXT_ARG, seg.o, seg.d, seg.t0, seg.t1, s->shadow_roulette, rng);
}

/* Light i's next-event estimate at scattering point x for a path arriving along w_in, aimed at the
 * light point (u1, u2) picks, divided by the probability of aiming at it (light_select_prob, as a
 * rectangle hit's MIS weight uses); the shadow ray draws from rng. */
static inline vec3 pathtrace_light_at(KERNEL_CONTEXT_PARAM, int i, vec3 x, vec3 w_in, float u1, float u2,
                                      NV_PRIVATE rng_state* rng) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  const float prob = light_select_prob(s, lights, i);
  light_sample ls;
  if (!light_sample_point(&lights[i], x, u1, u2, &ls)) return vec3_splat(0.0f);
  const float f = phase_eval(s->medium.phase, w_in, ls.dir);
  if (!(f > 0.0f)) {
    if (f != f) ctx->status |= STATUS_NAN; /* e.g. a NaN g: not dropped silently */
    return vec3_splat(0.0f);
  }
  const vec3 tr = pathtrace_shadow(KERNEL_CONTEXT_ARG, i, x, ls.dir, ls.dist, rng);
  if (vec3_is_zero(tr)) return vec3_splat(0.0f);
  /* Point light: Le·f·Tr·I/d² / prob. Rectangle: Le·f·Tr/(prob·pdf_light) weighted against the
   * direction sampling, whose pdf is f (sampling is exact). */
  const float light_pdf = prob * ls.pdf;
  const float w =
      light_pdf > 0.0f ? mis_power_heuristic(light_pdf, f) / light_pdf : 1.0f / prob;
  return vec3_scale(vec3_mul(ls.radiance, tr), f * w);
}

/* pathtrace_light_at with the light point drawn from rng. */
static inline vec3 pathtrace_light(KERNEL_CONTEXT_PARAM, int i, vec3 x, vec3 w_in, NV_PRIVATE rng_state* rng) {
  const float u1 = rng_uniform(rng), u2 = rng_uniform(rng);
  return pathtrace_light_at(KERNEL_CONTEXT_ARG, i, x, w_in, u1, u2, rng);
}

/* pathtrace_direct with its leading numbers given: u_select picks the light (one per event), (u1, u2)
 * the point aimed at on every light; shadow rays draw from rng. For callers stratifying them over many
 * estimates at one point (ms_cache_build.h); the path tracer draws all from rng in turn (a light's
 * numbers after the previous shadow ray, none when no light can be picked), which this cannot share. */
static inline vec3 pathtrace_direct_at(KERNEL_CONTEXT_PARAM, vec3 x, vec3 w_in, float u_select, float u1, float u2,
                                       NV_PRIVATE rng_state* rng) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  switch (s->light_sampling) {
    case LIGHT_SAMPLING_ALL: {
      vec3 sum = vec3_splat(0.0f);
      for (int i = 0; i < s->num_lights; ++i)
        sum = vec3_add(sum, pathtrace_light_at(KERNEL_CONTEXT_ARG, i, x, w_in, u1, u2, rng));
      return sum;
    }
    case LIGHT_SAMPLING_ONE: {
      const int i = light_select(ctx->lights, s->num_lights, u_select);
      return i < 0 ? vec3_splat(0.0f) : pathtrace_light_at(KERNEL_CONTEXT_ARG, i, x, w_in, u1, u2, rng);
    }
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry (scene_kinds.h) */
  }
}

/* Direct light at a scattering point x for a path arriving along w_in: every light, or one picked
 * by light_select (scene_params.light_sampling). */
static inline vec3 pathtrace_direct(KERNEL_CONTEXT_PARAM, vec3 x, vec3 w_in, NV_PRIVATE rng_state* rng) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  switch (s->light_sampling) {
    case LIGHT_SAMPLING_ALL: {
      vec3 sum = vec3_splat(0.0f);
      for (int i = 0; i < s->num_lights; ++i)
        sum = vec3_add(sum, pathtrace_light(KERNEL_CONTEXT_ARG, i, x, w_in, rng));
      return sum;
    }
    case LIGHT_SAMPLING_ONE: {
      const int i = light_select(lights, s->num_lights, rng_uniform(rng));
      if (i < 0) return vec3_splat(0.0f);
      return pathtrace_light(KERNEL_CONTEXT_ARG, i, x, w_in, rng);
    }
    default: return vec3_splat(0.0f); /* unknown: reported at the kernel's entry (scene_kinds.h) */
  }
}

/* What the lights at infinity send along −d to a ray escaping along d, each MIS-weighted against its
 * next-event estimate as a light surface hit is (prev_phase_pdf 0: the camera's ray, unweighted). */
static inline vec3 pathtrace_escaped(KERNEL_CONTEXT_PARAM, vec3 d, float prev_phase_pdf) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  vec3 sum = vec3_splat(0.0f);
  for (int i = 0; i < s->num_lights; ++i) {
    const vec3 Le = light_escaped(&lights[i], d);
    if (vec3_is_zero(Le)) continue;
    const float w = prev_phase_pdf > 0.0f
                        ? mis_power_heuristic(prev_phase_pdf, light_select_prob(s, lights, i) *
                                                                  light_pdf(&lights[i], d, NV_INFINITY))
                        : 1.0f;
    sum = vec3_add(sum, vec3_scale(Le, w));
  }
  return sum;
}

/* Radiance arriving at o from −d by one path: the ray o + t·d, then up to max_bounces real scattering
 * events. unscattered_emitters 0 drops the emitter the first segment may hit (the lights' unscattered
 * light, which the ray marcher adds itself: ms_cache.h), keeping the background. first_phase_pdf: 0
 * when o is the camera, else the phase pdf d was drawn with at event o (whose next-event estimate the
 * caller made), for the MIS weight of an emitter the first segment hits. Non-finite results are left
 * to the caller's check. */
static inline vec3 pathtrace_radiance(KERNEL_CONTEXT_PARAM, vec3 o, vec3 d, int unscattered_emitters,
                                      float first_phase_pdf, NV_PRIVATE rng_state* rng_in) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  NV_PRIVATE uint* status = &ctx->status;
  rng_state rng = *rng_in;
  vec3 L = vec3_splat(0.0f), beta = vec3_splat(1.0f);
  float prev_phase_pdf = first_phase_pdf; /* 0: the ray left the camera, no MIS on what it hits */
  int depth = 0;
  /* Loops: at most max_bounces + 1 iterations, each ending the path or a real event taking depth
   * towards max_bounces (checked before the increment: bounces = INT_MAX cannot overflow), each walk
   * capped (tracking.h). Reaching max_bounces is the requested truncation, not a status. */
  for (;;) {
    float t_surf;
    int front = 0;
    const int light_hit = light_hit_nearest(lights, s->num_lights, o, d, 0.0f, -1, &t_surf, &front);
    medium_segment seg;
    if (s->has_medium && medium_intersect(&s->medium, o, d, 0.0f, t_surf, &seg)) {
      float t_hit;
      const int event = tracking_delta(KERNEL_CONTEXT_ARG, seg.o, seg.d, seg.t0, seg.t1, &rng, &beta,
                                       &t_hit TRACK_EMISSION_ARG(&L));
      if (event == TRACK_ABSORBED) break;
      if (event == TRACK_SCATTERED) {
        if (depth >= s->max_bounces) break;
        ++depth;
        const vec3 x = vec3_madd(o, d, t_hit);
        L = vec3_add(L, vec3_mul(beta, pathtrace_direct(KERNEL_CONTEXT_ARG, x, d, &rng)));
        const float u1 = rng_uniform(&rng), u2 = rng_uniform(&rng);
        float pdf;
        d = phase_sample(s->medium.phase, d, u1, u2, &pdf);
        if (!(pdf > 0.0f)) { /* sampled a direction it gives no density (or NaN): unusable */
          *status |= STATUS_NEGATIVE_PDF;
          if (pdf != pdf) *status |= STATUS_NAN;
          break;
        }
        o = x;
        prev_phase_pdf = pdf;
        continue;
      }
    }
    if (light_hit >= 0) {
      if (front && (unscattered_emitters || depth > 0)) {
        float w = 1.0f;
        if (prev_phase_pdf > 0.0f)
          w = mis_power_heuristic(prev_phase_pdf, light_select_prob(s, lights, light_hit) *
                                                      light_pdf(&lights[light_hit], d, t_surf));
        L = vec3_add(L, vec3_scale(vec3_mul(beta, vec3_from4(lights[light_hit].radiance)), w));
      }
    } else {
      vec3 Le = vec3_from4(s->background);
      if (unscattered_emitters || depth > 0) Le = vec3_add(Le, pathtrace_escaped(KERNEL_CONTEXT_ARG, d, prev_phase_pdf));
      L = vec3_add(L, vec3_mul(beta, Le));
    }
    break;
  }
  *rng_in = rng;
  return L;
}

static inline vec3 pathtrace_sample(KERNEL_CONTEXT_PARAM, int px, int py, uint sample) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE uint* status = &ctx->status;
  const uint pixel = (uint)py * (uint)s->camera.width + (uint)px;
  rng_state rng = rng_init(s->seed, pixel, sample);
  const float jx = rng_uniform(&rng), jy = rng_uniform(&rng);
  const float lu = rng_uniform(&rng), lv = rng_uniform(&rng);
  const ray3 cam = camera_ray(&s->camera, (float)px + jx, (float)py + jy, lu, lv);
  const vec3 L = pathtrace_radiance(KERNEL_CONTEXT_ARG, cam.origin, cam.dir, 1, 0.0f, &rng);
  return status_finite_or_zero(status, L);
}

#endif
