/* structs.h: every struct that crosses host and device, declared once. Fields are 4-byte scalars
 * or nv_float4 (four floats), padded explicitly to a multiple of 16 bytes, so the layout is the
 * same in C++ and OpenCL C; tests/device/struct_layout_test.cpp checks every offset on the device. */
#ifndef NARVAL_STRUCTS_H
#define NARVAL_STRUCTS_H

#include "shared/emission_kinds.h"
#include "shared/light_kinds.h"
#include "shared/phase_kinds.h"
#include "shared/vec3.h"

/* Next-event estimation in the path tracer (scene_params.light_sampling; light_select.h). */
#define LIGHT_SAMPLING_ALL 0 /* a shadow ray to every light at every scattering event */
#define LIGHT_SAMPLING_ONE 1 /* one light per event, picked with light_params.select_prob */


/* Status word bits: kernels OR these into a global uint; the host reports them. */
#define STATUS_NAN 1u
#define STATUS_NEGATIVE_PDF 2u
#define STATUS_ITERATION_CAP 4u
/* A phase function or light kind the kernels do not know reached them (scene_kinds.h): the host
 * validates kinds before uploading, so this means a host and kernels out of step. */
#define STATUS_UNKNOWN_KIND 8u

/* What a kernel keeps of an estimate (a pixel, a path, a cache node): L when finite, else 0 with
 * STATUS_NAN raised, so one bad sample is reported instead of spreading. */
static inline vec3 status_finite_or_zero(NV_PRIVATE uint* status, vec3 L) {
  if (vec3_is_finite(L)) return L;
  *status |= STATUS_NAN;
  return vec3_splat(0.0f);
}

/* Pinhole or thin-lens camera. Pixel (0,0) is the top-left corner of the image. */
typedef struct camera_params {
  nv_float4 position;
  nv_float4 forward;  /* unit view direction */
  nv_float4 right;    /* unit, image +x */
  nv_float4 up;       /* unit, image -y (pixel rows grow downwards) */
  float tan_half_vfov;
  float aspect;       /* width / height */
  float lens_radius;  /* 0: pinhole */
  float focus_distance;
  int width;
  int height;
  int pad0;
  int pad1;
} camera_params;

/* One emitter. Rectangle: corner + s*edge_u + t*edge_v, s,t in [0,1], emitting `radiance` one-sided
 * along `normal`; normal.w holds the area. Point: `corner` is the position, `radiance` the intensity in
 * W/sr. select_prob: the chance NEE picks this light when it picks one per event (light_select.h). */
typedef struct light_params {
  nv_float4 corner;
  nv_float4 edge_u;
  nv_float4 edge_v;
  nv_float4 normal;
  nv_float4 radiance;
  int type;
  float select_prob;
  int pad0;
  int pad1;
} light_params;

/* The coarse majorant grid over the medium's index box (host/volume/majorant_grid.h; the DDA in
 * majorant_dda.h); the per-cell density bounds travel in their own buffer. */
typedef struct majorant_grid_params {
  nv_float4 cell_size; /* xyz: index units per cell along each axis (dims / cells); w unused */
  int cells_x;
  int cells_y;
  int cells_z;
  int pad0;
} majorant_grid_params;

/* Emission of the medium (pbrt-v4's model: σa(x)·Le(x) per unit length). The emission grid has its
 * own index space (transform and bounding box in the file). The blackbody table (host/colour/blackbody.h):
 * table_size linear-sRGB entries evenly over [0, table_max] kelvin, 0 at or below 100 K. */
typedef struct emission_params {
  nv_affine index_to_grid; /* medium index space → emission grid index space */
  nv_float4 grid_dims;     /* the emission grid's resolution; x = 0: no grid (v = 1) */
  nv_float4 color;         /* colour · scale (EMISSION_COLOR), scale in each channel (EMISSION_BLACKBODY) */
  float temperature_offset;
  float temperature_scale;
  float table_max;         /* kelvin of the table's last entry */
  int table_size;          /* entries (rgb triples) in the table */
  int kind;                /* emission_kinds.h */
  int pad0, pad1, pad2;
} emission_params;

/* A phase function: its kind (phase_kinds.h) and the kind's own constants (its header,
 * phase_<kind>.h, says which; HG: coef.x = g). */
typedef struct phase_params {
  nv_float4 coef;
  int kind;
  int pad0;
  int pad1;
  int pad2;
} phase_params;

/* The participating medium: the box [0, dims] in grid index space (grid.h), reached from world space by
 * one affine map. Coefficients are per unit density, times the material's density multiplier D. */
typedef struct medium_params {
  nv_affine world_to_index;
  nv_float4 dims;       /* grid resolution as floats; (1,1,1) for a homogeneous box */
  nv_float4 sigma_a;    /* absorption · D */
  nv_float4 sigma_s;    /* scattering · D */
  float majorant;       /* >= max over the box and channels of sigma_t(x) */
  int grey;             /* 1: sigma_a and sigma_s are equal in all channels (analogue tracking) */
  int pad0;
  int pad1;
  phase_params phase;
  majorant_grid_params majorant_grid; /* density bounds per cell: empty space is skipped */
  emission_params emission;
} medium_params;

