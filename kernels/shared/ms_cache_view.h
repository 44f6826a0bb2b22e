/* ms_cache_view.h: the multiple-scattering cache laid out in view space (MS_CACHE_LAYOUT_VIEW; ms_cache.h
 * holds what a node estimates and how). In a dense cloud lit from the camera's side the scattered light
 * lives in a layer a few mean free paths under the visible surface, thinner than a cell of the grid
 * layout, which spreads its nodes evenly over the box and cannot resolve it (bench/RESULTS.md). What a
 * pixel sees of the in-scattering is
 *   ∫ T(t) σs(t) J(t) dt = ∫ (σs/σt) J e^{−τ} dτ,     τ the optical depth from the camera,
 * so the nodes that matter are spread evenly in e^{−τ} along the view rays: production engines' froxels
 * (frustum-aligned voxels; Hillaire 2015, "Physically based and unified volumetric rendering in
 * Frostbite"), with depth in optical depth, not distance, so that the nodes follow the medium's surface.
 *
 * Layout (nx·ny columns of nz slices; node (cx, cy, s) at cx + nx·(cy + ny·s), MS_CACHE_STRIDE floats
 * each): column (cx, cy) is the camera ray through image point ((cx + ½)·tile, (cy + ½)·tile),
 * tile = ms_cache_params.tile pixels. Once per cache (ms_view_place_column), the grey τ (σ̄t the channel
 * mean per unit density) is marched along it to its total τ_end (march_column_density,
 * MS_VIEW_PLACE_STEPS samples over occupied majorant cells) and cut where the transmittance has fallen to
 *   T_i = 1 − (1 − T_end)·i/nz,   i = 0 … nz,   T_end = max(e^{−τ_end}, MS_VIEW_T_MIN)
 * (levels stop at τ_max = −ln MS_VIEW_T_MIN, past which the pixel sees less than MS_VIEW_T_MIN of the medium): node s is
 * the slice [τ_s, τ_{s+1}], an equal share of what the pixel sees. A column meeting no density stores
 * τ = −1 and takes no paths.
 *
 * A node holds the slice's mean, not a point's value: its paths start along the column with density
 * ∝ e^{−τ} over the slice (T uniform in [T_{s+1}, T_s]: ms_view_sample_point), aimed at the camera (the
 * camera closure), so it estimates J̄_s = ∫_s J e^{−τ} dτ / ∫_s e^{−τ} dτ, and Σ_s (T_s − T_{s+1})·J̄_s
 * is the column's in-scattering ∫ J e^{−τ} dτ exactly (for the grey σs/σt of a medium of one albedo).
 * Point values interpolated linearly in τ are biased where J falls steeply (convex in τ) under the
 * surface (bench/RESULTS.md).
 *
 * Lookup (ms_view_lookup): a sample at grey optical depth τ of the pixel's own march reads its four
 * nearest columns (ms_view_columns) bilinearly, each column's slices integrated over the march step (the
 * last slice running on past its end); columns without medium drop out, the others' weights renormalised.
 * Reading by τ, not distance, keeps a pixel's layers registered with its neighbours' where the surface
 * depth differs (a bump, a silhouette): one mean free path under the surface is read one mean free path
 * under the pixel's own surface. Errors: the tile's blur (in-scattering varies more slowly in the image
 * than single scattering, which the march computes per pixel), the slices' width where the pixel's τ
 * profile differs from its column's, and the paths' noise, averaged over four nodes. The cache depends on
 * the camera and image size: the host starts it over when either changes. */
#ifndef NARVAL_MS_CACHE_VIEW_H
#define NARVAL_MS_CACHE_VIEW_H

#include "shared/camera.h"
#include "shared/march.h"
#include "shared/ms_cache.h"

/* A node's slice, written by the placement in slots the running means leave free (ms_cache.h,
 * "Storage"): grey optical depth from the camera and distance along the ray at both ends (τ = −1: no medium). */
#define MS_VIEW_TAU 29
#define MS_VIEW_T 30
#define MS_VIEW_TAU_END 31
#define MS_VIEW_T_END 19
/* TURN (3 floats): the mean of the paths' turn, the node's grey value's gradient as the direction to the
 * camera turns (ms_cache_build.h, ms_cache_path; ms_cache_reproject.h). */
