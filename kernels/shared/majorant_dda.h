/* majorant_dda.h: a coarse majorant grid over the medium box and the 3D DDA that walks it (pbrt-v4's
 * MajorantGrid / DDAMajorantIterator, as a plain-C iterator a kernel loops over).
 * The index-space box [0, nx]×[0, ny]×[0, nz] is cut into cells_x×cells_y×cells_z cells of cell_size
 * index units; cell (i, j, k) covers [i, i+1]·cell_size.x × ... and its value
 * cell_max[i + cells_x·(j + cells_y·k)] bounds the trilinear DENSITY anywhere in that closed cell
 * (host/volume/majorant_grid.cpp builds it and proves the bound). For an index-space ray o + t·d over
 * [t0, t1] the DDA yields the cells crossed, in order, as segments [seg_t0, seg_t1] with their value:
 *   majorant_iter it = majorant_iter_begin(grid, o, d, t0, t1);
 *   float s0, s1, smax;
 *   while (majorant_iter_next(&it, cell_max, &s0, &s1, &smax)) { ... }
 * Contract (tests/unit/majorant_grid_test.cpp):
 * - segments are contiguous and increasing from t0 to t1, each with seg_t1 > seg_t0 (bit-exact: t
 *   values are handed on, never recomputed); t0 >= t1 yields nothing.
 * - a cell crossed with positive length is yielded, one only touched (an edge or corner crossed
 *   exactly) is not: tied axes step at once. A ray inside a face between two cells (d = 0 on that
 *   axis) walks the upper cells; both closed cells bound the density there.
 * - parts of [t0, t1] outside the box belong to the nearest boundary cell (density 0 there: still
 *   conservative); callers clip to the box first (medium_intersect) to avoid waste.
 * - at most cells_x + cells_y + cells_z - 2 segments (each step advances one axis monotonically), the
 *   loop capped at MAJORANT_DDA_BUDGET iterations (derivation there): next() returning 0 with
 *   it.t < it.t_end means the cap was hit, flagged STATUS_ITERATION_CAP (impossible by construction).
 * - a ±0 direction component never steps on that axis; a start exactly on a cell boundary starts in
 *   the cell the ray enters (the lower one when d < 0). A non-finite o, d, t0 or t1 yields nothing
 *   and sets STATUS_NAN (rather than read as an empty segment). Callers OR it.status into theirs. */
#ifndef NARVAL_MAJORANT_H
#define NARVAL_MAJORANT_H

#include "shared/structs.h"

/* The kernel's σ̄ = max-channel σt · cell value · MAJORANT_MARGIN: the trilinear lerps can exceed the
 * largest corner by a few ulps; the margin keeps 1 - σt/σ̄ >= 0 (the global majorant's, scene_upload.cpp). */
#define MAJORANT_MARGIN (1.0f + 1e-5f)
/* Index units by which the host pads each cell when bounding it: rounding can place a point the DDA
 * attributes to a cell a few ulps of its index coordinates outside it. */
#define MAJORANT_SLACK (1.0f / 256.0f)

/* Loop iterations of majorant_iter_next over a whole walk. Derivation: an iteration either ends the
 * walk (t_exit >= t_end: the last segment, then one call returning 0) or steps at least one axis, each
 * monotonically from its start cell to its last (exit = ∞ there): at most (nx − 1) + (ny − 1) +
 * (nz − 1) stepping iterations (zero-length segments included) + 2 = nx + ny + nz − 1 < the budget
 * nx + ny + nz + 3 (64³: ≤ 191 of 195). NARVAL_DDA_BUDGET replaces it at build time (tests force the cap). */
#ifdef NARVAL_DDA_BUDGET
#define MAJORANT_DDA_BUDGET(nx, ny, nz) (NARVAL_DDA_BUDGET)
#else
#define MAJORANT_DDA_BUDGET(nx, ny, nz) ((nx) + (ny) + (nz) + 3)
#endif


