/* grid.h: grid storage and lookup, grid_value(g, p) (kernels read density through kernel_context.h's
 * grid_density) at p in grid index space: voxel i covers [i, i+1], centre i + 0.5; trilinear; 0
 * outside. Storage is chosen here alone, with the same kernel arguments for each (GRID_STORAGE is a
 * grid argument's type); the host picks it per device (render/device_grid.h, scene key renderer.storage).
 * Device: -D MEDIUM_HOMOGENEOUS, 1 everywhere (an unused int); -D GRID_STORAGE_BUFFER, a __global float
 * buffer (GRID_BUFFER_HEADER, then the voxels, x fastest) filtered by grid_trilinear, the host's code;
 * -D GRID_STORAGE_BRICKS, sparse 8³ bricks (below) for grids beyond one image or buffer, the same bits;
 * otherwise a 3D image (CL_R, CL_FLOAT) with the sampler's hardware filtering. Host: grid_trilinear on
 * a float array, so tests and a native baseline see the same field.
 * Image and buffer reconstruct the same field and differ in arithmetic only:
 * - Addressing: CLK_ADDRESS_CLAMP (border 0), like grid_trilinear's zero corners, fades the field to 0
 *   over the half voxel beyond the outer centres (CLK_ADDRESS_CLAMP_TO_EDGE would repeat edge voxels).
 * - Filtering: CLK_FILTER_LINEAR (unnormalised) takes u = p - 0.5, i0 = floor(u), a = u - i0 and sums
 *   (1-a)(1-b)(1-c)·T000 + a(1-b)(1-c)·T100 + ... (the OpenCL spec's form, float on PoCL);
 *   grid_trilinear nests three lerps on the same a, b, c. Both sum non-negative terms, a few roundings
 *   from exact: on PoCL they agree within 16 ε of the density, ε = 2^-24
 *   (tests/device/grid_storage_lookup_test.cpp; bench/RESULTS.md); the device buffer is the host's
 *   bits (pixels: tests/render/grid_storage_test.cpp).
 * - Many GPUs (NVIDIA's texture units: 9-bit fixed point, 8 fractional bits) quantise a, b, c to
 *   multiples of 1/256: up to 1/256 of the neighbour difference per axis, 3/256 of the eight corners'
 *   range in all (bench/RESULTS.md). The buffer is exact float on every device; the image still does
 *   more lookups per second on GPUs (bench/RESULTS.md).
 * - Coordinates are clamped to [-1, 1e7] first: clamp addressing sends huge or infinite ones to the
 *   wrong edge on some devices (DESIGN.md), and int conversions stay defined; -1 is over half a voxel
 *   outside: density 0. */
#ifndef NARVAL_GRID_H
#define NARVAL_GRID_H

#include "shared/vec3.h"

/* The float buffer's layout: GRID_BUFFER_HEADER 32-bit slots (nx, ny, nz as ints, then 0; 16 bytes,
 * so the voxels stay 16-byte aligned), then nx·ny·nz floats, x fastest (the 3D image's order). */
#define GRID_BUFFER_HEADER 4

/* A corner's weight at index i along an axis of n voxels: w inside, 0 outside (border colour 0). */
static inline float grid_corner_weight(int i, int n, float w) { return (i >= 0 && i < n) ? w : 0.0f; }

/* i clamped into [0, n-1]: outside corners (weight 0) load an in-range voxel, with no branch per corner. */
static inline int grid_clamp_index(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }

/* The eight corners v_xyz (v100: x + 1, y, z) weighed along x, then y, then z. Every storage that
 * filters by hand (buffer, bricks) ends here, so the same corners and weights give the same bits. */
static inline float grid_trilinear_combine(float v000, float v100, float v010, float v110, float v001, float v101,
                                           float v011, float v111, float wx0, float wx1, float wy0, float wy1,
                                           float wz0, float wz1) {
  const float c00 = v000 * wx0 + v100 * wx1;
  const float c01 = v010 * wx0 + v110 * wx1;
  const float c10 = v001 * wx0 + v101 * wx1;
  const float c11 = v011 * wx0 + v111 * wx1;
  const float c0 = c00 * wy0 + c01 * wy1;
  const float c1 = c10 * wy0 + c11 * wy1;
  return c0 * wz0 + c1 * wz1;
}

