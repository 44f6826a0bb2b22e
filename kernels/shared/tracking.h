/* tracking.h: null-collision free flight and transmittance (dissertation §4.2) against a majorant
 * σ̄ >= σt, per majorant-grid cell (default) or one global σ̄ over the box.
 * Free flight: delta tracking (Algorithm 1). Grey σ: the analogue walk (absorb with P = σa/σ̄,
 * scatter with σs/σ̄, else go on; the throughput never changes). Chromatic σ: spectral tracking (Kutz
 * et al. 2017, §4.2, history-aware average collision probabilities), P_x ∝ avg(σ_x ⊙ β) for x in
 * {a, s, n}, β ⊙= σ_x/(σ̄ P_x) on the chosen event: unbiased per channel, analogue when σ is grey.
 * Transmittance: ratio tracking (Algorithm 2), Tr ⊙= 1 − σt(x)/σ̄ per channel; closed form if homogeneous. */
#ifndef NARVAL_TRACKING_H
#define NARVAL_TRACKING_H

#include "shared/emission.h"
#include "shared/kernel_context.h"
#include "shared/majorant_dda.h"
#include "shared/rng.h"
#include "shared/sampling.h"
#include "shared/structs.h"

/* Iteration cap of both walks; hitting it sets STATUS_ITERATION_CAP and ends the walk (delta: absorbed,
 * ratio: 0). A walk over a length ℓ takes 1 + Poisson(σ̄ℓ) steps (with the grid Poisson(∫σ̄_grid), fewer;
 * the DDA under the walk has its own budget, majorant_dda.h). The densest test scene (σt = 1e6 over a unit box,
 * hard_cases_numeric) has σ̄ℓ ≈ 1e6 at most, the dissertation's clouds < 1e4, and P(Poisson(1e6) > 1e7)
 * is 0 in any precision. At σ̄ℓ ≳ 1e7 float gives out anyway: the mean step 1/σ̄ ≈ 1e-7·ℓ is an ulp of
 * t ≳ ℓ (2⁻²³ ≈ 1.2e-7), so t + step rounds back to t. Slow but bounded
 * (StatusWord.OverDenseGridHitsTheTrackingCapWithoutHelp; bench/RESULTS.md).
 * NARVAL_TRACKING_MAX_STEPS overrides it at build time (tests force the cap with a small value). */
#ifndef NARVAL_TRACKING_MAX_STEPS
#define NARVAL_TRACKING_MAX_STEPS 10000000
#endif
#define TRACKING_MAX_STEPS NARVAL_TRACKING_MAX_STEPS

#define TRACK_ESCAPED 0
#define TRACK_SCATTERED 1
#define TRACK_ABSORBED 2

/* Status bits besides the cap (structs.h). STATUS_NAN: a non-finite majorant (NaN, or +inf from σ·D
 * overflowing: steps of 1/inf = 0 never advance), density or throughput; the walk ends (delta:
 * absorbed, ratio: 0) rather than drop the NaN silently as a null collision. STATUS_NEGATIVE_PDF:
 * σt(x) > σ̄, so σn/σ̄ = 1 − σt(x)/σ̄ or the ratio weight is negative and the estimate biased; the walk
 * goes on. Ruled out by the global σ̄ = max σt · max ρ · (1 + 1e-5) (scene_upload.cpp) when maxValue is
 * the true maximum (loaders compute it), and by construction for grid cells (majorant_grid.cpp). Both
 * walks check medium_params.majorant (finite, positive) in either mode: it bounds every cell's σ̄ (0: all
 * cells empty). */

/* Majorants, chosen at build time so neither kernel carries the other's branch: the grid (pbrt-v4's
 * DDAMajorantIterator; majorant_dda.h), per cell σ̄ = max-channel σt · cell value · MAJORANT_MARGIN, or one
 * segment [t, t_max] with σ̄ = medium_params.majorant. Device: -DMAJORANT_GLOBAL (--majorant global,
 * auto on GPUs: host/render/majorant_options.h) or MEDIUM_HOMOGENEOUS (one cell: the same σ̄, no DDA)
 * take the global one. Host: -DMAJORANT_GLOBAL likewise, else the grid when grid_view and medium have
 * majorant cells (a runtime test: host tests walk both ways in one binary).
 * Free flight across segments (the budget): a tentative collision is where the majorant's optical
 * depth since the previous one reaches τ = −ln(1 − u) ~ Exp(1). In [s0, s1] with σ̄_i > 0 at t: if
 * t + τ/σ̄_i < s1 the collision is there, else τ −= σ̄_i·(s1 − t), on to s1; a cell with σ̄_i = 0 costs
 * no lookup or random number. This samples the Poisson process of rate σ̄(t) exactly (inverting its
 * cumulative rate), as pbrt-v4's fresh u per boundary does (memorylessness), with one uniform per
 * collision; one segment is the global walk bit for bit. An ulp of rounding can leave τ < 0: clamped
 * to 0, a collision at the next segment's start (measure zero). */