#define MS_VIEW_TURN 4
#define MS_VIEW_T_MIN 0.01f
#define MS_VIEW_PLACE_STEPS 256
#define MS_VIEW_SAMPLE_STEPS 16 /* a path's march across its slice to its drawn τ */

/* Column (cx, cy)'s ray: the camera ray through the centre of its tile. */
static inline ray3 ms_view_column_ray(NV_CONSTANT const camera_params* cam, int tile, int cx, int cy) {
  return camera_ray(cam, ((float)cx + 0.5f) * (float)tile, ((float)cy + 0.5f) * (float)tile, 0.5f, 0.5f);
}

/* Grey extinction per unit density: the mean of the channels (the march's τ and the nodes' agree). */
static inline float ms_view_sigma_t(NV_CONSTANT const medium_params* m) {
  const vec3 st = medium_sigma_t(m);
  return (st.x + st.y + st.z) / 3.0f;
}

/* A march step's grey optical depth, `density` read at its middle, and where in the step, τ linear over
 * it, acc + d reaches `level`: the walk of the placement and of the path starts along a column. */
static inline float ms_view_step_depth(float sigma, float density, float delta) {
  return sigma * nv_fmax(density, 0.0f) * delta;
}
static inline float ms_view_step_cross(float t, float delta, float acc, float d, float level) {
  return t - 0.5f * delta + delta * nv_fmin(1.0f, nv_fmax(0.0f, (level - acc) / d));
}

/* Level i of a column whose transmittance ends at t_end ("Layout"). */
static inline float ms_view_level(float t_end, int i, int nz) {
  return -nv_log(1.0f - (1.0f - t_end) * (float)i / (float)nz);
}

/* Slice ends: level i lies at distance t; it starts node i and ends node i − 1. */
static inline void ms_view_store_level(NV_GLOBAL float* cache, size_t slice_stride, int i, int nz, float level,
                                       float t) {
  if (i < nz) {
    cache[(size_t)i * slice_stride + MS_VIEW_TAU] = level;
    cache[(size_t)i * slice_stride + MS_VIEW_T] = t;
  }
  if (i > 0) {
    cache[(size_t)(i - 1) * slice_stride + MS_VIEW_TAU_END] = level;
    cache[(size_t)(i - 1) * slice_stride + MS_VIEW_T_END] = t;
  }
}

/* Places column `column`'s slices ("Layout"; ms_cache_place_view): writes each node's ends (MS_VIEW_TAU …)
 * so the build need not march the column at every launch. `cache`: slice 0; slice s is nx·ny nodes on. */
static inline void ms_view_place_column(KERNEL_CONTEXT_PARAM, NV_PRIVATE const ms_cache_params* mc, int column,
                                        NV_GLOBAL float* cache) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE const node_grid_params* c = &mc->grid;
  const size_t slice_stride = (size_t)c->nx * (size_t)c->ny * MS_CACHE_STRIDE;
  const ray3 r = ms_view_column_ray(&s->camera, mc->tile, column % c->nx, column / c->nx);
  for (int slice = 0; slice < c->nz; ++slice) {
    NV_GLOBAL float* v = cache + (size_t)slice * slice_stride;
    v[MS_VIEW_TAU] = v[MS_VIEW_TAU_END] = -1.0f;
    v[MS_VIEW_T] = v[MS_VIEW_T_END] = 0.0f;
  }
  medium_segment seg;
  vec3 Lb;
  if (!march_view(s, ctx->lights, r.origin, r.dir, &Lb, &seg)) return;
  const float sigma = ms_view_sigma_t(&s->medium);
  /* One march over the segment, its samples' densities kept: τ_end first (march_column_density's sum,
   * bit for bit), then where τ(t), linear over each step, reaches each level in turn; levels it does not
   * reach (rounding, or past τ_max) lie at the end of the last step with medium. */
  float rho[MS_VIEW_PLACE_STEPS], at[MS_VIEW_PLACE_STEPS], sum = 0.0f, t;
  int samples = 0;
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, &seg, MS_VIEW_PLACE_STEPS);
  while (samples < MS_VIEW_PLACE_STEPS && march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    at[samples] = t;
    rho[samples] = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg.o, seg.d, t));
    sum += rho[samples++];
  }
  ctx->status |= it.status;
  const float total = sigma * (sum * it.delta);
  if (!(total > 0.0f)) return;
  const float t_end = nv_fmax(nv_exp(-total), MS_VIEW_T_MIN);
  int i = 0;
  float acc = 0.0f, end = seg.t0;
  for (int k = 0; k < samples && i <= c->nz; ++k) {
    const float d = ms_view_step_depth(sigma, rho[k], it.delta);
    if (!(d > 0.0f)) continue;
    end = at[k] + 0.5f * it.delta;
    for (; i <= c->nz; ++i) {
      const float level = ms_view_level(t_end, i, c->nz);
      if (acc + d < level) break;
      ms_view_store_level(cache, slice_stride, i, c->nz, level, ms_view_step_cross(at[k], it.delta, acc, d, level));
    }
    acc += d;
  }
  for (; i <= c->nz; ++i) ms_view_store_level(cache, slice_stride, i, c->nz, ms_view_level(t_end, i, c->nz), end);
}