/* The trilinear filter's cell of index-space point p, clamped as above: its lower corner voxel
 * (x0, y0, z0) and the upper corners' weights (ax, ay, az). */
typedef struct grid_cell {
  int x0, y0, z0;
  float ax, ay, az;
} grid_cell;

static inline grid_cell grid_locate(vec3 p) {
  const float fx = nv_fmin(nv_fmax(p.x, -1.0f), 1.0e7f) - 0.5f;
  const float fy = nv_fmin(nv_fmax(p.y, -1.0f), 1.0e7f) - 0.5f;
  const float fz = nv_fmin(nv_fmax(p.z, -1.0f), 1.0e7f) - 0.5f;
  const float x0f = nv_floor(fx), y0f = nv_floor(fy), z0f = nv_floor(fz);
  const grid_cell c = {(int)x0f, (int)y0f, (int)z0f, fx - x0f, fy - y0f, fz - z0f};
  return c;
}

/* Trilinear value of the dense grid `data` (nx·ny·nz floats, x fastest, all finite, nx·ny < 2^31)
 * at index-space point p (notes above). Inside [0.5, n - 0.5] on every axis it reproduces a field
 * linear in x, y and z (to rounding); NaN coordinates read 0. */
static inline float grid_trilinear(NV_GLOBAL const float* data, int nx, int ny, int nz, vec3 p) {
  const grid_cell cell = grid_locate(p);
  const int x0 = cell.x0, y0 = cell.y0, z0 = cell.z0;
  const float ax = cell.ax, ay = cell.ay, az = cell.az;
  if (x0 >= 0 && y0 >= 0 && z0 >= 0 && x0 < nx - 1 && y0 < ny - 1 && z0 < nz - 1) {
    /* All eight corners inside (almost every lookup): one base address, fixed strides, the same
     * products and sums as below, so the same bits, and faster (bench/RESULTS.md). nx·ny fits an
     * int (the host refuses larger slices); the base is size_t for big grids. */
    const int sy = nx, sz = nx * ny;
    NV_GLOBAL const float* b = data + ((size_t)x0 + (size_t)sy * (size_t)y0 + (size_t)sz * (size_t)z0);
    return grid_trilinear_combine(b[0], b[1], b[sy], b[sy + 1], b[sz], b[sz + 1], b[sz + sy], b[sz + sy + 1],
                                  1.0f - ax, ax, 1.0f - ay, ay, 1.0f - az, az);
  }
  /* Near or outside the faces: corners outside weigh 0 and read a clamped in-range voxel. */
  const float wx0 = grid_corner_weight(x0, nx, 1.0f - ax), wx1 = grid_corner_weight(x0 + 1, nx, ax);
  const float wy0 = grid_corner_weight(y0, ny, 1.0f - ay), wy1 = grid_corner_weight(y0 + 1, ny, ay);
  const float wz0 = grid_corner_weight(z0, nz, 1.0f - az), wz1 = grid_corner_weight(z0 + 1, nz, az);
  const size_t sx = (size_t)nx, sxy = (size_t)nx * (size_t)ny;
  const size_t xa = (size_t)grid_clamp_index(x0, nx), xb = (size_t)grid_clamp_index(x0 + 1, nx);
  const size_t ya = (size_t)grid_clamp_index(y0, ny) * sx, yb = (size_t)grid_clamp_index(y0 + 1, ny) * sx;
  const size_t za = (size_t)grid_clamp_index(z0, nz) * sxy, zb = (size_t)grid_clamp_index(z0 + 1, nz) * sxy;
  return grid_trilinear_combine(data[za + ya + xa], data[za + ya + xb], data[za + yb + xa], data[za + yb + xb],
                                data[zb + ya + xa], data[zb + ya + xb], data[zb + yb + xa], data[zb + yb + xb],
                                wx0, wx1, wy0, wy1, wz0, wz1);
}

