/* ms_cache_build.h: estimating the multiple-scattering cache (ms_cache.h) with the path tracer's
 * own code; kept apart from the lookup so the ray marcher does not compile the path tracer. */
#ifndef NARVAL_MS_CACHE_BUILD_H
#define NARVAL_MS_CACHE_BUILD_H

#include "shared/ms_cache.h"
#include "shared/ms_cache_view.h"
#include "shared/pathtrace.h"
#include "shared/sampling.h"
#include "shared/sobol_owen.h"

/* Offsets the scene's seed so that node n's paths never share pixel n's camera samples' numbers. */
#define MS_CACHE_SEED_OFFSET 0x6d73u

/* Leading coordinates of node `node`'s path k: its start in the slice and the light its next-event
 * estimate picks (u[0], u[1]), its direction (u[2], u[3]), the point on the light (u[4], u[5]). The result
 * varies smoothly with them (the phase's peak against a wide light, the transmittance across the slice),
 * so each pair is a scrambled Sobol sequence over k (sobol_owen.h), every power-of-two prefix of a node's
 * paths stratified in it: tighter render-test bounds and less error between cache seeds, most with the
 * direct light alone (bench/RESULTS.md), since further bounces, drawn at random from the path's
 * counter-based stream (rng.h; delta tracking takes as many numbers as it needs), hold most of the noise.
 * Each node's scrambling keys come from its own stream at sample index MS_CACHE_LEADING_STREAM (no path
 * reaches it): nodes' errors stay independent and K paths give the same cache whatever the launches. */
#define MS_CACHE_LEADING_STREAM 0xFFFFFFFFu
#define MS_CACHE_LEADING_KEYS 9 /* three pairs: the index's seed, then each axis's */
static inline void ms_cache_leading_keys(uint seed, int node, NV_PRIVATE uint* keys) {
  rng_state r = rng_init(seed + MS_CACHE_SEED_OFFSET, (uint)node, MS_CACHE_LEADING_STREAM);
  for (int i = 0; i < MS_CACHE_LEADING_KEYS; ++i) keys[i] = rng_next_uint(&r);
}
static inline void ms_cache_leading(NV_PRIVATE const uint* keys, uint k, NV_PRIVATE float* u) {
  for (int pair = 0; pair < 3; ++pair)
    sobol_owen_2d(k, keys[3 * pair], keys[3 * pair + 1], keys[3 * pair + 2], &u[2 * pair], &u[2 * pair + 1]);
}

/* The direction from x to the camera, w_c; a node at the camera's very position takes −forward. */
static inline vec3 ms_cache_to_camera(NV_CONSTANT const scene_params* s, vec3 x) {
  const vec3 to_camera = vec3_sub(vec3_from4(s->camera.position), x);
  const float d = vec3_length(to_camera);
  return d > 0.0f ? vec3_scale(to_camera, 1.0f / d) : vec3_scale(vec3_from4(s->camera.forward), -1.0f);
}

/* The direction ω path k looks along, density *pdf (ms_cache.h, "Closure"): uniform on the sphere (mean
 * radiance R, −3·L·ω estimates b), or for the camera closure −w, w drawn from the phase function about w_c:
 * where a camera path arriving at x along −w_c would scatter, drawn as the path tracer draws it. */
static inline vec3 ms_cache_direction(NV_CONSTANT const scene_params* s, int closure, vec3 w_c, float u1, float u2,
                                      NV_PRIVATE float* pdf) {
  switch (closure) {
    case MS_CACHE_CLOSURE_LINEAR: *pdf = 0.25f * NV_INV_PI; return sample_uniform_sphere(u1, u2);
    case MS_CACHE_CLOSURE_CAMERA:
      return vec3_scale(phase_sample(s->medium.phase, w_c, u1, u2, pdf), -1.0f);
    default: *pdf = 0.0f; return sample_uniform_sphere(u1, u2); /* unknown: reported at the kernel's entry */
  }
}

/* Path k's estimate at node `node` and the direction ω it looked along: the rest's radiance arriving
 * at world point x (a grid node's; a view node's path draws its own in the slice, ms_cache_view.h),
 * plus the next-event estimate with the direct light (ms_cache.h, "Direct").
 * *turn: with the camera closure, the estimate's change as w_c turns (ms_cache_reproject.h, "Direction"):
 * the scattered part's grey value times the score of its direction, d ln p/dμ·(s − μ·w_c), s = −ω,
 * μ = s·w_c (the direct light's own change is left out); 0 otherwise. */
