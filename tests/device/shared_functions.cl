/* shared_functions.cl: evaluates shared kernel functions (the headers in kernels/shared/) on the device for a
 * batch of inputs, so tests/device/shared_functions_test.cpp can compare them with the host's
 * values of the very same code. One work-item per input; every kernel takes the batch size n.
 * Build with -DMEDIUM_HOMOGENEOUS: grid.h then reads density 1 (the host's grid_view with NULL
 * data), which is what the tracking kernels compare against. */
#include "shared/accum.h"
#include "shared/camera.h"
#include "shared/intersect.h"
#include "shared/light.h"
#include "shared/march.h"
#include "shared/ms_cache.h"
#include "shared/phase.h"
#include "shared/rng.h"
#include "shared/sampling.h"
#include "shared/scene_kinds.h"
#include "shared/tracking.h"

/* in: 3 floats per item (a sample's RGB), each added to words that start at start[0..7] -> the
 * ACCUM_WORDS words after accum_add_sample */
__kernel void sf_accum_add_sample(__global const float* in, __global const ulong* start, __global ulong* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  ulong words[ACCUM_WORDS];
  for (int w = 0; w < ACCUM_WORDS; ++w) words[w] = start[w];
  accum_add_sample(words, vec3_make(in[3 * i], in[3 * i + 1], in[3 * i + 2]));
  for (int w = 0; w < ACCUM_WORDS; ++w) out[ACCUM_WORDS * i + w] = words[w];
}

/* in: g[i], mu[i] -> phase_hg_eval */
__kernel void sf_phase_hg_eval(__global const float* g, __global const float* mu, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i < n) out[i] = phase_hg_eval(g[i], mu[i]);
}

/* in: g[i], u[i] -> phase_hg_sample_cos */
__kernel void sf_phase_hg_sample_cos(__global const float* g, __global const float* u, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i < n) out[i] = phase_hg_sample_cos(g[i], u[i]);
}

/* in: 6 floats per item (g, w_in.xyz, u1, u2) -> 4 floats (w_out.xyz, pdf) of phase_sample(HG) */
__kernel void sf_phase_sample(__global const float* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  __global const float* a = in + 6 * i;
  float pdf = 0.0f;
  const vec3 w = phase_sample(phase_make(PHASE_HG, a[0]), vec3_make(a[1], a[2], a[3]), a[4], a[5], &pdf);
  out[4 * i + 0] = w.x;
  out[4 * i + 1] = w.y;
  out[4 * i + 2] = w.z;
  out[4 * i + 3] = pdf;
}

/* in: 6 uints per item (counter[4], key[2]) -> 4 uints of Philox4x32-10 */
__kernel void sf_philox(__global const uint* in, __global uint* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  uint c[4], r[4];
  for (int k = 0; k < 4; ++k) c[k] = in[6 * i + k];
  rng_philox4x32(c, in[6 * i + 4], in[6 * i + 5], r);
  for (int k = 0; k < 4; ++k) out[4 * i + k] = r[k];
}

/* in: 3 uints per item (seed, pixel, sample) -> the first 8 rng_uniform draws of that stream */
__kernel void sf_rng_uniform(__global const uint* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  rng_state r = rng_init(in[3 * i], in[3 * i + 1], in[3 * i + 2]);
  for (int k = 0; k < 8; ++k) out[8 * i + k] = rng_uniform(&r);
}

/* in: 4 floats per item (px, py, lens_u, lens_v) -> 6 floats (origin.xyz, dir.xyz) */
__kernel void sf_camera_ray(__constant camera_params* cam, __global const float* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const ray3 r = camera_ray(cam, in[4 * i], in[4 * i + 1], in[4 * i + 2], in[4 * i + 3]);
  out[6 * i + 0] = r.origin.x;
  out[6 * i + 1] = r.origin.y;
  out[6 * i + 2] = r.origin.z;
  out[6 * i + 3] = r.dir.x;
  out[6 * i + 4] = r.dir.y;
  out[6 * i + 5] = r.dir.z;
}

/* in: 2 floats per item (u1, u2) -> 3 floats */
__kernel void sf_uniform_sphere(__global const float* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const vec3 v = sample_uniform_sphere(in[2 * i], in[2 * i + 1]);
  out[3 * i + 0] = v.x;
  out[3 * i + 1] = v.y;
  out[3 * i + 2] = v.z;
}