/* Sparse bricks (-D GRID_STORAGE_BRICKS). Brick (bx, by, bz) owns voxels [8bx, 8bx + 7] × ... and
 * stores GRID_BRICK_STORED³ = 9³ values, x fastest: its own and a one-voxel apron on each + side (the
 * next brick's first layer; 0 beyond the grid). A lookup's corners xa = clamp(x0), xb = clamp(x0 + 1)
 * satisfy xb <= xa + 1 <= 8·(xa >> 3) + 8, so all eight lie in brick (xa >> 3, ya >> 3, za >> 3): one
 * index and one brick per lookup, for 9³/8³ = 1.42x the voxels (without the apron, up to eight indices).
 * The table holds per brick (x fastest) its pool slot, or GRID_BRICK_EMPTY when all 9³ values are 0:
 * eight zero corners give +0, returned without touching the pool. grid_trilinear's corners, weights and
 * combine give the same bits (tests/unit/brick_grid_test.cpp, tests/device/grid_storage_lookup_test.cpp).
 * Device layout, one buffer: GRID_BRICKS_HEADER 32-bit slots (nx, ny, nz as ints, then the pool's
 * offset in floats), the table (one uint per brick), padding to 16 bytes, the pool (9³ floats per
 * occupied brick). Built by host/volume/brick_grid.h. */
#define GRID_BRICKS_HEADER 4
#define GRID_BRICK_LOG2 3
#define GRID_BRICK 8
#define GRID_BRICK_STORED 9
#define GRID_BRICK_FLOATS 729 /* GRID_BRICK_STORED³ */
#define GRID_BRICK_EMPTY 0xffffffffu

/* Bricks along an axis of n voxels. */
static inline int grid_brick_count(int n) { return (n + GRID_BRICK - 1) >> GRID_BRICK_LOG2; }

/* grid_trilinear of the grid whose bricks are `table` and `pool` (see above; nx·ny·nz voxels,
 * all finite and >= 0), at index-space point p: the same value, bit for bit. */
static inline float grid_bricks_trilinear(NV_GLOBAL const uint* table, NV_GLOBAL const float* pool, int nx, int ny,
                                          int nz, vec3 p) {
  const grid_cell cell = grid_locate(p);
  const int x0 = cell.x0, y0 = cell.y0, z0 = cell.z0;
  const float ax = cell.ax, ay = cell.ay, az = cell.az;
  const int xa = grid_clamp_index(x0, nx), ya = grid_clamp_index(y0, ny), za = grid_clamp_index(z0, nz);
  const int bx = xa >> GRID_BRICK_LOG2, by = ya >> GRID_BRICK_LOG2, bz = za >> GRID_BRICK_LOG2;
  const uint slot = table[(size_t)bx + (size_t)grid_brick_count(nx) *
                                           ((size_t)by + (size_t)grid_brick_count(ny) * (size_t)bz)];
  if (slot == GRID_BRICK_EMPTY) return 0.0f;
  /* Offsets of the corners inside the brick: 0..8 along each axis. */
  const int ox = bx << GRID_BRICK_LOG2, oy = by << GRID_BRICK_LOG2, oz = bz << GRID_BRICK_LOG2;
  const int sy = GRID_BRICK_STORED, sz = GRID_BRICK_STORED * GRID_BRICK_STORED;
  const int lxa = xa - ox, lxb = grid_clamp_index(x0 + 1, nx) - ox;
  const int lya = (ya - oy) * sy, lyb = (grid_clamp_index(y0 + 1, ny) - oy) * sy;
  const int lza = (za - oz) * sz, lzb = (grid_clamp_index(z0 + 1, nz) - oz) * sz;
  NV_GLOBAL const float* b = pool + (size_t)slot * GRID_BRICK_FLOATS;
  return grid_trilinear_combine(b[lza + lya + lxa], b[lza + lya + lxb], b[lza + lyb + lxa], b[lza + lyb + lxb],
                                b[lzb + lya + lxa], b[lzb + lya + lxb], b[lzb + lyb + lxa], b[lzb + lyb + lxb],
                                grid_corner_weight(x0, nx, 1.0f - ax), grid_corner_weight(x0 + 1, nx, ax),
                                grid_corner_weight(y0, ny, 1.0f - ay), grid_corner_weight(y0 + 1, ny, ay),
                                grid_corner_weight(z0, nz, 1.0f - az), grid_corner_weight(z0 + 1, nz, az));
}

