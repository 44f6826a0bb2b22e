/* light_cache.h: the light-transmittance cache of the real-time kernels (DESIGN.md "Real-time
 * caches"; the per-light "shadow volume" production engines keep, e.g. Hillaire 2016, Frostbite's
 * volumetric shadow maps). Per light, a grid of nodes over the medium's box holding what every
 * shadow ray of raymarch.h and lobe.h would otherwise march: the column density from the node to
 * the light (the point march_light_position gives: a point light, a rectangle's centre).
 *
 * Layout (light_cache_params, structs.h): nx·ny·nz nodes per light spanning the index box [0, dims]
 * corner to corner, node (i, j, k) at index point (i·dims.x/(nx − 1), j·dims.y/(ny − 1),
 * k·dims.z/(nz − 1)); the buffer holds the lights' slabs one after the other, x fastest. Nodes on
 * the faces and corners make the box's boundary exact for interpolation, and a point outside the
 * box needs no extrapolation (see light_cache_column).
 *
 * What a node stores: C = Σ_k ρ(x_k)·Δ, march_column_density from the node towards the light with
 * the kernel's own shadow_steps (the same quadrature as the exact march: the cache changes where
 * the integral is evaluated, not how). One float serves every channel: σt(x) = σt_unit·ρ(x) with a
 * single σt_unit per medium (DESIGN.md physics), so τ = σt_unit·C; storing τ rather than e^{−τ}
 * also keeps the ray marcher's octaves exact (they need exp(−bⁱτ)) and interpolates the smooth
 * quantity: e^{−τ} of an interpolated τ never leaves [0, 1].
 *
 * Lookup: trilinear over the 8 nodes around the point (grid_trilinear_combine, grid.h). Error
 * against the node quadrature at the point itself: trilinear interpolation reproduces any field
 * linear in x, y and z, and for a field with bounded second derivatives its error is at most
 * (h_x²·max|C_xx| + h_y²·max|C_yy| + h_z²·max|C_zz|)/8 (h the node spacing per axis); where C has
 * a kink (the light inside the box, a shadow edge) it is at most L·diag, L the Lipschitz constant of
 * C and diag = |(h_x, h_y, h_z)| the cell diagonal: the interpolant is a convex combination of the
 * corner values, each within L·diag of C at the point. For a homogeneous medium of density 1, C is
 * the length of the part of the shadow ray inside the box, Lipschitz with L = 1 when the light is
 * inside the box (C = |x − light|); tests/unit/light_cache_test.cpp checks both bounds.
 * Cost: one lookup (8 loads) replaces shadow_steps density lookups and a DDA walk per shadow ray.
 *
 * Built once per light on the device (kernels/light_cache.cl, host/render/light_cache.h), rebuilt
 * only when the medium, that light or the shadow step count changes. */
#ifndef NARVAL_LIGHT_CACHE_H
#define NARVAL_LIGHT_CACHE_H

#include "shared/march.h"

/* Nodes of one light's slab. */
static inline int light_cache_nodes(NV_CONSTANT const light_cache_params* c) { return c->nx * c->ny * c->nz; }

/* Index-space point of node `node` (x fastest) of the box [0, dims]. */
static inline vec3 light_cache_node_point(NV_CONSTANT const light_cache_params* c, vec3 dims, int node) {
  const int i = node % c->nx, j = (node / c->nx) % c->ny, k = node / (c->nx * c->ny);
  return vec3_make(dims.x * ((float)i / (float)(c->nx - 1)), dims.y * ((float)j / (float)(c->ny - 1)),
                   dims.z * ((float)k / (float)(c->nz - 1)));
}

/* What node `node` of light l's slab holds: the column density from the node to the light over
 * the kernel's shadow quadrature; 0 when the light sits on the node (nothing lies between).
 * Status word: STATUS_NAN for a NaN node point or column; STATUS_ITERATION_CAP from a DDA walk. */