/* Private DDA state; fields are read by tests, kernels only call begin/next. */
typedef struct majorant_iter {
  vec3 o, inv_d;           /* index-space ray origin and 1/d (unused on axes with d == 0) */
  float t, t_end;          /* start of the next segment; end of the whole segment */
  float next_x, next_y, next_z; /* t at which the ray leaves the current cell along each axis
                                   (NV_INFINITY: it never does inside the grid) */
  float size_x, size_y, size_z; /* cell size */
  int cx, cy, cz;          /* current cell */
  int step_x, step_y, step_z; /* +1, -1, or 0 (no movement along the axis) */
  int nx, ny, nz;          /* cell counts */
  int budget;              /* loop iterations left (MAJORANT_DDA_BUDGET) */
  int seg_cell;            /* linear index of the cell of the last yielded segment */
  uint status;             /* STATUS_NAN (non-finite input), STATUS_ITERATION_CAP (budget spent) */
} majorant_iter;

/* The cell c of coordinate p along one axis, clamped to [0, n-1]: c·size <= p < (c+1)·size, tested
 * against the faces as the DDA forms them (float products) to settle the quotient's rounding. On a
 * face: the cell the ray enters, upper for dir >= 0 (dir == 0: a ray inside a face walks the upper
 * cells), lower for dir < 0. fmin/fmax send NaN to 0, so the int is defined. */
static inline int majorant_cell_of(float p, float size, float dir, int n) {
  float c = nv_floor(p / size);
  if ((c + 1.0f) * size <= p)
    c += 1.0f;
  else if (c * size > p)
    c -= 1.0f;
  if (dir < 0.0f && c * size == p) c -= 1.0f;
  return (int)nv_fmin(nv_fmax(c, 0.0f), (float)(n - 1));
}

/* The t at which the ray leaves cell c along one axis: the far boundary in the direction of
 * travel, or NV_INFINITY when the axis does not move or c is the last cell that way (the ray then
 * stays in that boundary cell, see the contract). */
static inline float majorant_exit_t(int c, int step, int n, float size, float o, float inv_d) {
  if (step > 0) return c + 1 < n ? ((float)(c + 1) * size - o) * inv_d : NV_INFINITY;
  if (step < 0) return c > 0 ? ((float)c * size - o) * inv_d : NV_INFINITY;
  return NV_INFINITY;
}

/* The cell the walk starts in along one axis: the position's cell, settled against the DDA's own
 * crossing times (majorant_exit_t's expressions) so the first exit lies after t0 and the entry before.
 * o + t0·d is off by an ulp of |o| + |t0·d|, on a ray nearly parallel to a face a long stretch of t
 * that the spatial test alone would put on the wrong side. One step either way suffices: the error
 * is far below a cell's width (at least a voxel with chooseMajorantResolution). */
static inline int majorant_start_cell(float o, float d, float inv_d, float t0, float size, int n) {
  int c = majorant_cell_of(o + d * t0, size, d, n);
  if (d > 0.0f) {
    if (c + 1 < n && ((float)(c + 1) * size - o) * inv_d <= t0)
      c += 1; /* its exit is already behind */
    else if (c > 0 && ((float)c * size - o) * inv_d > t0)
      c -= 1; /* not entered yet */
  } else if (d < 0.0f) {
    if (c > 0 && ((float)c * size - o) * inv_d <= t0)
      c -= 1;
    else if (c + 1 < n && ((float)(c + 1) * size - o) * inv_d > t0)
      c += 1;
  }
  return c;
}

