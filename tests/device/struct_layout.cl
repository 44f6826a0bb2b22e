/* struct_layout.cl: the size and field offsets of every struct that crosses host and device
 * (kernels/shared/structs.h, and the vec3.h storage types they are built from), as the OpenCL
 * compiler lays them out. tests/device/struct_layout_test.cpp includes this very file as C++ to get
 * the same list, so the host and device lists cannot drift apart; only the kernel is OpenCL-only.
 * Output: out[0] = number of entries, then per entry one value: sizeof(type) for STRUCT_LAYOUT_SIZE,
 * offsetof and sizeof of the field for STRUCT_LAYOUT_FIELD (two values). */
#include "shared/structs.h"

/* offsetof is not part of OpenCL C 1.2; clang (and GCC, on the host) provide the builtin. */
#define STRUCT_LAYOUT_OFFSETOF(type, field) __builtin_offsetof(type, field)
#define STRUCT_LAYOUT_FIELD_SIZE(type, field) sizeof(((type*)0)->field)

/* S(type): the struct's size. F(type, field): one field (nested designators allowed). */
#define STRUCT_LAYOUT_ENTRIES(S, F)                                                                \
  S(nv_float4) F(nv_float4, x) F(nv_float4, y) F(nv_float4, z) F(nv_float4, w)                     \
  S(nv_affine) F(nv_affine, row[0]) F(nv_affine, row[1]) F(nv_affine, row[2])                     \
  S(camera_params) F(camera_params, position) F(camera_params, forward) F(camera_params, right)     \
  F(camera_params, up) F(camera_params, tan_half_vfov) F(camera_params, aspect)                    \
  F(camera_params, lens_radius) F(camera_params, focus_distance) F(camera_params, width)           \
  F(camera_params, height) F(camera_params, pad0) F(camera_params, pad1)                           \
  S(light_params) F(light_params, corner) F(light_params, edge_u) F(light_params, edge_v)          \
  F(light_params, normal) F(light_params, radiance) F(light_params, type) F(light_params, select_prob)\
  F(light_params, pad0) F(light_params, pad1)                                                       \
  S(medium_params) F(medium_params, world_to_index) F(medium_params, world_to_index.row[2])        \
  F(medium_params, dims) F(medium_params, sigma_a) F(medium_params, sigma_s)                       \
  F(medium_params, majorant) F(medium_params, grey) F(medium_params, pad0) F(medium_params, pad1)  \
  F(medium_params, phase) F(medium_params, phase.kind)                                             \
  F(medium_params, majorant_grid) F(medium_params, majorant_grid.cells_z)                         \
  F(medium_params, emission) F(medium_params, emission.kind)                                       \
  S(phase_params) F(phase_params, coef) F(phase_params, kind) F(phase_params, pad0)                 \
  F(phase_params, pad1) F(phase_params, pad2)                                                      \
  S(emission_params) F(emission_params, index_to_grid) F(emission_params, grid_dims)              \
  F(emission_params, color) F(emission_params, temperature_offset)                                \
  F(emission_params, temperature_scale) F(emission_params, table_max) F(emission_params, table_size)\
  F(emission_params, kind) F(emission_params, pad0) F(emission_params, pad1) F(emission_params, pad2)\
  S(majorant_grid_params) F(majorant_grid_params, cell_size) F(majorant_grid_params, cells_x)     \
  F(majorant_grid_params, cells_y) F(majorant_grid_params, cells_z) F(majorant_grid_params, pad0)  \
  S(scene_params) F(scene_params, camera) F(scene_params, camera.height) F(scene_params, medium)    \
  F(scene_params, medium.sigma_s) F(scene_params, medium.grey) F(scene_params, background)         \
  F(scene_params, has_medium) F(scene_params, num_lights) F(scene_params, max_bounces)             \
  F(scene_params, seed) F(scene_params, light_sampling) F(scene_params, shadow_roulette)           \
  F(scene_params, pad0) F(scene_params, pad1)                                                     \
  S(march_params) F(march_params, steps) F(march_params, shadow_steps) F(march_params, min_transmittance) \
  F(march_params, area_light_samples) F(march_params, shadow_area_samples) F(march_params, area_light_phase) \
  F(march_params, shadow_weighting) F(march_params, octaves) F(march_params, octave_a)                   \
  F(march_params, octave_b) F(march_params, octave_c) F(march_params, pad0)                               \
  S(lobe_params) F(lobe_params, depth_factor) F(lobe_params, radius) F(lobe_params, points)               \
  F(lobe_params, view_steps) F(lobe_params, variant) F(lobe_params, pad0) F(lobe_params, pad1)            \
  F(lobe_params, pad2)                                                                                    \
  S(ms_cache_params) F(ms_cache_params, grid) F(ms_cache_params, grid.nz) F(ms_cache_params, closure)     \
  F(ms_cache_params, layout) F(ms_cache_params, tile) F(ms_cache_params, direct)                          \
  F(ms_cache_params, filter_twicing) F(ms_cache_params, filter) F(ms_cache_params, pad0)                  \
  F(ms_cache_params, pad1)                                                                                \
  S(node_grid_params) F(node_grid_params, index_to_world) F(node_grid_params, nx)           \
  F(node_grid_params, ny) F(node_grid_params, nz) F(node_grid_params, pad0)

#ifdef __OPENCL_C_VERSION__

#define STRUCT_LAYOUT_PUT(v) \
  do {                       \
    if (n < capacity) out[n] = (uint)(v); \
    ++n;                     \
  } while (0);
#define STRUCT_LAYOUT_DEVICE_SIZE(type) STRUCT_LAYOUT_PUT(sizeof(type))
#define STRUCT_LAYOUT_DEVICE_FIELD(type, field)            \
  STRUCT_LAYOUT_PUT(STRUCT_LAYOUT_OFFSETOF(type, field)) \
  STRUCT_LAYOUT_PUT(STRUCT_LAYOUT_FIELD_SIZE(type, field))

__kernel void struct_layout(__global uint* out, uint capacity) {
  if (get_global_id(0) != 0) return;
  uint n = 1u;
  STRUCT_LAYOUT_ENTRIES(STRUCT_LAYOUT_DEVICE_SIZE, STRUCT_LAYOUT_DEVICE_FIELD)
  out[0] = n - 1u;
}

#endif