#if defined(MAJORANT_GLOBAL) || (defined(NV_DEVICE) && defined(MEDIUM_HOMOGENEOUS))
#define TRACKING_USE_MAJORANT_GRID(m) 0
#elif defined(NV_DEVICE)
#define TRACKING_USE_MAJORANT_GRID(m) 1
#else
#define TRACKING_USE_MAJORANT_GRID(m)                                                                   \
  (GRID_MAJORANTS != 0 && (m)->majorant_grid.cells_x > 0 && (m)->majorant_grid.cells_y > 0 &&           \
   (m)->majorant_grid.cells_z > 0)
#endif

/* Grey or chromatic σ (scene specialisation, host/render/kernel_features.h): -DMEDIUM_GREY keeps only
 * the analogue walk, -DMEDIUM_CHROMATIC only spectral tracking; the host sets one exactly when
 * medium_params.grey says so (the generic kernel's walk, bit for bit). Neither: the runtime flag. */
#if defined(MEDIUM_GREY)
#define TRACKING_GREY(m) 1
#elif defined(MEDIUM_CHROMATIC)
#define TRACKING_GREY(m) 0
#else
#define TRACKING_GREY(m) ((m)->grey)
#endif

/* -DCOUNTERS: TRACK_COUNT counts tentative and real collisions and lookups (kernel_context.h). */

/* Emission (-DEMISSION, emission.h), pbrt-v4's estimator: at every tentative collision t_i (null or
 * real, before its event is chosen) tracking_delta adds β ⊙ σa(t_i)·Le(t_i)/σ̄(t_i) to *emitted.
 * Unbiased for either majorant: tentative collisions before any real event have density σ̄(t)·T(t)
 * (thinning; under spectral tracking β carries each channel's T(t)/(the walk's own survival)), so the
 * sum's mean is ∫ T σa Le dt to the segment's end; beyond a real collision it is the scattered paths'. */
#ifdef EMISSION
#define TRACK_EMISSION_PARAM , NV_PRIVATE vec3* emitted
#define TRACK_EMISSION_ARG(x) , x
#else
#define TRACK_EMISSION_PARAM
#define TRACK_EMISSION_ARG(x)
#endif

/* The walk's position in its majorant segments. */
typedef struct tracking_walk {
  majorant_iter dda;  /* grid: the cells still ahead */
  float t;            /* the last tentative collision, or the start of the current segment */
  float seg_end;      /* end of the current segment */
  float bar;          /* σ̄ over the current segment (0: empty cell, or none yet) */
  float bar_scale;    /* grid: σ̄ per unit of cell value, max-channel σt · MAJORANT_MARGIN */
  int grid;           /* 1: segments from the DDA; 0: the one global segment */
} tracking_walk;

/* A walk over [t0, t1] of the index-space ray o + t·d. Callers have checked m->majorant is finite
 * and positive (so are σt and, with the grid, bar_scale). */
static inline tracking_walk tracking_walk_begin(NV_CONSTANT const medium_params* m, int use_grid, vec3 o, vec3 d,
                                                float t0, float t1) {
  tracking_walk w;
  w.t = t0;
  w.grid = use_grid;
  if (use_grid) {
    const vec3 st = medium_sigma_t(m);
    w.bar_scale = nv_fmax(st.x, nv_fmax(st.y, st.z)) * MAJORANT_MARGIN;
    w.dda = majorant_iter_begin(m->majorant_grid, o, d, t0, t1);
    w.seg_end = t0; /* no segment yet: the first step fetches one */
    w.bar = 0.0f;
  } else {
    w.bar_scale = 0.0f;
    w.dda.status = 0u;
    w.seg_end = t1;
    w.bar = m->majorant;
  }
  return w;
}

/* Spends the majorant optical depth `tau` from w->t on ("the budget" above). 1: w->t is the next
 * tentative collision, w->bar its σ̄. 0: the walk left [t0, t1]; DDA status bits go to *status. */
