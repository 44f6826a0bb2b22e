/* ms_cache_view.h: the multiple-scattering cache laid out in view space (MS_CACHE_LAYOUT_VIEW;
 * ms_cache.h holds what a node estimates and how). The grid layout spends its nodes evenly over the
 * medium's box; in a dense cloud lit from the camera's side the scattered light lives in a layer a
 * few mean free paths thick under the visible surface, thinner than a cell, and the grid cannot
 * resolve it (bench/RESULTS.md: the front-lit Disney cloud's multiple scattering reads 0.45–0.70 of
 * the path tracer's at 16–64 cells). What a pixel sees of the in-scattering is
 *   ∫ T(t) σs(t) J(t) dt = ∫ (σs/σt) J e^{−τ} dτ,     τ the optical depth from the camera,
 * so the nodes that matter are those spread evenly in e^{−τ} along the view rays: the layout of
 * production engines' froxels (frustum-aligned voxels; Hillaire 2015, "Physically based and unified
 * volumetric rendering in Frostbite"), with the depth axis taken in optical depth instead of
 * distance so that the nodes follow the medium's surface wherever it is.
 *
 * Layout (node_grid_params ms_cache: nx·ny columns, nz = slices per column; node (cx, cy, s) at index
 * cx + nx·(cy + ny·s), MS_CACHE_STRIDE floats each): column (cx, cy) is the camera ray through the
 * image point ((cx + ½)·tile, (cy + ½)·tile), tile = realtime_params.ms_cache_tile pixels. Along it
 * (once per cache, before any paths: ms_view_place_column),
 * τ(t) is marched with MS_VIEW_PLACE_STEPS samples over its occupied majorant cells (march.h), in
 * the grey extinction σ̄t (the mean of the three channels, per unit density), to its total τ_end
 * (march_column_density; levels stop at τ_max = −ln MS_VIEW_T_MIN: past it the pixel sees under
 * 1% of the medium). Node s sits
 * where the transmittance has fallen to
 *   T_s = 1 − (1 − T_end)·s/(nz − 1),   T_end = max(e^{−τ_end}, MS_VIEW_T_MIN),
 * equal shares of what the pixel sees: s = 0 at the medium's first sample, nz − 1 at its end (or at
 * τ_max). A node stores its τ_s and the in-scattering towards the camera there (the camera closure:
 * its paths are phase-sampled about the direction to the camera, ms_cache_build.h). A column that
 * meets no density stores τ = −1 and no paths.
 *
 * Lookup: a pixel's sample at grey optical depth τ (its own march's, ms_view_columns) reads its
 * four nearest columns, bilinear in image space; each column interpolates linearly in τ between the
 * two nodes around it (clamped at its ends), and columns without medium drop out (the weights of the
 * others renormalised). Reading by τ rather than by distance keeps a pixel's layers registered with
 * its neighbours' when the surface is at different depths in them (a bump, a silhouette): the node
 * one mean free path under the surface is read one mean free path under the pixel's own surface.
 * Errors: the tile's blur (the in-scattering varies more slowly in the image than the single
 * scattering, which the march computes per pixel), the linear τ interpolation between slices, and
 * the paths' noise, which the lookup averages over up to eight nodes.
 * The cache depends on the camera and the image size: the host starts it over when either changes. */
#ifndef NARVAL_MS_CACHE_VIEW_H
#define NARVAL_MS_CACHE_VIEW_H

#include "shared/camera.h"
#include "shared/march.h"
#include "shared/ms_cache.h"

#define MS_VIEW_TAU 29 /* node's grey optical depth from the camera; −1: its column holds no medium */
#define MS_VIEW_T 30   /* node's distance from the camera along its column's ray */
#define MS_VIEW_T_MIN 0.01f
#define MS_VIEW_PLACE_STEPS 256