#ifdef NV_DEVICE

/* GRID_STORAGE is the type of one grid in the chosen storage, grid_value(g, p) its trilinear value
 * at index-space point p: the density grid and the emission grid (emission.h) share both. */
#ifdef MEDIUM_HOMOGENEOUS
#define GRID_STORAGE int /* unused */
#define GRID_IS_HOMOGENEOUS(g) 1
static inline float grid_value(GRID_STORAGE g, vec3 p) { return 1.0f; }
#elif defined(GRID_STORAGE_BRICKS)
#define GRID_STORAGE NV_GLOBAL const float*
#define GRID_IS_HOMOGENEOUS(g) 0
static inline float grid_value(GRID_STORAGE g, vec3 p) {
  const int4 h = vload4(0, (NV_GLOBAL const int*)g);
  return grid_bricks_trilinear((NV_GLOBAL const uint*)g + GRID_BRICKS_HEADER, g + h.w, h.x, h.y, h.z, p);
}
#elif defined(GRID_STORAGE_BUFFER)
#define GRID_STORAGE NV_GLOBAL const float*
#define GRID_IS_HOMOGENEOUS(g) 0
static inline float grid_value(GRID_STORAGE g, vec3 p) {
  const int4 h = vload4(0, (NV_GLOBAL const int*)g);
  return grid_trilinear(g + GRID_BUFFER_HEADER, h.x, h.y, h.z, p);
}
#else
#define GRID_STORAGE read_only image3d_t
#define GRID_IS_HOMOGENEOUS(g) 0
__constant sampler_t grid_sampler = CLK_NORMALIZED_COORDS_FALSE | CLK_ADDRESS_CLAMP | CLK_FILTER_LINEAR;
static inline float grid_value(GRID_STORAGE g, vec3 p) {
  /* Callers stay inside the box; the clamp keeps wild coordinates off the far edge (DESIGN.md). */
  const float4 q = (float4)(clamp(p.x, -1.0f, 1.0e7f), clamp(p.y, -1.0f, 1.0e7f), clamp(p.z, -1.0f, 1.0e7f), 0.0f);
  return read_imagef(g, grid_sampler, q).x;
}
#endif

/* Whether a grid of this storage can be a field of the kernels' context struct
 * (kernel_context.h): everything but an image (OpenCL C forbids images in structs). */
#if defined(MEDIUM_HOMOGENEOUS) || defined(GRID_STORAGE_BRICKS) || defined(GRID_STORAGE_BUFFER)
#define GRID_STORAGE_IN_CONTEXT 1
#else
#define GRID_STORAGE_IN_CONTEXT 0
#endif

#else /* host */

typedef struct grid_view {
  const float* data; /* NULL: homogeneous, density 1 */
  int nx, ny, nz;
  const float* majorants; /* per-cell density bounds (medium_params.majorant_grid); NULL: no skipping */
  /* Emission (emission.h, read with -DEMISSION): the emission grid (NULL: none) and the blackbody
   * table (medium_params.emission). */
  const float* emission_data;
  int emission_nx, emission_ny, emission_nz;
  const float* emission_table;
} grid_view;

/* The density of a host grid view at index-space point p (what grid_density reads on the host). */
static inline float grid_view_density(const grid_view* g, vec3 p) {
  if (!g->data) return 1.0f;
  return grid_trilinear(g->data, g->nx, g->ny, g->nz, p);
}
#endif

#endif
