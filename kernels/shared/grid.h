/* grid.h: the one function through which every kernel reads density, grid_density(GRID_ARG, p),
 * with p in grid index space (voxel i covers [i, i+1], centre i + 0.5; trilinear; 0 outside).
 * Storage is chosen here and nowhere else; the kernel signatures are the same for every choice
 * (GRID_KERNEL_PARAM is always two arguments: the grid, then the majorant cells):
 * - device, -D MEDIUM_HOMOGENEOUS: 1 everywhere (the grid argument is an unused int);
 * - device, -D GRID_STORAGE_BUFFER: a __global float buffer (GRID_BUFFER_HEADER, then the voxels,
 *   x fastest) filtered by grid_trilinear below: the code the host runs;
 * - device, otherwise: a 3D image (CL_R, CL_FLOAT) read with the sampler (hardware filtering);
 * - host: grid_trilinear on a float array, so tests and a native baseline see the same field.
 * The host picks the storage per device (render/device_grid.h, scene key renderer.storage).
 * GRID_PARAM also carries the majorant grid's per-cell bounds (GRID_MAJORANTS), so every function
 * that reads density can skip empty space (march.h) without another parameter.
 *
 * Image and buffer reconstruct the same field; they differ in arithmetic only:
 * - Addressing: the sampler is CLK_ADDRESS_CLAMP (border colour 0: density outside the grid is 0,
 *   so the field fades to 0 over the half voxel outside the outermost voxel centres), not
 *   CLK_ADDRESS_CLAMP_TO_EDGE (which would repeat the edge voxels outwards). grid_trilinear reads 0
 *   for every corner outside the grid in the same way.
 * - Filtering: CLK_FILTER_LINEAR with unnormalised coordinates takes texel centres at i + 0.5:
 *   u = p - 0.5, i0 = floor(u), a = u - i0, and sums the eight corners as
 *   (1-a)(1-b)(1-c)·T000 + a(1-b)(1-c)·T100 + ... (the OpenCL spec's form, which PoCL computes in
 *   float). grid_trilinear computes the same a, b, c and nests three lerps instead. Both are sums
 *   of non-negative terms, so each is within a few float roundings of the exact value relative to
 *   the result: on PoCL image and buffer agree within 16 ε of the density, ε = 2^-24 (measured:
 *   5 ε; tests/device/grid_storage_lookup_test.cpp), and the buffer on the device matches the
 *   host bit for bit. Rendered pixels: tests/render/grid_storage_test.cpp.
 * - Many GPUs (NVIDIA among them; CUDA's texture units store a, b, c in 9-bit fixed point with 8
 *   fractional bits) quantise the weights to multiples of 1/256: a lookup may then be off by up to
 *   1/256 of the difference between neighbouring voxels along each axis (an H100 was measured at
 *   0.0079 of the eight corners' range, against 3/256 = 0.0117). The buffer is exact float
 *   arithmetic on every device (bit for bit the host's, on PoCL and on that H100); the image is
 *   still the right choice on GPUs: there it did 1.8-2.7x the buffer's lookups per second.
 * - The coordinate is clamped to [-1, 1e7] first: clamp addressing sends huge or infinite
 *   coordinates to the wrong edge on some devices (DESIGN.md), and here it keeps the int
 *   conversions defined. -1 is outside the grid by more than half a voxel: density 0. */
#ifndef NARVAL_GRID_H
#define NARVAL_GRID_H

#include "shared/vec3.h"

/* The float buffer's layout: GRID_BUFFER_HEADER 32-bit slots (nx, ny, nz as ints, then 0; 16 bytes,
 * so the voxels stay 16-byte aligned), then nx·ny·nz floats, x fastest (the 3D image's order). */
#define GRID_BUFFER_HEADER 4

/* The weight of a corner at index i along an axis of n voxels: w inside the grid, 0 outside
 * (border colour 0). */
static inline float grid_corner_weight(int i, int n, float w) { return (i >= 0 && i < n) ? w : 0.0f; }

/* i clamped into [0, n-1]: corners outside the grid read an in-range voxel with weight 0, so all
 * eight loads are in bounds without a branch per corner. */
static inline int grid_clamp_index(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }

/* Trilinear reconstruction of the dense grid `data` (nx·ny·nz floats, x fastest, all finite,
 * nx·ny < 2^31) at
 * index-space point p, with voxel centres at i + 0.5 and 0 outside the grid (see the notes above).
 * Inside [0.5, n - 0.5] on every axis it reproduces a field linear in x, y and z exactly (up to
 * float rounding); NaN coordinates read 0. */