static inline int tracking_walk_step(NV_PRIVATE tracking_walk* w, NV_GLOBAL const float* cells, float tau,
                                     NV_PRIVATE uint* status) {
  for (;;) {
    if (w->bar > 0.0f) {
      const float dt = tau / w->bar;
      if (w->t + dt < w->seg_end) {
        w->t += dt;
        return 1;
      }
      tau = nv_fmax(0.0f, tau - w->bar * (w->seg_end - w->t));
    }
    if (!w->grid) return 0;
    float s0, s1, cell;
    if (!majorant_iter_next(&w->dda, cells, &s0, &s1, &cell)) {
      *status |= w->dda.status;
      return 0;
    }
    w->t = s0;
    w->seg_end = s1;
    w->bar = w->bar_scale * cell;
  }
}

/* Both walks start at the segment's entry o + t·d, their parameter s = t' − t growing from 0 in
 * steps it can hold; a collision is reported as t + s. Stepping t itself, a camera 10⁶ units away has
 * an ulp of 0.06 there: steps of 1/σ̄ below half of it round back to t, and in a medium empty under its
 * majorant the walk stands still until its cap (tests/render/tracking_far_test.cpp). */
static inline vec3 tracking_entry(vec3 o, vec3 d, float t) { return vec3_madd(o, d, t); }

/* Walks o + t·d (index-space origin and direction; t is the world-space ray parameter because d is
 * the world direction mapped by the same affine map) from t to t_max. On TRACK_SCATTERED, *t_out
 * is the collision and *beta has been reweighted (chromatic media only). */
static inline int tracking_delta(KERNEL_CONTEXT_PARAM, vec3 o, vec3 d, float t, float t_max, NV_PRIVATE rng_state* rng,
                                 NV_PRIVATE vec3* beta, NV_PRIVATE float* t_out TRACK_EMISSION_PARAM) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  if (!(m->majorant < NV_INFINITY)) { /* NaN or +inf */
    *status |= STATUS_NAN;
    return TRACK_ABSORBED;
  }
  if (!(m->majorant > 0.0f)) return TRACK_ESCAPED;
  const vec3 sa = vec3_from4(m->sigma_a), ss = vec3_from4(m->sigma_s);
  const int grey = TRACKING_GREY(m);
  const vec3 entry = tracking_entry(o, d, t);
  tracking_walk w = tracking_walk_begin(m, TRACKING_USE_MAJORANT_GRID(m), entry, d, 0.0f, t_max - t);
  for (int step = 0; step < TRACKING_MAX_STEPS; ++step) {
    if (!tracking_walk_step(&w, GRID_MAJORANTS, sample_exponential(rng_uniform(rng), 1.0f), status))
      return TRACK_ESCAPED;
    const float sigma_bar = w.bar;
    TRACK_COUNT(tentative);
    TRACK_COUNT(lookups);
    const vec3 x_index = vec3_madd(entry, d, w.t);
    const float rho = grid_density(KERNEL_CONTEXT_ARG, x_index);
#ifdef EMISSION
    if (rho > 0.0f) /* β ⊙ σa·Le/σ̄ at every tentative collision (above) */
      *emitted = vec3_add(*emitted, vec3_scale(vec3_mul(*beta, emission_source(KERNEL_CONTEXT_ARG, x_index, rho)),
                                               1.0f / sigma_bar));
#endif
    const float u = rng_uniform(rng);
    if (grey) {
      const float pa = sa.x * rho / sigma_bar, ps = ss.x * rho / sigma_bar;
      const float pn = 1.0f - pa - ps; /* null-collision probability */
      if (!(pn >= 0.0f)) {
        if (!(pn < 0.0f)) { /* NaN: a NaN density would otherwise pass as a null collision */
          *status |= STATUS_NAN;
          return TRACK_ABSORBED;
        }
        *status |= STATUS_NEGATIVE_PDF;
      }
      if (u < pa) {
        TRACK_COUNT(real);
        return TRACK_ABSORBED;
      }
      if (u < pa + ps) {
        TRACK_COUNT(real);
        *t_out = t + w.t;
        return TRACK_SCATTERED;
      }
      continue;
    }
    const vec3 b = *beta;
    const vec3 sig_a = vec3_scale(sa, rho), sig_s = vec3_scale(ss, rho);
    const vec3 sig_n = vec3_sub(vec3_splat(sigma_bar), vec3_add(sig_a, sig_s));
    if (nv_fmin(sig_n.x, nv_fmin(sig_n.y, sig_n.z)) < 0.0f) *status |= STATUS_NEGATIVE_PDF;
    const float wa = vec3_average(vec3_mul(sig_a, b));
    const float ws = vec3_average(vec3_mul(sig_s, b));
    const float wn = vec3_average(vec3_mul(sig_n, b));
    const float c = wa + ws + wn;
    if (!(c > 0.0f)) {
      if (c != c) *status |= STATUS_NAN; /* NaN density or throughput */
      return TRACK_ABSORBED;             /* else zero throughput: nothing left to carry */
    }
    const float x = u * c;
    if (x < wa) {
      TRACK_COUNT(real);
      return TRACK_ABSORBED;
    }
    if (x < wa + ws) {
      TRACK_COUNT(real);
      *beta = vec3_scale(vec3_mul(b, sig_s), c / (sigma_bar * ws));
      *t_out = t + w.t;
      return TRACK_SCATTERED;
    }
    *beta = vec3_scale(vec3_mul(b, sig_n), c / (sigma_bar * wn));
  }
  *status |= STATUS_ITERATION_CAP;
  return TRACK_ABSORBED;
}