static inline majorant_iter majorant_iter_begin(majorant_grid_params g, vec3 o, vec3 d, float t0, float t1) {
  majorant_iter it;
  it.o = o;
  it.inv_d = vec3_make(d.x != 0.0f ? 1.0f / d.x : 0.0f, d.y != 0.0f ? 1.0f / d.y : 0.0f,
                       d.z != 0.0f ? 1.0f / d.z : 0.0f);
  it.t = t0;
  it.t_end = t1;
  it.size_x = g.cell_size.x;
  it.size_y = g.cell_size.y;
  it.size_z = g.cell_size.z;
  it.nx = g.cells_x;
  it.ny = g.cells_y;
  it.nz = g.cells_z;
  it.step_x = d.x > 0.0f ? 1 : (d.x < 0.0f ? -1 : 0);
  it.step_y = d.y > 0.0f ? 1 : (d.y < 0.0f ? -1 : 0);
  it.step_z = d.z > 0.0f ? 1 : (d.z < 0.0f ? -1 : 0);
  it.budget = MAJORANT_DDA_BUDGET(g.cells_x, g.cells_y, g.cells_z);
  it.seg_cell = -1;
  it.status = 0u;
  const int finite = nv_isfinite(t0) && nv_isfinite(t1) && vec3_is_finite(o) && vec3_is_finite(d);
  if (!finite || g.cells_x < 1 || g.cells_y < 1 || g.cells_z < 1) {
    it.budget = 0; /* nothing to walk */
    it.t_end = it.t;
    if (!finite) it.status = STATUS_NAN;
  }
  it.cx = majorant_start_cell(o.x, d.x, it.inv_d.x, t0, it.size_x, it.nx);
  it.cy = majorant_start_cell(o.y, d.y, it.inv_d.y, t0, it.size_y, it.ny);
  it.cz = majorant_start_cell(o.z, d.z, it.inv_d.z, t0, it.size_z, it.nz);
  it.next_x = majorant_exit_t(it.cx, it.step_x, it.nx, it.size_x, o.x, it.inv_d.x);
  it.next_y = majorant_exit_t(it.cy, it.step_y, it.ny, it.size_y, o.y, it.inv_d.y);
  it.next_z = majorant_exit_t(it.cz, it.step_z, it.nz, it.size_z, o.z, it.inv_d.z);
  return it;
}

/* Yields the next segment and its cell's value; 0 when [t0, t1] is covered. */
static inline int majorant_iter_next(NV_PRIVATE majorant_iter* it, NV_GLOBAL const float* cell_max,
                                     NV_PRIVATE float* seg_t0, NV_PRIVATE float* seg_t1,
                                     NV_PRIVATE float* seg_max) {
  while (it->budget > 0) {
    it->budget -= 1;
    if (!(it->t < it->t_end)) return 0;
    const float t_exit = nv_fmin(it->next_x, nv_fmin(it->next_y, it->next_z));
    const float start = it->t;
    const float end = nv_fmin(t_exit, it->t_end);
    const int cell = it->cx + it->nx * (it->cy + it->ny * it->cz);
    if (!(t_exit < it->t_end)) { /* also a NaN exit (0·inf for a denormal d): stay in this cell */
      it->t = it->t_end;
    } else {
      /* Step every axis whose boundary is at t_exit (an edge or corner crossed exactly moves
       * diagonally, never through a touched cell); t_exit < t_end makes it a number equal to at least
       * one. A crossing behind `start` (rounding at the start point) steps without moving t. */
      it->t = nv_fmax(start, t_exit);
      if (it->next_x == t_exit) {
        it->cx += it->step_x;
        it->next_x = majorant_exit_t(it->cx, it->step_x, it->nx, it->size_x, it->o.x, it->inv_d.x);
      }
      if (it->next_y == t_exit) {
        it->cy += it->step_y;
        it->next_y = majorant_exit_t(it->cy, it->step_y, it->ny, it->size_y, it->o.y, it->inv_d.y);
      }
      if (it->next_z == t_exit) {
        it->cz += it->step_z;
        it->next_z = majorant_exit_t(it->cz, it->step_z, it->nz, it->size_z, it->o.z, it->inv_d.z);
      }
    }
    if (end > start) {
      *seg_t0 = start;
      *seg_t1 = end;
      *seg_max = cell_max[cell];
      it->seg_cell = cell;
      return 1;
    }
    /* Zero or negative length (rounding at the start): the ray does not really cross this cell. */
  }
  if (it->t < it->t_end) it->status |= STATUS_ITERATION_CAP; /* budget spent before t_end */
  return 0;
}

#endif
