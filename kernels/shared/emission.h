/* emission.h: emissive media, pbrt-v4's model (DESIGN.md "Emission"): the medium emits σa(x)·Le(x) per
 * unit length, so the radiance along a ray gains ∫ T(t) σa(t) Le(t) dt. Le by kind (emission_kinds.h):
 *   EMISSION_COLOR      colour · scale · v(x)           (v: the emission grid, e.g. EmberGen's `flames`; else 1)
 *   EMISSION_BLACKBODY  scale · B((v(x) − offset) · s)  (v: a temperature grid; pbrt-v4's temperatureoffset/-scale)
 * B: host/colour/blackbody.h's colour (peak-normalised Planck spectrum through the CIE 1931 matching functions
 * into linear sRGB, 0 at or below 100 K), tabulated by the host over [0, table_max] kelvin (table_max at least
 * the grid's hottest) and interpolated linearly: the table, not the colour per voxel, so B follows the
 * temperature trilinearly reconstructed at x, as in pbrt-v4. The emission grid has its own index space
 * (transform, bounding box), reached from the medium's by emission_params.index_to_grid.
 *
 * Built only with -DEMISSION (host/render/kernel_features.h; host tests define it): otherwise nothing here
 * compiles and no kernel reads the emission grid or table (kernel_context.h). Collected by tracking_delta at
 * each tentative collision (path tracer, tracking.h), the view march (raymarch.h) and march_emission (lobe.h). */
#ifndef NARVAL_EMISSION_H
#define NARVAL_EMISSION_H

#include "shared/kernel_context.h"

#ifdef EMISSION

/* The emission grid's value at medium index point p (1 without a grid). */
static inline float emission_grid_value(KERNEL_CONTEXT_PARAM, vec3 p) {
  NV_CONSTANT const emission_params* e = &ctx->medium->emission;
  if (!(e->grid_dims.x > 0.0f)) return 1.0f;
  const vec3 q = affine_point(e->index_to_grid, p);
#if !defined(NV_DEVICE)
  const grid_view* g = ctx->grids;
  return grid_trilinear(g->emission_data, g->emission_nx, g->emission_ny, g->emission_nz, q);
#elif GRID_STORAGE_IN_CONTEXT
  return grid_value(ctx->emission_grid, q);
#else
  return grid_value(emission_image, q);
#endif
}

/* Nothing is emitted at or below this temperature (pbrt-v4's rule), whatever the table holds. */
#define EMISSION_MIN_KELVIN 100.0f

/* B(T) from the table, linearly interpolated; the last entry above table_max (sized so that no grid
 * temperature gets there); exactly 0 for T at or below EMISSION_MIN_KELVIN and for NaN. */
static inline vec3 emission_blackbody(NV_CONSTANT const emission_params* e, NV_GLOBAL const float* table, float T) {
  if (!(T > EMISSION_MIN_KELVIN)) return vec3_splat(0.0f);
  const int last = e->table_size - 1;
  const float x = nv_fmin(T / e->table_max, 1.0f) * (float)last;
  const int i = (int)nv_fmin(nv_floor(x), (float)(last - 1));
  const float a = x - (float)i;
  NV_GLOBAL const float* lo = table + 3 * i;
  return vec3_make(lo[0] + a * (lo[3] - lo[0]), lo[1] + a * (lo[4] - lo[1]), lo[2] + a * (lo[5] - lo[2]));
}

/* Le at medium index point p; an unknown kind emits nothing (reported at the kernel's entry, scene_kinds.h). */
static inline vec3 emission_radiance(KERNEL_CONTEXT_PARAM, vec3 p) {
  NV_CONSTANT const emission_params* e = &ctx->medium->emission;
  switch (e->kind) {
    case EMISSION_NONE: return vec3_splat(0.0f);
    case EMISSION_COLOR: return vec3_scale(vec3_from4(e->color), emission_grid_value(KERNEL_CONTEXT_ARG, p));
    case EMISSION_BLACKBODY: {
#ifdef NV_DEVICE
      NV_GLOBAL const float* table = ctx->emission_table;
#else
      const float* table = ctx->grids->emission_table;
#endif
      const float T = (emission_grid_value(KERNEL_CONTEXT_ARG, p) - e->temperature_offset) * e->temperature_scale;
      return vec3_mul(vec3_from4(e->color), emission_blackbody(e, table, T));
    }
    default: return vec3_splat(0.0f);
  }
}

/* σa(x)·Le(x), the emitted radiance per unit length at medium index point p of density rho. */
static inline vec3 emission_source(KERNEL_CONTEXT_PARAM, vec3 p, float rho) {
  const vec3 sigma_a = vec3_scale(vec3_from4(ctx->medium->sigma_a), rho);
  if (vec3_is_zero(sigma_a)) return sigma_a; /* no absorption, no emission: skip the emission grid */
  return vec3_mul(sigma_a, emission_radiance(KERNEL_CONTEXT_ARG, p));
}

#endif /* EMISSION */

#endif