/* in: 9 floats per item (o.xyz, d.xyz, hi.xyz) -> 3 floats (hit as 0/1, t_near, t_far) */
__kernel void sf_intersect_box(__global const float* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  __global const float* a = in + 9 * i;
  float tn = 0.0f, tf = 0.0f;
  const int hit = intersect_box(vec3_make(a[0], a[1], a[2]), vec3_make(a[3], a[4], a[5]), vec3_make(a[6], a[7], a[8]), &tn, &tf);
  out[3 * i + 0] = (float)hit;
  out[3 * i + 1] = tn;
  out[3 * i + 2] = tf;
}

/* Homogeneous medium (density 1). in: 2 floats per item (t, t_max) -> 3 floats of tracking_ratio */
__kernel void sf_tracking_ratio(__constant medium_params* m, __global const float* in, __global float* out, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  rng_state rng = rng_init(1u, i, 0u);
  kernel_context ctx = kernel_context_of_medium(m, 0); /* homogeneous: one global majorant */
  const vec3 tr = tracking_ratio(&ctx, vec3_make(0.0f, 0.0f, 0.0f), vec3_make(0.0f, 0.0f, 1.0f), in[2 * i],
                                 in[2 * i + 1], 0.0f, &rng);
  out[3 * i + 0] = tr.x;
  out[3 * i + 1] = tr.y;
  out[3 * i + 2] = tr.z;
}

/* Homogeneous medium, walks of stream (seed, i, 0) over [0, t_max]. in: t_max per item -> 5 floats
 * (event, t_out, beta.xyz) of tracking_delta. */
__kernel void sf_tracking_delta(__constant medium_params* m, __global const float* in, uint seed, __global float* out,
                                uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  rng_state rng = rng_init(seed, i, 0u);
  kernel_context ctx = kernel_context_of_medium(m, 0);
  vec3 beta = vec3_make(1.0f, 1.0f, 1.0f);
  float t = -1.0f;
  const int e = tracking_delta(&ctx, vec3_make(0.0f, 0.0f, 0.0f), vec3_make(0.0f, 0.0f, 1.0f), 0.0f, in[i], &rng,
                               &beta, &t);
  out[5 * i + 0] = (float)e;
  out[5 * i + 1] = t;
  out[5 * i + 2] = beta.x;
  out[5 * i + 3] = beta.y;
  out[5 * i + 4] = beta.z;
}

/* Kinds the kernels dispatch on, one item: out[0] the entry's status (scene_kinds_status), out[1]
 * the bits of phase_eval for the scene's phase kind, out[2] the bits of phase_sample's pdf, out[3]
 * light_sample_point's answer for lights[0] seen from the origin. */
__kernel void sf_scene_kinds(__constant scene_params* s, __constant light_params* lights, __global uint* out, uint n) {
  if (get_global_id(0) != 0 || n < 1u) return;
  const vec3 w = vec3_make(0.0f, 0.0f, 1.0f);
  float pdf = -1.0f;
  phase_sample(s->medium.phase, w, 0.25f, 0.5f, &pdf);
  light_sample ls;
  out[0] = scene_kinds_status(s, lights);
  out[1] = as_uint(phase_eval(s->medium.phase, w, w));
  out[2] = as_uint(pdf);
  out[3] = (uint)light_sample_point(&lights[0], vec3_make(0.0f, 0.0f, 0.0f), 0.5f, 0.5f, &ls);
}

/* The real-time kernels' kinds, one item: out[0] the entries' status (march_, lobe_ and
 * ms_cache_kinds_status), out[1] the bits of march_light_phase's red for lights[0] seen from the
 * origin along +z (HG 0.5, K = 1), out[2] the bits of ms_cache_closure for R = 2, g = 0.8,
 * b/R = (0, 0, 0.9) towards +z. The blocks, kernel arguments by value in the renderer, are copied to
 * private memory as those are. */
__kernel void sf_realtime_kinds(__constant march_params* mp, __constant lobe_params* lp,
                                __constant ms_cache_params* mcp, __constant light_params* lights, __global uint* out,
                                uint n) {
  if (get_global_id(0) != 0 || n < 1u) return;
  const march_params march = *mp;
  const lobe_params lobe = *lp;
  const ms_cache_params ms_cache = *mcp;
  const vec3 w = vec3_make(0.0f, 0.0f, 1.0f);
  out[0] = march_kinds_status(&march) | lobe_kinds_status(&lobe) | ms_cache_kinds_status(&ms_cache);
  out[1] = as_uint(march_light_phase(&lights[0], vec3_make(0.0f, 0.0f, 0.0f), phase_make(PHASE_HG, 0.5f), w,
                                     march.area_light_phase, 1).x);
  out[2] = as_uint(ms_cache_closure(ms_cache.closure, 2.0f, 0.8f, vec3_make(0.0f, 0.0f, 0.9f), w));
}
