/* kernel_context.h: what every kernel function works on, in one struct: the scene, its lights and
 * medium, the density and emission grids, the majorant cells, the blackbody table, the status word
 * and the collision counters. A kernel's entry fills it once (kernel_context_begin) and passes its
 * address down; a new grid, table or tally is a field here and in the entries, not a parameter
 * spliced into every signature.
 * One exception, OpenCL's: an image may not be a struct member (OpenCL C 6.9), so with image storage
 * (the default on GPUs, grid.h) the two grid images travel beside the context:
 * KERNEL_CONTEXT_PARAM / KERNEL_CONTEXT_ARG are the context pointer, plus the images in that build.
 * The host (tests, the native baseline) reads its grids through a grid_view (grid.h). */
#ifndef NARVAL_KERNEL_CONTEXT_H
#define NARVAL_KERNEL_CONTEXT_H

#include "shared/grid.h"
#include "shared/structs.h"

/* Counters (-DCOUNTERS on the device; always present on the host): per work-item counts of
 * tentative (delta/spectral tracking) and real (absorbing or scattering) collisions and of density
 * lookups (both walks), in private 64-bit integers; the kernel adds them to per-pixel slots of its
 * own (pathtrace.cl), the host sums those: no atomics, no floats, no overflow (2^64). Without
 * COUNTERS every count vanishes from the source. Every delta-tracking tentative collision reads the
 * density once, so lookups − tentative = the ratio-tracking lookups of the shadow rays. */
typedef struct track_counters {
  nv_ulong tentative;
  nv_ulong real;
  nv_ulong lookups;
} track_counters;

typedef struct kernel_context {
  NV_CONSTANT const scene_params* scene;
  NV_CONSTANT const light_params* lights;
  NV_CONSTANT const medium_params* medium; /* &scene->medium (host tests may point it at a medium alone) */
#ifdef NV_DEVICE
#if GRID_STORAGE_IN_CONTEXT
  GRID_STORAGE grid;          /* the density grid (buffer or bricks; homogeneous: an unused int) */
  GRID_STORAGE emission_grid; /* the emission grid, or the density grid again (emission.h) */
#endif
  NV_GLOBAL const float* majorants;      /* the majorant grid's per-cell density bounds */
  NV_GLOBAL const float* emission_table; /* the blackbody table (emission.h) */
#else
  const grid_view* grids; /* density, majorant cells, emission grid and table */
#endif
  uint status; /* STATUS_* bits (structs.h), ORed by every function */
#if !defined(NV_DEVICE) || defined(COUNTERS)
  track_counters counters;
#endif
} kernel_context;

#ifdef NV_DEVICE
#if GRID_STORAGE_IN_CONTEXT
#define KERNEL_CONTEXT_PARAM NV_PRIVATE kernel_context* ctx
#define KERNEL_CONTEXT_ARG ctx
#else
#define KERNEL_CONTEXT_PARAM NV_PRIVATE kernel_context* ctx, GRID_STORAGE grid_image, GRID_STORAGE emission_image
#define KERNEL_CONTEXT_ARG ctx, grid_image, emission_image
#endif
/* The arguments every kernel starts with (cl/kernel_args.h binds them by name). */
#define KERNEL_SCENE_ARGS                                                                              \
  __constant scene_params *scene, __constant light_params *lights, GRID_STORAGE grid,                  \
      __global const float *grid_majorants, GRID_STORAGE emission_grid, __global const float *emission_table

/* The context of a kernel's entry over its KERNEL_SCENE_ARGS. */
#if GRID_STORAGE_IN_CONTEXT
#define KERNEL_CONTEXT_BEGIN(ctx)                                                                      \
  kernel_context ctx = kernel_context_begin(scene, lights, grid_majorants, emission_table);            \
  ctx.grid = grid;                                                                                     \
  ctx.emission_grid = emission_grid
#else
#define KERNEL_CONTEXT_BEGIN(ctx)                                                                      \
  kernel_context ctx = kernel_context_begin(scene, lights, grid_majorants, emission_table);            \
  (void)0
#endif
/* After KERNEL_CONTEXT_BEGIN(ctx) at a kernel's entry: the arguments its functions take. */
#if GRID_STORAGE_IN_CONTEXT
#define KERNEL_ENTRY_ARG(ctx) &ctx
#else
#define KERNEL_ENTRY_ARG(ctx) &ctx, grid, emission_grid
#endif

static inline kernel_context kernel_context_begin(__constant scene_params* scene, __constant light_params* lights,
                                                  __global const float* majorants,
                                                  __global const float* emission_table) {
  kernel_context c;
  c.scene = scene;
  c.lights = lights;
  c.medium = &scene->medium;
  c.majorants = majorants;
  c.emission_table = emission_table;
  c.status = 0u;
#ifdef COUNTERS
  c.counters.tentative = c.counters.real = c.counters.lookups = 0u;
#endif
  return c;
}
/* A context over a medium alone (test kernels of one function): no scene, lights or emission. */
static inline kernel_context kernel_context_of_medium(__constant medium_params* m, __global const float* majorants) {
  kernel_context c;
  c.scene = 0;
  c.lights = 0;
  c.medium = m;
  c.majorants = majorants;
  c.emission_table = 0;
  c.status = 0u;
#ifdef COUNTERS
  c.counters.tentative = c.counters.real = c.counters.lookups = 0u;
#endif
  return c;
}
#else /* host */
#define KERNEL_CONTEXT_PARAM kernel_context* ctx
#define KERNEL_CONTEXT_ARG ctx

/* A host context over a medium and its grids (scene and lights optional: NULL). */
static inline kernel_context kernel_context_host(const scene_params* scene, const light_params* lights,
                                                 const medium_params* medium, const grid_view* grids) {
  kernel_context c;
  c.scene = scene;
  c.lights = lights;
  c.medium = medium ? medium : (scene ? &scene->medium : 0);
  c.grids = grids;
  c.status = 0u;
  c.counters.tentative = c.counters.real = c.counters.lookups = 0u;
  return c;
}
#endif

#if !defined(NV_DEVICE) || defined(COUNTERS)
#define TRACK_COUNT(field) (ctx->counters.field += 1u)
#else
#define TRACK_COUNT(field) ((void)0)
#endif

/* The density at index-space point p (grid.h's storage), and the majorant cells. */
#ifdef NV_DEVICE
#ifdef MEDIUM_HOMOGENEOUS
static inline float grid_density(KERNEL_CONTEXT_PARAM, vec3 p) { return 1.0f; }
#elif GRID_STORAGE_IN_CONTEXT
static inline float grid_density(KERNEL_CONTEXT_PARAM, vec3 p) { return grid_value(ctx->grid, p); }
#else
static inline float grid_density(KERNEL_CONTEXT_PARAM, vec3 p) { return grid_value(grid_image, p); }
#endif
#define GRID_MAJORANTS (ctx->majorants)
#define GRID_IS_HOMOGENEOUS_CTX(ctx) GRID_IS_HOMOGENEOUS(0)
#else
static inline float grid_density(KERNEL_CONTEXT_PARAM, vec3 p) { return grid_view_density(ctx->grids, p); }
#define GRID_MAJORANTS (ctx->grids->majorants)
#define GRID_IS_HOMOGENEOUS_CTX(ctx) ((ctx)->grids->data == 0)
#endif

#endif