/* Column (cx, cy)'s ray: the camera ray through the centre of its tile. */
static inline ray3 ms_view_column_ray(NV_CONSTANT const camera_params* cam, int tile, int cx, int cy) {
  return camera_ray(cam, ((float)cx + 0.5f) * (float)tile, ((float)cy + 0.5f) * (float)tile, 0.5f, 0.5f);
}

/* Grey extinction per unit density: the mean of the channels (the march's τ and the nodes' agree). */
static inline float ms_view_sigma_t(NV_CONSTANT const medium_params* m) {
  const vec3 st = vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s));
  return (st.x + st.y + st.z) / 3.0f;
}

/* Places column `column`'s nodes ("Layout"), once per cache (ms_cache_place_view, before any
 * paths): marches the column for τ_end, then once more to every node's level, and writes each
 * node's τ (−1 when the column holds no medium) and its distance along the column's ray, which the
 * build then reads (ms_view_node_point) instead of marching again at every launch. `cache` points
 * at the column's first node (slice 0); slice s is nx·ny nodes further. */
static inline void ms_view_place_column(KERNEL_CONTEXT_PARAM, NV_CONSTANT const realtime_params* rp, int column,
                                        NV_GLOBAL float* cache) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const node_grid_params* c = &rp->ms_cache;
  const size_t slice_stride = (size_t)c->nx * (size_t)c->ny * MS_CACHE_STRIDE;
  const ray3 r = ms_view_column_ray(&s->camera, rp->ms_cache_tile, column % c->nx, column / c->nx);
  for (int slice = 0; slice < c->nz; ++slice) {
    cache[(size_t)slice * slice_stride + MS_VIEW_TAU] = -1.0f;
    cache[(size_t)slice * slice_stride + MS_VIEW_T] = 0.0f;
  }
  medium_segment seg;
  if (!s->has_medium || !march_view_segment(s, ctx->lights, r.origin, r.dir, &seg)) return;
  const float sigma = ms_view_sigma_t(&s->medium);
  /* First march: τ_end, the column over the same samples as the second (the segment [t0, t1] again). */
  const float total = sigma * march_column_density(KERNEL_CONTEXT_ARG, r.origin, r.dir, seg.t1, MS_VIEW_PLACE_STEPS);
  if (!(total > 0.0f)) return;
  const float t_end = nv_fmax(nv_exp(-total), MS_VIEW_T_MIN);
  /* Second march: where τ(t), linear over each step, reaches each level in turn; levels it does not
   * reach (rounding, or past τ_max) lie at the end of the last step with medium. */
  int slice = 0;
  float acc = 0.0f, end = seg.t0, t;
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, &seg, MS_VIEW_PLACE_STEPS);
  while (slice < c->nz && march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    const float d = sigma * nv_fmax(grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg.o, seg.d, t)), 0.0f) * it.delta;
    if (!(d > 0.0f)) continue;
    end = t + 0.5f * it.delta;
    for (; slice < c->nz; ++slice) {
      const float level = -nv_log(1.0f - (1.0f - t_end) * (float)slice / (float)(c->nz - 1));
      if (acc + d < level) break;
      NV_GLOBAL float* v = cache + (size_t)slice * slice_stride;
      v[MS_VIEW_TAU] = level;
      v[MS_VIEW_T] = t - 0.5f * it.delta + it.delta * nv_fmin(1.0f, nv_fmax(0.0f, (level - acc) / d));
    }
    acc += d;
  }
  for (; slice < c->nz; ++slice) {
    NV_GLOBAL float* v = cache + (size_t)slice * slice_stride;
    v[MS_VIEW_TAU] = -nv_log(1.0f - (1.0f - t_end) * (float)slice / (float)(c->nz - 1));
    v[MS_VIEW_T] = end;
  }
}

/* Node `node`'s world point, placed by ms_view_place_column; its τ is v[MS_VIEW_TAU] (−1: its
 * column holds no medium, and the point is meaningless). */
