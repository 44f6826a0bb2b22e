/* grid.h: the one function through which every kernel reads density, grid_density(GRID_ARG, p),
 * with p in grid index space (voxel i covers [i, i+1], centre i + 0.5; trilinear; 0 outside).
 * Device: a 3D image (CL_R, CL_FLOAT) read with the hardware sampler, or 1 everywhere for a
 * homogeneous medium (-D MEDIUM_HOMOGENEOUS). Host: the same reconstruction on a float array, so
 * tests and a native baseline see the same field. Storage is chosen here and nowhere else.
 * GRID_PARAM also carries the majorant grid's per-cell bounds (GRID_MAJORANTS), so every function
 * that reads density can skip empty space (march.h) without another parameter. */
#ifndef NARVAL_GRID_H
#define NARVAL_GRID_H

#include "shared/vec3.h"

#ifdef NV_DEVICE

#ifdef MEDIUM_HOMOGENEOUS
#define GRID_PARAM int grid_unused, NV_GLOBAL const float* grid_majorants
#define GRID_ARG grid_unused, grid_majorants
#define GRID_KERNEL_PARAM GRID_PARAM
#define GRID_MAJORANTS grid_majorants
#define GRID_IS_HOMOGENEOUS(g) 1
static inline float grid_density(GRID_PARAM, vec3 p) { return 1.0f; }
#else
#define GRID_PARAM read_only image3d_t grid, NV_GLOBAL const float* grid_majorants
#define GRID_ARG grid, grid_majorants
#define GRID_KERNEL_PARAM GRID_PARAM
#define GRID_MAJORANTS grid_majorants
#define GRID_IS_HOMOGENEOUS(g) 0
__constant sampler_t grid_sampler = CLK_NORMALIZED_COORDS_FALSE | CLK_ADDRESS_CLAMP | CLK_FILTER_LINEAR;
static inline float grid_density(GRID_PARAM, vec3 p) {
  /* Callers stay inside the box; the clamp keeps wild coordinates off the far edge (DESIGN.md). */
  const float4 q = (float4)(clamp(p.x, -1.0f, 1.0e7f), clamp(p.y, -1.0f, 1.0e7f), clamp(p.z, -1.0f, 1.0e7f), 0.0f);
  return read_imagef(grid, grid_sampler, q).x;
}
#endif

#else /* host */

typedef struct grid_view {
  const float* data; /* NULL: homogeneous, density 1 */
  int nx, ny, nz;
  const float* majorants; /* per-cell density bounds (medium_params.majorant_grid); NULL: no skipping */
} grid_view;
#define GRID_PARAM const grid_view* grid
#define GRID_ARG grid
#define GRID_MAJORANTS (grid->majorants)
#define GRID_IS_HOMOGENEOUS(g) ((g)->data == 0)

static inline float grid_voxel(const grid_view* g, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= g->nx || y >= g->ny || z >= g->nz) return 0.0f;
  return g->data[(size_t)x + (size_t)g->nx * ((size_t)y + (size_t)g->ny * (size_t)z)];
}

static inline float grid_density(GRID_PARAM, vec3 p) {
  if (!grid->data) return 1.0f;
  /* The device's clamp, so huge or infinite coordinates read 0 here too (and never overflow int). */
  const float fx = fminf(fmaxf(p.x, -1.0f), 1.0e7f) - 0.5f;
  const float fy = fminf(fmaxf(p.y, -1.0f), 1.0e7f) - 0.5f;
  const float fz = fminf(fmaxf(p.z, -1.0f), 1.0e7f) - 0.5f;
  const float x0f = floorf(fx), y0f = floorf(fy), z0f = floorf(fz);
  const int x0 = (int)x0f, y0 = (int)y0f, z0 = (int)z0f;
  const float ax = fx - x0f, ay = fy - y0f, az = fz - z0f;
  float c[2][2];
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      c[dz][dy] = grid_voxel(grid, x0, y0 + dy, z0 + dz) * (1.0f - ax) + grid_voxel(grid, x0 + 1, y0 + dy, z0 + dz) * ax;
  const float c0 = c[0][0] * (1.0f - ay) + c[0][1] * ay;
  const float c1 = c[1][0] * (1.0f - ay) + c[1][1] * ay;
  return c0 * (1.0f - az) + c1 * az;
}

#endif

#endif