static inline float light_cache_build_node(NV_CONSTANT const medium_params* m, GRID_PARAM,
                                           NV_CONSTANT const light_cache_params* c, int shadow_steps,
                                           NV_CONSTANT const light_params* l, int node, NV_PRIVATE uint* status) {
  const vec3 x = affine_point(c->index_to_world, light_cache_node_point(c, vec3_from4(m->dims), node));
  const vec3 to = vec3_sub(march_light_position(l), x);
  const float d2 = vec3_dot(to, to);
  if (!(d2 > 0.0f)) {
    if (d2 != d2) *status |= STATUS_NAN;
    return 0.0f;
  }
  const float dist = nv_sqrt(d2);
  const float column = march_column_density(m, GRID_ARG, x, vec3_scale(to, 1.0f / dist), dist, shadow_steps, status);
  if (column != column) *status |= STATUS_NAN; /* a NaN density on the way: said, not cached silently */
  return column;
}

/* One axis of a lookup: the lower node and the weight of the upper one for coordinate u (in node
 * units), clamped into the box so points on its faces (and a rounding outside) read the face. */
static inline int light_cache_axis(float u, int n, NV_PRIVATE float* w) {
  const float top = (float)(n - 1);
  const float v = nv_fmin(nv_fmax(u, 0.0f), top); /* a NaN u reads node 0 */
  const int i = (int)nv_fmin(nv_floor(v), top - 1.0f);
  *w = v - (float)i;
  return i;
}

/* Column density to light `light` at index-space point p inside the box [0, dims]: trilinear over
 * the slab's nodes. */
static inline float light_cache_column_at(NV_CONSTANT const light_cache_params* c, NV_GLOBAL const float* cache,
                                          int light, vec3 dims, vec3 p) {
  float ax, ay, az;
  const int x0 = light_cache_axis(p.x / dims.x * (float)(c->nx - 1), c->nx, &ax);
  const int y0 = light_cache_axis(p.y / dims.y * (float)(c->ny - 1), c->ny, &ay);
  const int z0 = light_cache_axis(p.z / dims.z * (float)(c->nz - 1), c->nz, &az);
  const int sy = c->nx, sz = c->nx * c->ny;
  NV_GLOBAL const float* b =
      cache + (size_t)light * (size_t)light_cache_nodes(c) + (size_t)(x0 + sy * y0 + sz * z0);
  return grid_trilinear_combine(b[0], b[1], b[sy], b[sy + 1], b[sz], b[sz + 1], b[sz + sy], b[sz + sy + 1],
                                1.0f - ax, ax, 1.0f - ay, ay, 1.0f - az, az);
}

/* Column density from world point x to light `light`, which lies `dist` away along unit `dir`.
 * The density is 0 outside the box, so the shadow ray's column is that of the point where it
 * enters the box (x itself when x is inside): a point outside reads the box's face, never an
 * extrapolation, and a shadow ray that misses the box has column 0. */
static inline float light_cache_column(NV_CONSTANT const medium_params* m, NV_CONSTANT const light_cache_params* c,
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

/* Optical depth τ from x to light `light` (unit `dir`, `dist` from march_light_as_point), per
 * channel: one cache lookup when the cache is on, else the exact shadow march of shadow_steps
 * samples (the kernels' pixels before the cache, bit for bit). Both real-time kernels call this
 * for every shadow ray. */
static inline vec3 light_cache_optical_depth(NV_CONSTANT const medium_params* m, GRID_PARAM,
                                             NV_CONSTANT const realtime_params* rp, NV_GLOBAL const float* cache,
                                             int light, vec3 x, vec3 dir, float dist, NV_PRIVATE uint* status) {
  if (rp->light_cache.nx > 0) {
    const vec3 sigma_t_unit = vec3_add(vec3_from4(m->sigma_a), vec3_from4(m->sigma_s));
    return vec3_scale(sigma_t_unit, light_cache_column(m, &rp->light_cache, cache, light, x, dir, dist, status));
  }
  return march_optical_depth(m, GRID_ARG, x, dir, dist, rp->shadow_steps, status);
}

#endif
