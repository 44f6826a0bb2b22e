/* ms_cache.cl: adds `count` paths per node to the multiple-scattering cache (shared/ms_cache_build.h),
 * paths [first, first + count) of nodes [node_first, node_first + node_count), after the view layout's
 * nodes were placed (once per cache). One work-item per node of the range (1D, padded to a multiple of
 * the local size): a budgeted refinement adds a sweep's paths a slice of nodes at a time
 * (host/render/device_ms_cache.cpp). `scene` is the scene with one bounce fewer (ms_cache.h, "Bounces"). */
#include "shared/scene_kinds.h"
#include "shared/ms_cache_build.h"
#include "shared/ms_cache_filter.h"
#include "shared/ms_cache_reproject.h"

__kernel void ms_cache_build(KERNEL_SCENE_ARGS, ms_cache_params ms_cache, uint node_first, uint node_count,
                             uint first, uint count, __global float* cache, __global uint* status_word) {
  if (get_global_id(0) >= node_count) return;
  const int node = (int)(node_first + get_global_id(0));
  if (node >= node_grid_count(&ms_cache.grid)) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | ms_cache_kinds_status(&ms_cache); /* STATUS_UNKNOWN_KIND */
  ms_cache_build_node(KERNEL_ENTRY_ARG(ctx), &ms_cache, node, cache + (size_t)node * MS_CACHE_STRIDE, first, count);
  if (ctx.status) atomic_or(status_word, ctx.status);
}

/* The view layout's placement (ms_cache_view.h, ms_view_place_column): one work-item per column of
 * [column_first, column_first + column_count), every column once when the cache starts over, before
 * ms_cache_build. */
__kernel void ms_cache_place_view(KERNEL_SCENE_ARGS, ms_cache_params ms_cache, uint column_first, uint column_count,
                                  __global float* cache, __global uint* status_word) {
  if (get_global_id(0) >= column_count) return;
  const int column = (int)(column_first + get_global_id(0));
  if (column >= ms_cache.grid.nx * ms_cache.grid.ny) return;
  KERNEL_CONTEXT_BEGIN(ctx);
  ctx.status = scene_kinds_status(scene, lights) | ms_cache_kinds_status(&ms_cache); /* STATUS_UNKNOWN_KIND */
  ms_view_place_column(KERNEL_ENTRY_ARG(ctx), &ms_cache, column, cache + (size_t)column * MS_CACHE_STRIDE);
  if (ctx.status) atomic_or(status_word, ctx.status);
}

/* The view layout's filter (ms_cache_filter.h): one work-item per column of
 * [column_first, column_first + column_count), after the paths changed; `filtered` (the cache's layout,
 * a copy of each node with its R filtered) is what the march reads once every column is done. The
 * weights from `cache`, the values from `values`: the cache itself, or with `residual` 1 the first
 * pass's output, for twicing's second pass. */
__kernel void ms_cache_filter_view(ms_cache_params ms_cache, uint column_first, uint column_count,
                                   __global const float* cache, __global const float* values, int residual,
                                   __global float* filtered) {
  if (get_global_id(0) >= column_count) return;
  const int column = (int)(column_first + get_global_id(0));
  if (column >= ms_cache.grid.nx * ms_cache.grid.ny) return;
  ms_view_filter_column(&ms_cache.grid, cache, values, residual, column, ms_cache.filter, MS_VIEW_FILTER_TOLERANCE,
                        filtered + (size_t)column * MS_CACHE_STRIDE);
}

/* The view layout's reprojection over a camera move (ms_cache_reproject.h): one work-item per node of
 * `placed` (placed for `scene`'s camera), read from `previous` (`previous_cache`, drawn for
 * `previous_camera`) into `prior`. */
__kernel void ms_cache_reproject_view(__constant scene_params* scene, ms_cache_params ms_cache,
                                      ms_cache_params previous_cache, camera_params previous_camera,
                                      __global const float* previous, __global const float* placed,
                                      __global float* prior) {
  const int node = (int)get_global_id(0);
  if (node >= node_grid_count(&ms_cache.grid)) return;
  ms_view_reproject_node(&scene->camera, scene->medium.phase, &previous_camera, &ms_cache, &previous_cache, previous,
                         placed, node, prior + (size_t)node * MS_CACHE_STRIDE);
}

/* The drawn cache while the new paths replace the reprojected prior (ms_cache_reproject.h, "Blend"): one
 * work-item per node; `fresh` the new paths' running means or their filtered copy. */
__kernel void ms_cache_blend_view(ms_cache_params ms_cache, int target, __global const float* prior,
                                  __global const float* fresh, __global float* drawn) {
  const int node = (int)get_global_id(0);
  if (node >= node_grid_count(&ms_cache.grid)) return;
  const size_t at = (size_t)node * MS_CACHE_STRIDE;
  ms_view_blend_node(prior + at, fresh + at, target, drawn + at);
}
