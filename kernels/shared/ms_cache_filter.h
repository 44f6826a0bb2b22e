/* ms_cache_filter.h: a filter over the view cache's nodes (ms_cache_view.h) that averages neighbouring
 * columns where they agree within their noise. On an interactive CPU build a node's paths are few and
 * their noise is most of the view cache's error; wider tiles average more paths per pixel but mix columns
 * whose in-scattering differs (bench/RESULTS.md). What tells columns that may be mixed apart is J itself,
 * not a guide from the single scattering (at albedo 0.99 most of J is multiple scattering; a back-lit
 * cloud's dark ring holds none), so the range distance is the nodes' own difference measured in their
 * noise, as in non-local-means filtering of Monte Carlo renders (Rousselle, Knaus & Zwicker 2012,
 * "Adaptive rendering with non-local means filtering", Eq. 4), with the column's slices as the patch:
 *   d²_j = (1/nz) Σ_s max(0, (J_j,s − J_s)² − (v_s + v_j,s)) / (ε + k²·(v_s + v_j,s)),
 * J_s the grey (channel-mean) value of slice s = [τ_a, τ_b]; J_j,s column j's slices integrated over that
 * τ range (ms_view_lookup with column j alone: registered by optical depth as the lookup is, and the
 * column's own reads give its J̄_s exactly); v_s, v_j,s the variances of those means (mean grey L²,
 * MS_CACHE_SQUARE, less J², over the paths n; for j, of its slice holding the range's midpoint). A
 * neighbour within the noise (d² = 0) weighs as much as the column itself; k (MS_VIEW_FILTER_TOLERANCE)
 * sets how many standard errors beyond it keep e^{−1} of the weight. The filtered column:
 *   J̃_s = Σ_j w_j·J_j,s / Σ_j w_j,   w_j = e^{−(Δx² + Δy²)/(2σ_s²)} · e^{−d²_j},
 * over the columns j with medium within max(1, ⌊2σ_s⌋) on each axis, one weight per column for all its
 * slices; σ_s in columns (msCache.filter; 0: off). A patch rather than one node makes the distance less
 * noisy and measured better on most scenes (bench/RESULTS.md). Weights that depend on the noise bias the
 * filter where true differences hide in it (the price of every such denoiser); k → ∞ is a plain Gaussian.
 * It reads the running means and writes a second buffer of the same layout (R filtered, other slots
 * copied; the view lookup reads R alone) for the march, after every build launch, so the raw means keep
 * refining and the weights tighten as the noise falls.
 *
 * Twicing (msCache.filterTwicing; Tukey 1977, "Exploratory Data Analysis", ch. 16): S, its weights fixed
 * by the raw means, is linear, and where the in-scattering curves its bias is (S − I)·J ≈ (m₂/2)·∇²J, m₂
 * the weights' second moment: a dark column among brighter ones (J convex across the image, as in a
 * back-lit cloud's ring) reads too bright. Filtering the residual and adding it back,
 * J̃ = S(J) + S(J − S(J)) = 2·S(J) − S(S(J)), cancels that term (a field quadratic in the columns comes
 * back exactly, where S alone is off by m₂) for a kernel 2S − S² that keeps more weight, so more noise,
 * at the centre. A second pass computes it from the first's output (ms_view_filter_column with
 * `residual`), same weights, clamped at 0 (radiance: where the field dips more sharply than a quadratic,
 * 2S − S² can overshoot below it); it takes out most of the filter's brightening of mid-dark bands
 * (bench/RESULTS.md). */
#ifndef NARVAL_MS_CACHE_FILTER_H
#define NARVAL_MS_CACHE_FILTER_H

#include "shared/ms_cache_view.h"

#define MS_VIEW_FILTER_EPSILON 1e-20f /* ε: keeps d² finite between noiseless nodes */
#define MS_VIEW_FILTER_MAX_SLICES 64  /* msCache.slices' upper bound (the loader's) */
/* k, fixed: the value that measured best when it was a scene key (bench/RESULTS.md). */
#define MS_VIEW_FILTER_TOLERANCE 2.0f

/* The grey value of a node and the variance of that mean ("v_s"). */
static inline float ms_view_grey(NV_GLOBAL const float* v) { return (v[0] + v[1] + v[2]) * (1.0f / 3.0f); }
static inline float ms_view_grey_variance(NV_GLOBAL const float* v) {
  const float J = ms_view_grey(v);
  return v[3] > 0.0f ? nv_fmax(0.0f, v[MS_CACHE_SQUARE] - J * J) / v[3] : 0.0f;
}