/* Russian roulette on a ratio-tracked transmittance (pbrt-v4's TraceTransmittance): once every
 * channel is below `below`, end with probability q = 3/4, else go on with Tr/(1 − q): unbiased,
 * (1 − q)·Tr/(1 − q) = Tr, and a ray past a few mean free paths stops paying for lookups. */
#define TRACKING_ROULETTE_Q 0.75f

/* Ratio-tracking estimate of the transmittance along o + t·d over [t, t_max]; `roulette_below` > 0
 * plays Russian roulette below that transmittance (above), 0 never. */
static inline vec3 tracking_ratio(KERNEL_CONTEXT_PARAM, vec3 o, vec3 d, float t, float t_max, float roulette_below,
                                  NV_PRIVATE rng_state* rng) {
  NV_CONSTANT const medium_params* m = ctx->medium;
  NV_PRIVATE uint* status = &ctx->status;
  vec3 tr = vec3_splat(1.0f);
  if (!(m->majorant < NV_INFINITY)) { /* NaN or +inf, see tracking_delta */
    *status |= STATUS_NAN;
    return vec3_splat(0.0f);
  }
  if (!(m->majorant > 0.0f)) return tr;
  const vec3 st = medium_sigma_t(m);
  /* A homogeneous medium has the closed form: Beer-Lambert, no variance. */
  if (GRID_IS_HOMOGENEOUS_CTX(ctx)) return vec3_exp_neg(vec3_scale(st, nv_fmax(0.0f, t_max - t)));
  const vec3 entry = tracking_entry(o, d, t);
  tracking_walk w = tracking_walk_begin(m, TRACKING_USE_MAJORANT_GRID(m), entry, d, 0.0f, t_max - t);
  for (int step = 0; step < TRACKING_MAX_STEPS; ++step) {
    if (!tracking_walk_step(&w, GRID_MAJORANTS, sample_exponential(rng_uniform(rng), 1.0f), status)) return tr;
    const float inv_bar = 1.0f / w.bar;
    TRACK_COUNT(lookups);
    const float rho = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(entry, d, w.t));
    const vec3 wt = vec3_sub(vec3_splat(1.0f), vec3_scale(st, rho * inv_bar)); /* σn/σ̄ per channel */
    const float w_min = nv_fmin(wt.x, nv_fmin(wt.y, wt.z));
    if (!(w_min >= 0.0f)) {
      if (w_min != w_min) { /* NaN density: NaN in all three channels */
        *status |= STATUS_NAN;
        return vec3_splat(0.0f);
      }
      *status |= STATUS_NEGATIVE_PDF;
    }
    tr = vec3_mul(tr, wt);
    if (vec3_is_zero(tr)) return tr;
    if (nv_fmax(tr.x, nv_fmax(tr.y, tr.z)) < roulette_below) {
      if (rng_uniform(rng) < TRACKING_ROULETTE_Q) return vec3_splat(0.0f);
      tr = vec3_scale(tr, 1.0f / (1.0f - TRACKING_ROULETTE_Q));
    }
  }
  *status |= STATUS_ITERATION_CAP;
  return vec3_splat(0.0f);
}

#endif