/* A path's start in node `node`'s slice ("A node holds the slice's mean"): T = T_s − u·(T_s − T_{s+1}),
 * and where the column reaches that τ, marched across the slice (its end when rounding leaves the
 * march short). The node must hold medium (v[MS_VIEW_TAU] ≥ 0). */
static inline vec3 ms_view_sample_point(KERNEL_CONTEXT_PARAM, NV_PRIVATE const ms_cache_params* mc, int node,
                                        NV_GLOBAL const float* v, float u) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE const node_grid_params* c = &mc->grid;
  const ray3 r = ms_view_column_ray(&s->camera, mc->tile, node % c->nx, (node / c->nx) % c->ny);
  medium_segment seg;
  vec3 Lb;
  if (!march_view(s, ctx->lights, r.origin, r.dir, &Lb, &seg)) return vec3_madd(r.origin, r.dir, v[MS_VIEW_T]);
  seg.t0 = v[MS_VIEW_T];
  seg.t1 = v[MS_VIEW_T_END];
  const float T0 = nv_exp(-v[MS_VIEW_TAU]), T1 = nv_exp(-v[MS_VIEW_TAU_END]);
  const float target = -nv_log(T0 - u * (T0 - T1)) - v[MS_VIEW_TAU];
  const float sigma = ms_view_sigma_t(&s->medium);
  float acc = 0.0f, at = seg.t1, t;
  if (seg.t1 > seg.t0) {
    march_iter it = march_begin(KERNEL_CONTEXT_ARG, &seg, MS_VIEW_SAMPLE_STEPS);
    while (march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
      const float density = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg.o, seg.d, t));
      const float d = ms_view_step_depth(sigma, density, it.delta);
      if (!(d > 0.0f)) continue;
      if (acc + d >= target) {
        at = ms_view_step_cross(t, it.delta, acc, d, target);
        break;
      }
      acc += d;
    }
  }
  return vec3_madd(r.origin, r.dir, at);
}

/* A pixel's four columns and their bilinear weights (0 for a column past the image's last). */
typedef struct ms_view_columns {
  int column[4];
  float w[4];
} ms_view_columns;

/* One axis: the lower column and the upper one's weight at position u in column units. */
static inline int ms_view_axis(float u, int n, NV_PRIVATE float* w) {
  if (n < 2) {
    *w = 0.0f;
    return 0;
  }
  return node_grid_axis(u, n, w);
}

/* The columns around image point (x, y) in pixels (clamped to the outermost columns). */
static inline ms_view_columns ms_view_locate_at(NV_PRIVATE const ms_cache_params* mc, float x, float y) {
  NV_PRIVATE const node_grid_params* c = &mc->grid;
  const float tile = (float)mc->tile;
  float ax, ay;
  const int x0 = ms_view_axis(x / tile - 0.5f, c->nx, &ax);
  const int y0 = ms_view_axis(y / tile - 0.5f, c->ny, &ay);
  ms_view_columns cols;
  for (int k = 0; k < 4; ++k) {
    const int dx = k & 1, dy = k >> 1;
    const int x = x0 + dx < c->nx ? x0 + dx : x0, y = y0 + dy < c->ny ? y0 + dy : y0;
    cols.column[k] = x + c->nx * y;
    cols.w[k] = (dx ? ax : 1.0f - ax) * (dy ? ay : 1.0f - ay);
  }
  return cols;
}