/* Column j read over node v's τ range (J_j,s), and the variance of j's slice at its midpoint (v_j,s). */
static inline vec3 ms_view_filter_read(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* cache,
                                       NV_GLOBAL const float* v, int j, NV_PRIVATE float* variance) {
  const size_t slice_stride = (size_t)c->nx * (size_t)c->ny * MS_CACHE_STRIDE;
  NV_GLOBAL const float* col = cache + (size_t)j * MS_CACHE_STRIDE;
  const float a = v[MS_VIEW_TAU], b = v[MS_VIEW_TAU_END], mid = 0.5f * (a + b);
  int s = 0;
  while (s + 1 < c->nz && col[(size_t)(s + 1) * slice_stride + MS_VIEW_TAU] <= mid) ++s;
  *variance = ms_view_grey_variance(col + (size_t)s * slice_stride);
  ms_view_columns one = {{j, 0, 0, 0}, {1.0f, 0.0f, 0.0f, 0.0f}};
  return ms_view_lookup(c, cache, &one, a, b - a);
}

/* Column `column`'s filtered slices ("The filtered column"; σ_s = sigma_s, k = tolerance) into `out`
 * (the filtered buffer at the column's slice 0: J̃ in slots 0–2, the rest copied; a column without
 * medium is copied). Weights from `cache`, the running means; values from `values`: the running means
 * (S(J)), or with `residual` the first pass's output F, giving max(0, 2·F − S(F)) ("Twicing"). */
static inline void ms_view_filter_column(NV_PRIVATE const node_grid_params* c, NV_GLOBAL const float* cache,
                                         NV_GLOBAL const float* values, int residual, int column, float sigma_s,
                                         float tolerance, NV_GLOBAL float* out) {
  const size_t slice_stride = (size_t)c->nx * (size_t)c->ny * MS_CACHE_STRIDE;
  const int cx = column % c->nx, cy = column / c->nx;
  const int nz = c->nz < MS_VIEW_FILTER_MAX_SLICES ? c->nz : MS_VIEW_FILTER_MAX_SLICES;
  NV_GLOBAL const float* own = cache + (size_t)column * MS_CACHE_STRIDE;
  for (int s = 0; s < c->nz; ++s)
    for (int i = 0; i < MS_CACHE_STRIDE; ++i) out[(size_t)s * slice_stride + i] = own[(size_t)s * slice_stride + i];
  if (own[MS_VIEW_TAU] < 0.0f || !(sigma_s > 0.0f)) return;
  const int radius = (int)nv_fmax(1.0f, 2.0f * sigma_s); /* the Gaussian cut at 2σ_s (one column at least) */
  const float inv_s = 0.5f / (sigma_s * sigma_s), k2 = tolerance * tolerance;
  vec3 sum[MS_VIEW_FILTER_MAX_SLICES], read[MS_VIEW_FILTER_MAX_SLICES]; /* read: neighbour j's, per slice */
  for (int s = 0; s < nz; ++s) sum[s] = vec3_splat(0.0f);
  float weight = 0.0f;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int x = cx + dx, y = cy + dy;
      if (x < 0 || y < 0 || x >= c->nx || y >= c->ny) continue;
      const int j = x + c->nx * y;
      if (cache[(size_t)j * MS_CACHE_STRIDE + MS_VIEW_TAU] < 0.0f) continue;
      float d2 = 0.0f; /* the patch distance d²_j: the mean of the slices' */
      for (int s = 0; s < nz; ++s) {
        NV_GLOBAL const float* v = own + (size_t)s * slice_stride;
        float vj;
        read[s] = ms_view_filter_read(c, cache, v, j, &vj);
        if (j == column) continue; /* its own distance is 0, whatever the reads: the weight's floor of 1 */
        const float diff = vec3_average(read[s]) - ms_view_grey(v);
        const float var = ms_view_grey_variance(v) + vj;
        d2 += nv_fmax(0.0f, diff * diff - var) / (MS_VIEW_FILTER_EPSILON + k2 * var);
      }
      const float w = nv_exp(-(float)(dx * dx + dy * dy) * inv_s - d2 / (float)nz);
      for (int s = 0; s < nz; ++s) {
        float unused;
        if (residual) read[s] = ms_view_filter_read(c, values, own + (size_t)s * slice_stride, j, &unused);
        sum[s] = vec3_add(sum[s], vec3_scale(read[s], w));
      }
      weight += w;
    }
  for (int s = 0; s < nz; ++s) { /* weight ≥ 1: the column itself (a node read across slices of no width,
                                  * or noiseless with no paths yet, would otherwise be at a distance) */
    NV_GLOBAL float* o = out + (size_t)s * slice_stride;
    vec3 J = vec3_make(sum[s].x / weight, sum[s].y / weight, sum[s].z / weight);
    if (residual) {
      NV_GLOBAL const float* f = values + (size_t)column * MS_CACHE_STRIDE + (size_t)s * slice_stride;
      J = vec3_max(vec3_splat(0.0f), vec3_sub(vec3_scale(vec3_make(f[0], f[1], f[2]), 2.0f), J));
    }
    o[0] = J.x;
    o[1] = J.y;
    o[2] = J.z;
  }
}

#endif