static inline vec3 ms_cache_path(KERNEL_CONTEXT_PARAM, NV_PRIVATE const ms_cache_params* mc, int node,
                                 NV_GLOBAL const float* v, vec3 x, NV_PRIVATE const uint* keys, uint k,
                                 NV_PRIVATE vec3* omega, NV_PRIVATE vec3* turn) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE uint* status = &ctx->status;
  const int view = mc->layout == MS_CACHE_LAYOUT_VIEW, direct = mc->direct;
  const int closure = mc->closure; /* the camera closure in the view layout (the host sets it) */
  float u[6]; /* the leading coordinates, stratified over the node's paths ("Leading coordinates") */
  ms_cache_leading(keys, k, u);
  rng_state rng = rng_init(s->seed + MS_CACHE_SEED_OFFSET, (uint)node, k);
  if (view) x = ms_view_sample_point(KERNEL_CONTEXT_ARG, mc, node, v, u[0]); /* in its slice */
  float pdf;
  const vec3 w_c = ms_cache_to_camera(s, x);
  *omega = ms_cache_direction(s, closure, w_c, u[2], u[3], &pdf);
  vec3 L = vec3_splat(0.0f);
  if (direct) L = pathtrace_direct_at(KERNEL_CONTEXT_ARG, x, vec3_scale(w_c, -1.0f), u[1], u[4], u[5], &rng);
  const vec3 scattered = pathtrace_radiance(KERNEL_CONTEXT_ARG, x, *omega, direct, direct ? pdf : 0.0f, &rng);
  *turn = vec3_splat(0.0f);
  if (closure == MS_CACHE_CLOSURE_CAMERA) {
    const vec3 sc = vec3_scale(*omega, -1.0f);
    const float mu = vec3_dot(sc, w_c);
    const float score = phase_log_slope(s->medium.phase, mu) * vec3_average(status_finite_or_zero(status, scattered));
    *turn = vec3_scale(vec3_sub(sc, vec3_scale(w_c, mu)), score);
  }
  return status_finite_or_zero(status, vec3_add(L, scattered));
}

/* Whether a lookup can read node `node`. Lookups happen only at samples of positive density and read their
 * cell's eight nodes, each within one node spacing h per axis; the majorant grid bounds the density per
 * cell (majorant_dda.h). So a node is read only if a majorant cell overlapping [p − h, p + h] (p its index-space
 * point, widened by MAJORANT_SLACK) has a positive bound; the build skips the others, the empty space
 * around a cloud. Without a majorant grid (the global majorant): every node. */
static inline int ms_cache_node_is_read(KERNEL_CONTEXT_PARAM, NV_PRIVATE const node_grid_params* c, int node) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  const majorant_grid_params g = m->majorant_grid;
  if (g.cells_x <= 0 || g.cells_y <= 0 || g.cells_z <= 0) return 1;
  const vec3 dims = vec3_from4(m->dims), p = node_grid_point(c, dims, node);
  const vec3 h = vec3_make(dims.x / (float)(c->nx - 1), dims.y / (float)(c->ny - 1), dims.z / (float)(c->nz - 1));
  int lo[3], hi[3];
  const float pc[3] = {p.x, p.y, p.z}, hc[3] = {h.x, h.y, h.z}, size[3] = {g.cell_size.x, g.cell_size.y, g.cell_size.z};
  const int n[3] = {g.cells_x, g.cells_y, g.cells_z};
  for (int a = 0; a < 3; ++a) {
    lo[a] = (int)nv_fmax(0.0f, nv_floor((pc[a] - hc[a] - MAJORANT_SLACK) / size[a]));
    hi[a] = (int)nv_fmin((float)(n[a] - 1), nv_floor((pc[a] + hc[a] + MAJORANT_SLACK) / size[a]));
  }
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i)
        if (GRID_MAJORANTS[i + g.cells_x * (j + g.cells_y * k)] > 0.0f) return 1;
  return 0;
}

