/* light_cache.h: the real-time kernels' light-transmittance cache (DESIGN.md "Real-time caches"; the
 * per-light "shadow volume" production engines keep, e.g. Hillaire 2016, Frostbite's volumetric shadow
 * maps): what every shadow ray of raymarch.h and lobe.h would march, per node of a grid over the
 * medium's box (node_grid.h; the light_cache kernel argument), one slab of nodes per light in turn.
 * A node holds the column C = Σ_k ρ(x_k)·Δ to the light by march_light_column with the kernel's own
 * shadow_steps, as the exact march computes it: the cache changes where the integral is evaluated, not
 * how. One float serves every channel, τ = σt_unit·C (one σt_unit per medium: DESIGN.md physics);
 * τ rather than e^{−τ} keeps the ray marcher's octaves exact (exp(−bⁱτ)) and interpolates the smooth
 * quantity, whose e^{−τ} never leaves [0, 1]. Lookup: trilinear over the 8 surrounding nodes
 * (node_grid.h states its bounds). In a homogeneous medium of density 1, C is the shadow ray's length
 * inside the box: smooth for a light outside (over the face it exits by), 1-Lipschitz with a kink for
 * one inside (C = |x − light|; tests/unit/light_cache_test.cpp checks both). One lookup (8 loads)
 * replaces shadow_steps density lookups and a DDA walk per shadow ray. Built once per light on the
 * device (kernels/light_cache.cl, host/render/device_light_cache.h); rebuilt only when the medium, that
 * light or shadow_steps changes. */
#ifndef NARVAL_LIGHT_CACHE_H
#define NARVAL_LIGHT_CACHE_H

#include "shared/march.h"
#include "shared/node_grid.h"

/* What node `node` of light l's slab holds (march_light_column); 0 when the light sits on the node.
 * Status word: STATUS_NAN for a NaN node point or column; STATUS_ITERATION_CAP from a DDA walk. */
static inline float light_cache_build_node(KERNEL_CONTEXT_PARAM,
                                           NV_PRIVATE const node_grid_params* c, int shadow_steps, int K,
                                           int weighting, NV_CONSTANT const light_params* l, int node) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  const vec3 x = affine_point(c->index_to_world, node_grid_point(c, vec3_from4(m->dims), node));
  /* Weighted by the phase: towards the camera, along the view ray through the node. */
  const vec3 from_camera = vec3_sub(x, vec3_from4(ctx->scene->camera.position));
  const float d = vec3_length(from_camera);
  const vec3 view_dir = d > 0.0f ? vec3_scale(from_camera, 1.0f / d) : vec3_from4(ctx->scene->camera.forward);
  const float column = march_light_column(KERNEL_CONTEXT_ARG, l, x, K, shadow_steps, weighting, view_dir);
  if (column != column) *status |= STATUS_NAN; /* a NaN density on the way: said, not cached silently */
  return column;
}

/* Column density to light `light` at index-space point p in the box [0, dims]: trilinear over its slab. */
static inline float light_cache_column_at(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* cache,
                                          int light, vec3 dims, vec3 p) {
  return node_grid_interpolate(c, cache + (size_t)light * (size_t)node_grid_count(c), 1, node_grid_locate(c, dims, p));
}

/* Column density from world point x to light `light`, `dist` away along unit `dir`. Density is 0
 * outside the box, so the column is that of the point where the shadow ray enters it (x when inside):
 * a point outside reads the box's face, never an extrapolation; a ray missing the box has column 0. */
static inline float light_cache_column(NV_CONSTANT const medium_params* m, NV_PRIVATE const node_grid_params* c,
                                       NV_GLOBAL const float* cache, int light, vec3 x, vec3 dir, float dist,
                                       NV_PRIVATE uint* status) {
  const vec3 dims = vec3_from4(m->dims);
  const vec3 p = affine_point(m->world_to_index, x);
  if (p.x >= 0.0f && p.y >= 0.0f && p.z >= 0.0f && p.x <= dims.x && p.y <= dims.y && p.z <= dims.z)
    return light_cache_column_at(c, cache, light, dims, p); /* inside: no ray to clip */
  medium_segment seg;
  if (!march_clip(m, x, dir, dist, &seg, status)) return 0.0f;
  return light_cache_column_at(c, cache, light, dims, vec3_madd(seg.o, seg.d, seg.t0));
}

/* Optical depth τ per channel from x to light `light` (unit `dir`, `dist` from light_view_from), for
 * every shadow ray of both real-time kernels: one cache lookup when the cache is on, else the exact
 * shadow march of shadow_steps samples. */
static inline vec3 light_cache_optical_depth(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                             NV_PRIVATE const node_grid_params* lc, NV_GLOBAL const float* cache,
                                             int light, vec3 x, vec3 dir, float dist, vec3 view_dir) {
  NV_CONSTANT const light_params* lights = ctx->lights;
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  const vec3 sigma_t_unit = medium_sigma_t(m);
  if (lc->nx > 0)
    return vec3_scale(sigma_t_unit, light_cache_column(m, lc, cache, light, x, dir, dist, status));
  if (mp->shadow_area_samples > 1 && light_has_area(&lights[light])) /* the columns the cache would hold */
    return vec3_scale(sigma_t_unit,
                      march_light_column(KERNEL_CONTEXT_ARG, &lights[light], x, mp->shadow_area_samples,
                                         mp->shadow_steps, mp->shadow_weighting, view_dir));
  return march_optical_depth(KERNEL_CONTEXT_ARG, x, dir, dist, mp->shadow_steps);
}

#endif