/* Pixel (px, py)'s columns: those around its centre. */
static inline ms_view_columns ms_view_locate(NV_PRIVATE const ms_cache_params* mc, int px, int py) {
  return ms_view_locate_at(mc, (float)px + 0.5f, (float)py + 0.5f);
}

/* 1 − e^{−x} for x ≥ 0, accurate for small x (march_step_weight's series). */
static inline float ms_view_one_minus_exp(float x) { return x * march_step_weight(x, nv_exp(-x)); }

/* The in-scattering towards the camera per unit σs over a march step, grey optical depth tau to tau + dtau,
 * for the pixel's columns `cols` ("Lookup"); 0 where none holds medium. J(τ) is piecewise constant over a
 * column's slices, so its mean under the step's weight e^{−(τ − tau)} (the energy-conserving step's,
 * march.h) is exact:
 *   J_step = Σ_s J̄_s·(e^{−(lo_s − tau)} − e^{−(hi_s − tau)}) / (1 − e^{−dtau}),
 * [lo_s, hi_s] slice s's part of the step (the first slice reaching back to 0, the last on to ∞). A point
 * read at the step's middle, a quadrature of its own, made the image depend on the step count where steps
 * cross slices near the surface (bench/RESULTS.md). The weight is the grey τ's (a chromatic medium's
 * channels fall at their own rates). A step inside one slice, and dtau = 0, read that slice. */
static inline vec3 ms_view_lookup(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* cache,
                                  NV_PRIVATE const ms_view_columns* cols, float tau, float dtau) {
  const size_t slice_stride = (size_t)c->nx * (size_t)c->ny * MS_CACHE_STRIDE;
  const float end = tau + dtau;
  vec3 sum = vec3_splat(0.0f);
  float weight = 0.0f;
  for (int k = 0; k < 4; ++k) {
    NV_GLOBAL const float* col = cache + (size_t)cols->column[k] * MS_CACHE_STRIDE;
    if (!(cols->w[k] > 0.0f) || col[MS_VIEW_TAU] < 0.0f) continue;
    int s = 0;
    while (s + 1 < c->nz && col[(size_t)(s + 1) * slice_stride + MS_VIEW_TAU] <= tau) ++s;
    const float first_end = s + 1 < c->nz ? col[(size_t)(s + 1) * slice_stride + MS_VIEW_TAU] : end;
    vec3 J = vec3_splat(0.0f);
    if (first_end < end) { /* the step crosses slices (first_end > tau; else it reads the one it is in) */
      float lo = tau, total = 0.0f; /* the step's part inside slice s starts at lo; at most nz pieces */
      for (;; ++s) {
        NV_GLOBAL const float* v = col + (size_t)s * slice_stride;
        const float hi = s + 1 < c->nz ? nv_fmin(col[(size_t)(s + 1) * slice_stride + MS_VIEW_TAU], end) : end;
        const float w = nv_exp(tau - lo) * ms_view_one_minus_exp(hi - lo);
        J = vec3_add(J, vec3_scale(vec3_make(v[0], v[1], v[2]), w));
        total += w; /* telescopes to 1 − e^{−(end − tau)}, in the pieces' own rounding */
        if (!(hi < end)) break;
        lo = hi;
      }
      J = vec3_scale(J, 1.0f / total);
    } else {
      NV_GLOBAL const float* v = col + (size_t)s * slice_stride;
      J = vec3_make(v[0], v[1], v[2]);
    }
    sum = vec3_add(sum, vec3_scale(J, cols->w[k]));
    weight += cols->w[k];
  }
  return weight > 0.0f ? vec3_scale(sum, 1.0f / weight) : sum;
}

#endif
