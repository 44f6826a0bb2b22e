/* node_grid.h: a grid of nodes spanning the medium's index box [0, dims] corner to corner, the
 * layout of the real-time caches (light_cache.h, ms_cache.h). node_grid_params (structs.h): nx·ny·nz
 * nodes (each >= 2; nx = 0: no grid), node (i, j, k) at index point (i·dims.x/(nx − 1),
 * j·dims.y/(ny − 1), k·dims.z/(nz − 1)), x fastest. Nodes on the faces and corners make the box's
 * boundary exact for interpolation, and a point outside the box is never extrapolated to.
 * Trilinear interpolation reproduces any field linear in x, y and z; for a field with bounded
 * second derivatives it errs by at most (h_x²·max|f_xx| + h_y²·max|f_yy| + h_z²·max|f_zz|)/8 (h
 * the node spacing per axis), and where f has a kink by at most L·|(h_x, h_y, h_z)| (L its
 * Lipschitz constant): the interpolant is a convex combination of the corner values. */
#ifndef NARVAL_NODE_GRID_H
#define NARVAL_NODE_GRID_H

#include "shared/grid.h"
#include "shared/structs.h"

static inline int node_grid_count(NV_PRIVATE const node_grid_params* c) { return c->nx * c->ny * c->nz; }

/* Index-space point of node `node` (x fastest) of the box [0, dims]. */
static inline vec3 node_grid_point(NV_PRIVATE const node_grid_params* c, vec3 dims, int node) {
  const int i = node % c->nx, j = (node / c->nx) % c->ny, k = node / (c->nx * c->ny);
  return vec3_make(dims.x * ((float)i / (float)(c->nx - 1)), dims.y * ((float)j / (float)(c->ny - 1)),
                   dims.z * ((float)k / (float)(c->nz - 1)));
}

/* One axis of a lookup: the lower node and the weight of the upper one for coordinate u (in node
 * units), clamped into the box so points on its faces (and a rounding outside) read the face. */
static inline int node_grid_axis(float u, int n, NV_PRIVATE float* w) {
  const float top = (float)(n - 1);
  const float v = nv_fmin(nv_fmax(u, 0.0f), top); /* a NaN u reads node 0 */
  const int i = (int)nv_fmin(nv_floor(v), top - 1.0f);
  *w = v - (float)i;
  return i;
}

/* The cell around index-space point p: the index of its lowest node and the weights of the upper
 * nodes along x, y and z; the eight corners are base + {0, 1} + {0, nx} + {0, nx·ny}. */
typedef struct node_grid_cell {
  int base;
  float ax, ay, az;
} node_grid_cell;

static inline node_grid_cell node_grid_locate(NV_PRIVATE const node_grid_params* c, vec3 dims, vec3 p) {
  node_grid_cell cell;
  const int x0 = node_grid_axis(p.x / dims.x * (float)(c->nx - 1), c->nx, &cell.ax);
  const int y0 = node_grid_axis(p.y / dims.y * (float)(c->ny - 1), c->ny, &cell.ay);
  const int z0 = node_grid_axis(p.z / dims.z * (float)(c->nz - 1), c->nz, &cell.az);
  cell.base = x0 + c->nx * (y0 + c->ny * z0);
  return cell;
}

/* The cell's eight corners, k = dx + 2·dy + 4·dz: their offsets in a buffer of `stride` floats per
 * node and their trilinear weights (summing to 1). For a lookup that combines the corners other
 * than linearly (ms_cache.h). */
static inline void node_grid_corners(NV_PRIVATE const node_grid_params* c, node_grid_cell cell, int stride,
                                     NV_PRIVATE size_t* at, NV_PRIVATE float* w) {
  const size_t sy = (size_t)c->nx, sz = (size_t)c->nx * (size_t)c->ny;
  for (int k = 0; k < 8; ++k) {
    const int dx = k & 1, dy = (k >> 1) & 1, dz = k >> 2;
    at[k] = ((size_t)cell.base + (size_t)dx + (size_t)dy * sy + (size_t)dz * sz) * (size_t)stride;
    w[k] = (dx ? cell.ax : 1.0f - cell.ax) * (dy ? cell.ay : 1.0f - cell.ay) * (dz ? cell.az : 1.0f - cell.az);
  }
}

/* Trilinear interpolation of the values v[stride·node] over the cell (grid_trilinear_combine, the
 * density lookups' arithmetic). */
static inline float node_grid_interpolate(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* v, int stride,
                                          node_grid_cell cell) {
  const size_t s1 = (size_t)stride, sy = (size_t)c->nx * s1, sz = (size_t)c->nx * (size_t)c->ny * s1;
  NV_GLOBAL const float* b = v + (size_t)cell.base * s1;
  return grid_trilinear_combine(b[0], b[s1], b[sy], b[sy + s1], b[sz], b[sz + s1], b[sz + sy], b[sz + sy + s1],
                                1.0f - cell.ax, cell.ax, 1.0f - cell.ay, cell.ay, 1.0f - cell.az, cell.az);
}

#endif