/* A grid of nodes spanning the medium's index box corner to corner (kernels/shared/node_grid.h):
 * the layout of the real-time caches. nx = 0: no grid. */
typedef struct node_grid_params {
  nv_affine index_to_world; /* node points to world space (the inverse of medium.world_to_index) */
  int nx;
  int ny;
  int nz;
  int pad0;
} node_grid_params;

/* Lobe Estimator variants (lobe.h): the dissertation's Eq. 7, and the corrected estimator. */
#define LOBE_EQ7 0
#define LOBE_CORRECTED 1

/* The real-time kernels' phase over a rectangle light (march_light_phase): K×K points
 * (K = march_params.area_light_samples; 1, the centre, is the dissertation's) or exact (phase_polygon.h). */
#define AREA_LIGHT_POINTS 0
#define AREA_LIGHT_EXACT 1

/* How the multiple-scattering cache answers for a direction (ms_cache.h, "Closure"): from its two
 * moments, or (CAMERA) with the in-scattering towards the camera estimated directly. */
#define MS_CACHE_CLOSURE_LINEAR 0
#define MS_CACHE_CLOSURE_CAMERA 2 /* 1 was an HG lobe's closure (removed) */

/* How a rectangle's shadow weights its K×K points (march_light_column): by each point's share of the
 * light reaching x (cos θ/d²), or (PHASE) of the light x scatters towards the camera (p(θ)·cos θ/d²). */
#define SHADOW_WEIGHTING_AREA 0
#define SHADOW_WEIGHTING_PHASE 1

/* Where the multiple-scattering cache's nodes are (ms_cache.h; ms_cache_view.h): a grid over the
 * medium's box, or columns over the image with nodes along each column's camera optical depth. */
#define MS_CACHE_LAYOUT_GRID 0
#define MS_CACHE_LAYOUT_VIEW 1

/* The real-time kernels' parameters, one block per feature, each its own kernel argument (by value,
 * bound by name: host/cl/kernel_args.cpp). DESIGN.md "raymarch", "lobe". */

/* The marches of the ray marcher, the lobe and the light cache's build (which marches their shadow
 * rays): sample counts, early stop, how rectangle lights are integrated. */
typedef struct march_params {
  int steps;                /* raymarch: samples over the view ray's segment; lobe: first-hit search samples */
  int shadow_steps;         /* samples per shadow ray (and per light-cache node when the cache is built) */
  float min_transmittance;  /* view marches stop once every channel's transmittance is below it; 0: never */
  int area_light_samples;   /* K: a rectangle is K×K points for the phase and 1/d² (march_light_phase_sum) */
  int shadow_area_samples;  /* K: a rectangle's shadow averaged over K×K points (march_light_column) */
  int area_light_phase;     /* AREA_LIGHT_POINTS (area_light_samples) or AREA_LIGHT_EXACT (march_light_phase) */
  int shadow_weighting;     /* SHADOW_WEIGHTING_AREA or _PHASE (march_light_column) */
  int octaves;              /* raymarch: multiple-scattering octaves (Wrenninge et al. 2013); 1 = off */
  float octave_a;           /* scattering scale per octave */
  float octave_b;           /* extinction scale per octave (a <= b conserves energy) */
  float octave_c;           /* phase anisotropy scale per octave */
  int pad0;
} march_params;

/* The Lobe Estimator (lobe.h). */
typedef struct lobe_params {
  float depth_factor;  /* the centre at depth_factor mean free paths past the first hit */
  float radius;        /* eq7: world units; corrected: mean free paths of unit density */
  int points;          /* directions in the lobe_directions buffer */
  int view_steps;      /* samples of each transmittance from the first hit to a lobe point */
  int variant;         /* LOBE_EQ7 or LOBE_CORRECTED */
  int pad0;
  int pad1;
  int pad2;
} lobe_params;

/* The ray marcher's multiple-scattering cache (ms_cache.h; ms_cache_view.h). */
typedef struct ms_cache_params {
  node_grid_params grid;  /* the nodes (the view layout: columns nx × ny of slices nz); nx = 0: off */
  int closure;            /* MS_CACHE_CLOSURE_LINEAR, _HG or _CAMERA (ms_cache.h, "Closure") */
  int layout;             /* MS_CACHE_LAYOUT_GRID or _VIEW (ms_cache_view.h) */
  int tile;               /* the view layout: pixels per column side */
  int direct;             /* 1: the cache holds the lights' unscattered light too (ms_cache.h, "Direct") */
  int filter_twicing;     /* the view layout, filter on: 1: the residual filtered and added back ("Twicing") */
  float filter;           /* the view layout: the filter's σ_s in columns; 0: off (ms_cache_filter.h) */
  int pad0;
  int pad1;
} ms_cache_params;

typedef struct scene_params {
  camera_params camera;
  medium_params medium;
  nv_float4 background;
  int has_medium;
  int num_lights;
  int max_bounces;      /* real scattering events per path */
  uint seed;
  int light_sampling;   /* path tracer's next-event estimation: LIGHT_SAMPLING_ALL or _ONE (light_select.h) */
  float shadow_roulette; /* ratio-tracked shadow rays play Russian roulette below this transmittance; 0: never */
  int pad0;
  int pad1;
} scene_params;

#endif