static inline float grid_trilinear(NV_GLOBAL const float* data, int nx, int ny, int nz, vec3 p) {
  const float fx = nv_fmin(nv_fmax(p.x, -1.0f), 1.0e7f) - 0.5f;
  const float fy = nv_fmin(nv_fmax(p.y, -1.0f), 1.0e7f) - 0.5f;
  const float fz = nv_fmin(nv_fmax(p.z, -1.0f), 1.0e7f) - 0.5f;
  const float x0f = nv_floor(fx), y0f = nv_floor(fy), z0f = nv_floor(fz);
  const int x0 = (int)x0f, y0 = (int)y0f, z0 = (int)z0f;
  const float ax = fx - x0f, ay = fy - y0f, az = fz - z0f;
  if (x0 >= 0 && y0 >= 0 && z0 >= 0 && x0 < nx - 1 && y0 < ny - 1 && z0 < nz - 1) {
    /* All eight corners inside (almost every lookup): one base address and fixed strides, the
     * same products and sums as below (weights 1 - a and a), so the same bits. The slice stride
     * nx·ny fits an int (the host refuses larger slices); the base is size_t for big grids.
     * Measured 1.2-1.3x the lookups/s of the general path alone on PoCL, 1.0-1.15x on an H100. */
    const int sy = nx, sz = nx * ny;
    NV_GLOBAL const float* b = data + ((size_t)x0 + (size_t)sy * (size_t)y0 + (size_t)sz * (size_t)z0);
    const float bx0 = 1.0f - ax, by0 = 1.0f - ay, bz0 = 1.0f - az;
    const float i00 = b[0] * bx0 + b[1] * ax;
    const float i01 = b[sy] * bx0 + b[sy + 1] * ax;
    const float i10 = b[sz] * bx0 + b[sz + 1] * ax;
    const float i11 = b[sz + sy] * bx0 + b[sz + sy + 1] * ax;
    return (i00 * by0 + i01 * ay) * bz0 + (i10 * by0 + i11 * ay) * az;
  }
  /* Near or outside the faces: corners outside weigh 0 and read a clamped in-range voxel. */
  const float wx0 = grid_corner_weight(x0, nx, 1.0f - ax), wx1 = grid_corner_weight(x0 + 1, nx, ax);
  const float wy0 = grid_corner_weight(y0, ny, 1.0f - ay), wy1 = grid_corner_weight(y0 + 1, ny, ay);
  const float wz0 = grid_corner_weight(z0, nz, 1.0f - az), wz1 = grid_corner_weight(z0 + 1, nz, az);
  const size_t sx = (size_t)nx, sxy = (size_t)nx * (size_t)ny;
  const size_t xa = (size_t)grid_clamp_index(x0, nx), xb = (size_t)grid_clamp_index(x0 + 1, nx);
  const size_t ya = (size_t)grid_clamp_index(y0, ny) * sx, yb = (size_t)grid_clamp_index(y0 + 1, ny) * sx;
  const size_t za = (size_t)grid_clamp_index(z0, nz) * sxy, zb = (size_t)grid_clamp_index(z0 + 1, nz) * sxy;
  /* x, then y, then z: value · weight, in the order the host's reference always used. */
  const float c00 = data[za + ya + xa] * wx0 + data[za + ya + xb] * wx1;
  const float c01 = data[za + yb + xa] * wx0 + data[za + yb + xb] * wx1;
  const float c10 = data[zb + ya + xa] * wx0 + data[zb + ya + xb] * wx1;
  const float c11 = data[zb + yb + xa] * wx0 + data[zb + yb + xb] * wx1;
  const float c0 = c00 * wy0 + c01 * wy1;
  const float c1 = c10 * wy0 + c11 * wy1;
  return c0 * wz0 + c1 * wz1;
}

#ifdef NV_DEVICE

#ifdef MEDIUM_HOMOGENEOUS
#define GRID_PARAM int grid_unused, NV_GLOBAL const float* grid_majorants
#define GRID_ARG grid_unused, grid_majorants
#define GRID_KERNEL_PARAM GRID_PARAM
#define GRID_MAJORANTS grid_majorants
#define GRID_IS_HOMOGENEOUS(g) 1
static inline float grid_density(GRID_PARAM, vec3 p) { return 1.0f; }
#elif defined(GRID_STORAGE_BUFFER)
#define GRID_PARAM NV_GLOBAL const float* grid, NV_GLOBAL const float* grid_majorants
#define GRID_ARG grid, grid_majorants
#define GRID_KERNEL_PARAM GRID_PARAM
#define GRID_MAJORANTS grid_majorants
#define GRID_IS_HOMOGENEOUS(g) 0
static inline float grid_density(GRID_PARAM, vec3 p) {
  const int4 h = vload4(0, (NV_GLOBAL const int*)grid);
  return grid_trilinear(grid + GRID_BUFFER_HEADER, h.x, h.y, h.z, p);
}
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

static inline float grid_density(GRID_PARAM, vec3 p) {
  if (!grid->data) return 1.0f;
  return grid_trilinear(grid->data, grid->nx, grid->ny, grid->nz, p);
}

#endif

#endif
