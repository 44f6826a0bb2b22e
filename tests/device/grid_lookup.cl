/* Test kernel: grid_value (what grid_density reads) at a batch of index-space points, in the grid
 * storage the program is built for (-DGRID_STORAGE_BUFFER: the float buffer; -DGRID_STORAGE_BRICKS:
 * sparse bricks; otherwise the 3D image and its sampler). */
#include "shared/grid.h"

__kernel void grid_lookup(GRID_STORAGE grid, __global const float* grid_majorants, __global const float4* points,
                          __global float* out) {
  const int i = get_global_id(0);
  const float4 q = points[i];
  out[i] = grid_value(grid, vec3_make(q.x, q.y, q.z));
}