/* The running mean of k + 1 values from that of the first k and the next, x: the first sets it (so a
 * node started over in place, its old value drawn until then, holds exactly what a zeroed one would:
 * device_ms_cache.cpp). */
static inline float ms_cache_running_mean(float mean, float x, uint k) {
  return k == 0u ? x : mean + (x - mean) / (float)(k + 1u);
}

/* Adds paths [first, first + count) to the running means of node `node` at world point x (ms_cache.h,
 * "Storage": v[0..2] R, v[3] the count, v[4 + 4ch .. 6 + 4ch] b of channel ch), then ln R and b/R. The
 * view layout, which reads neither, holds the mean of the paths' turn in v[4..6] instead
 * (MS_VIEW_TURN; ms_cache_path). */
static inline void ms_cache_refine_node(KERNEL_CONTEXT_PARAM, NV_PRIVATE const ms_cache_params* mc, vec3 x,
                                        int node, NV_GLOBAL float* v, uint first, uint count) {
  const int view = mc->layout == MS_CACHE_LAYOUT_VIEW;
  uint keys[MS_CACHE_LEADING_KEYS];
  ms_cache_leading_keys(ctx->scene->seed, node, keys);
  for (uint k = first; k < first + count; ++k) {
    vec3 omega, turn;
    const vec3 L = ms_cache_path(KERNEL_CONTEXT_ARG, mc, node, v, x, keys, k, &omega, &turn);
    const float Lc[3] = {L.x, L.y, L.z};
    const float w[3] = {-3.0f * omega.x, -3.0f * omega.y, -3.0f * omega.z}; /* 3·w, w = −ω */
    const float grey = vec3_average(L);
    v[MS_CACHE_SQUARE] = ms_cache_running_mean(v[MS_CACHE_SQUARE], grey * grey, k);
    for (int ch = 0; ch < 3; ++ch) {
      v[ch] = ms_cache_running_mean(v[ch], Lc[ch], k);
      if (view) continue;
      for (int a = 0; a < 3; ++a) v[4 + 4 * ch + a] = ms_cache_running_mean(v[4 + 4 * ch + a], Lc[ch] * w[a], k);
    }
    if (view) {
      const float t[3] = {turn.x, turn.y, turn.z};
      for (int a = 0; a < 3; ++a) v[MS_VIEW_TURN + a] = ms_cache_running_mean(v[MS_VIEW_TURN + a], t[a], k);
    }
    v[3] = (float)(k + 1u);
  }
  /* What the grid layout's lookup reads (ms_cache.h, "Storage"). */
  if (view) return;
  for (int ch = 0; ch < 3; ++ch) {
    const float R = v[ch];
    v[MS_CACHE_LOG_R + ch] = R > 0.0f ? nv_log(R) : -NV_INFINITY;
    for (int a = 0; a < 3; ++a) v[MS_CACHE_RATIO + 3 * ch + a] = R > 0.0f ? v[4 + 4 * ch + a] / R : 0.0f;
  }
}


/* One launch's work for node `node` (ms_cache.cl): paths [first, first + count). A grid node no lookup
 * reads stays 0 (ms_cache_node_is_read); a view node (placed by ms_view_place_column) takes none when
 * its column holds no medium. */
static inline void ms_cache_build_node(KERNEL_CONTEXT_PARAM, NV_PRIVATE const ms_cache_params* mc, int node,
                                       NV_GLOBAL float* v, uint first, uint count) {
  NV_PRIVATE const node_grid_params* c = &mc->grid;
  switch (mc->layout) {
    case MS_CACHE_LAYOUT_GRID:
      if (ms_cache_node_is_read(KERNEL_CONTEXT_ARG, c, node))
        ms_cache_refine_node(KERNEL_CONTEXT_ARG, mc,
                             affine_point(c->index_to_world, node_grid_point(c, vec3_from4(ctx->medium->dims), node)),
                             node, v, first, count);
      return;
    case MS_CACHE_LAYOUT_VIEW: { /* each path draws its point in the slice */
      if (!(v[MS_VIEW_TAU] >= 0.0f)) return;
      ms_cache_refine_node(KERNEL_CONTEXT_ARG, mc, vec3_splat(0.0f), node, v, first, count);
      return;
    }
    default: return; /* unknown: reported at the kernel's entry */
  }
}

#endif