static inline vec3 ms_view_node_point(NV_CONSTANT const scene_params* s, NV_CONSTANT const realtime_params* rp,
                                      int node, NV_GLOBAL const float* v) {
  NV_CONSTANT const node_grid_params* c = &rp->ms_cache;
  const ray3 r = ms_view_column_ray(&s->camera, rp->ms_cache_tile, node % c->nx, (node / c->nx) % c->ny);
  return vec3_madd(r.origin, r.dir, v[MS_VIEW_T]);
}

/* A pixel's four columns and their bilinear weights (0 for a column past the image's last). */
typedef struct ms_view_columns {
  int column[4];
  float w[4];
} ms_view_columns;

/* One axis: the lower column and the weight of the upper one for the pixel centre's position u in
 * column units; one column alone takes it all. */
static inline int ms_view_axis(float u, int n, NV_PRIVATE float* w) {
  if (n < 2) {
    *w = 0.0f;
    return 0;
  }
  return node_grid_axis(u, n, w);
}

static inline ms_view_columns ms_view_locate(NV_CONSTANT const realtime_params* rp, int px, int py) {
  NV_CONSTANT const node_grid_params* c = &rp->ms_cache;
  const float tile = (float)rp->ms_cache_tile;
  float ax, ay;
  const int x0 = ms_view_axis(((float)px + 0.5f) / tile - 0.5f, c->nx, &ax);
  const int y0 = ms_view_axis(((float)py + 0.5f) / tile - 0.5f, c->ny, &ay);
  ms_view_columns cols;
  for (int k = 0; k < 4; ++k) {
    const int dx = k & 1, dy = k >> 1;
    const int x = x0 + dx < c->nx ? x0 + dx : x0, y = y0 + dy < c->ny ? y0 + dy : y0;
    cols.column[k] = x + c->nx * y;
    cols.w[k] = (dx ? ax : 1.0f - ax) * (dy ? ay : 1.0f - ay);
  }
  return cols;
}

/* The in-scattering towards the camera per unit σs at grey optical depth tau, for the pixel whose
 * columns are `cols` ("Lookup"); 0 where none of them holds medium. */
static inline vec3 ms_view_lookup(NV_CONSTANT const node_grid_params* c, NV_GLOBAL const float* cache,
                                  NV_PRIVATE const ms_view_columns* cols, float tau) {
  const size_t slice_stride = (size_t)c->nx * (size_t)c->ny * MS_CACHE_STRIDE;
  vec3 sum = vec3_splat(0.0f);
  float weight = 0.0f;
  for (int k = 0; k < 4; ++k) {
    NV_GLOBAL const float* col = cache + (size_t)cols->column[k] * MS_CACHE_STRIDE;
    if (!(cols->w[k] > 0.0f) || col[MS_VIEW_TAU] < 0.0f) continue;
    int s = 0;
    while (s + 1 < c->nz && col[(size_t)(s + 1) * slice_stride + MS_VIEW_TAU] <= tau) ++s;
    NV_GLOBAL const float* a = col + (size_t)s * slice_stride;
    NV_GLOBAL const float* b = col + (size_t)(s + 1 < c->nz ? s + 1 : s) * slice_stride;
    const float span = b[MS_VIEW_TAU] - a[MS_VIEW_TAU];
    const float f = span > 0.0f ? nv_fmin(1.0f, nv_fmax(0.0f, (tau - a[MS_VIEW_TAU]) / span)) : 0.0f;
    const vec3 va = vec3_make(a[0], a[1], a[2]), vb = vec3_make(b[0], b[1], b[2]);
    sum = vec3_add(sum, vec3_scale(vec3_add(vec3_scale(va, 1.0f - f), vec3_scale(vb, f)), cols->w[k]));
    weight += cols->w[k];
  }
  return weight > 0.0f ? vec3_scale(sum, 1.0f / weight) : sum;
}

#endif
