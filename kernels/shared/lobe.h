/* lobe.h: the Lobe Estimator (dissertation ch. 6, Eq. 7; DESIGN.md "lobe"), deterministic, per pixel:
 *   L = L_b · (1/n) Σ_i Tr(x0 → P_i)
 *     + albedo ⊙ Σ_k (1/n) Σ_i p(cos θ_i) · Tr(P_i → light_k) · I_k / |light_k − P_i|²
 *
 * Parameters: march_params and lobe_params (structs.h; keys renderer.lobe.* and defaults in
 * docs/scene-format.md), each named below where it acts; n = points, the directions in `dirs`.
 *
 * 1. x0: the view ray's first point in the box with density > 0: `steps` midpoint samples over the
 *    occupied majorant cells only (march_iter), then LOBE_BISECTIONS bisections; features thinner than a
 *    step can be missed.
 * 2. c = x0 + t·ω, t = depth_factor / σ̄t, σ̄t the channel mean of σa + σs for unit density (D included),
 *    clamped to the rest of the segment in the box so that c stays "a point inside the volume" (ch. 6):
 *    past the box nothing attenuates and the lobe would see unshadowed light. Testing
 *    depth_factor < σ̄t·rest never divides by a zero or tiny σ̄t.
 * 3. d_i = the host's canonical directions (HG(g) about +Z, host/render/lobe_directions.cpp) rotated onto
 *    ω; P_i = c + r·d_i, r = radius in world units, exactly DESIGN.md. Sign: light from P_i reaches c
 *    along −d_i and leaves towards the camera along −ω, so cos = dot(d_i, ω) is HG(g)-distributed,
 *    importance sampling c's phase lobe; for g > 0 the P_i lie beyond c, and light from behind the medium
 *    is bright (forward scattering, dissertation Fig. 2.10). DESIGN.md's two statements agree; the
 *    dissertation's GLSL flips this sign (a bug, not followed). The frame about ω comes from the camera's
 *    `right` vector, not vec3_basis(ω): the lobe is attached to the camera (moving camera and scene
 *    rigidly together leaves the image unchanged) and smooth across the image (vec3_basis flips with
 *    ω.z's sign: a seam).
 * 4. Transmittances by the midpoint rule (true step lengths, all channels, inside the box only):
 *    Tr(x0 → P_i) over view_steps samples, Tr(P_i → light) by light_cache_optical_depth (a cache lookup
 *    or the exact march of shadow_steps). Lights as in raymarch.h (march_light_sum: a rectangle is a
 *    point at its centre, as DESIGN.md allows for real-time kernels); shadow rays see only the medium.
 *    cos θ_i = dot(normalize(P_i − light), −d_i): from the light to P_i, then towards c. albedo = σs/σt
 *    per channel (0 where σt = 0).
 * Economies: with L_b exactly 0 the view transmittances are not marched (0·Tr = 0: no pixel changes).
 * Early termination (min_transmittance ε > 0): Tr(x0 → P_i) stops once every channel's τ exceeds −ln ε',
 * ε' = ε / max(1, max channel of L_b); the value used is in [Tr_true, ε'), so each of the n terms is off
 * by less than ε': |ΔL| < ε'·L_b ≤ ε per channel (raymarch.h says why ε is scaled by L_b). No medium, a
 * ray missing the box (or meeting a rectangle light first), or no density > 0 on the segment: L = L_b
 * exactly (march_view). Means divide by n, so n transmittances of 1 give exactly L_b.
 * Loops: the first-hit search (`steps` samples, then LOBE_BISECTIONS), n lobe points × (one march of
 * view_steps + lights × (one cache lookup or a march of shadow_steps)): all bounded by the scene's
 * parameters; the only open-ended walk is the DDA under each march, capped by its budget (majorant_dda.h).
 *
 * Corrected (renderer.lobe.variant "corrected", the default; "eq7" is all of the above, bit for bit)
 * keeps the idea (HG-distributed points about a point inside the medium past the view ray's entry, their
 * light averaged) and changes what the measurements showed wrong:
 * C1. Eq. 7's in-scattered term ignores how much the medium scatters (a wisp of density 1e-6 gets a dense
 *     core's albedo·S̄: the white sheet around the smoke). With S constant along the view ray, single
 *     scattering is ∫ σs T S dt = albedo·S·∫ σt T dt = albedo·S·(1 − T_v) (d/dt T = −σt T; albedo
 *     independent of density), T_v the view ray's transmittance through the box: the term is weighted by
 *     1 − T_v, and L → L_b continuously as the density → 0. The background term becomes L_b·T_v, the
 *     light reaching the camera unscattered (Eq. 7's mean Tr(x0 → P_i) is what the lobe points see;
 *     dropping it saves n view marches).
 * C2. The centre: one march (view_steps samples, occupied cells) gives T_v and where the camera's light
 *     is scattered, t_c = ∫ t σt T S dt / ∫ σt T S dt (midpoint rule, channel means; S the lights'
 *     in-scattering, one light-cache lookup per sample), or with no light on the ray the expected first
 *     interaction, ∫ t σt T dt / ∫ σt T dt; a weighted mean of sample positions, inside the box. Eq. 7's
 *     depth_factor/σ̄t assumes unit density, so in a thin wisp or a dense core c lands where nothing
 *     scatters (black core and white ring on the default cloud); weighting by S matters for back-lit
 *     media (bench/RESULTS.md). Early termination as above: the samples left weigh below ε' together, so
 *     1 − T_v is off by less than ε' (the in-scattered term by a relative ε'/(1 − ε')). Sub-steps: the
 *     samples follow the occupied cells, so where a step spans several mean free paths its one
 *     midpoint can fall short of or far past where the density rises, and c jumps between pixels whose
 *     rays cross different cells (patches shaped like the cells on a dense front-lit cloud). A step
 *     whose majorant optical depth x (the cell's majorant density times σ̄t·Δ) exceeds 1 is split into
 *     min(⌊x⌋ + 1, LOBE_SUBSTEPS) sub-steps over its own length.
 * C3. Scale: r = radius/σ̄t, radius in mean free paths of unit density. Scaling geometry by s and σ by
 *     1/s scales r, t_c and every segment by s and leaves every optical depth, T_v, phase angle and
 *     (rectangle lights, I ∝ area) I/d² unchanged: the same image, which Eq. 7's world-unit r breaks.
 * C4. P_i = c + min(r, distance from c to the box along d_i)·d_i: a point outside the box sees its light
 *     unshadowed, which Eq. 7 paints as a bright ring around silhouettes.
 * Result: L = L_b·T_v + (1 − T_v)·albedo ⊙ (1/n) Σ_i Σ_k p(cos θ_i) · Tr(P_i → light_k) · I_k / d².
 * Loops: one march of view_steps (each split into at most LOBE_SUBSTEPS), n × lights lookups; no
 * first-hit search, no view marches.
 *
 * Emission (-DEMISSION, emission.h): both variants add march_emission over the view ray's segment
 * (`steps` samples), the medium's own light, which neither estimate above holds.
 *
 * Status word: STATUS_NAN for a non-finite pixel (written as 0) or a NaN density, phase value or lobe
 * point met on the way; STATUS_ITERATION_CAP from a DDA walk; no pdf, so never STATUS_NEGATIVE_PDF. */
#ifndef NARVAL_LOBE_H
#define NARVAL_LOBE_H

#include "shared/camera.h"
#include "shared/march_lights.h"
#include "shared/phase.h"

/* Halvings of the first-hit step: x0 is placed within Δ/64 past the density's zero crossing. */
#define LOBE_BISECTIONS 6

/* The most sub-steps one corrected view-march step is split into (header comment, C2). */
#define LOBE_SUBSTEPS 8

/* First parameter in [seg.t0, seg.t1] where the density is above zero (step 1; 0: none), bisected
 * between the last empty sample (or the start of the occupied piece) and the first non-empty one. */
static inline int lobe_first_hit(KERNEL_CONTEXT_PARAM, NV_PRIVATE const medium_segment* seg,
                                 int steps, NV_PRIVATE float* t_hit) {
  NV_PRIVATE uint* status = &ctx->status;
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, seg, steps);
  *status |= it.status;
  float t, lo = seg->t0;
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t)) {
    const float rho = grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, t));
    if (!(rho > 0.0f)) {
      if (rho != rho) *status |= STATUS_NAN; /* a NaN density must not pass as empty space */
      lo = t;
      continue;
    }
    lo = nv_fmax(lo, it.a); /* before its occupied piece the density is 0 */
    if (grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, lo)) > 0.0f) {
      *t_hit = lo;
      return 1;
    }
    /* Invariant: density(lo) == 0 < density(hi). */
    float hi = t;
    for (int b = 0; b < LOBE_BISECTIONS; ++b) {
      const float mid = 0.5f * (lo + hi);
      if (grid_density(KERNEL_CONTEXT_ARG, vec3_madd(seg->o, seg->d, mid)) > 0.0f)
        hi = mid;
      else
        lo = mid;
    }
    *t_hit = hi;
    return 1;
  }
  return 0;
}

/* Transmittance along a → b (1 where they coincide), marched until every channel's τ exceeds tau_limit. */
static inline vec3 lobe_transmittance_between(KERNEL_CONTEXT_PARAM, vec3 a, vec3 b,
                                              int steps, float tau_limit) {
  NV_PRIVATE uint* status = &ctx->status;
  const vec3 ab = vec3_sub(b, a);
  const float dist = vec3_length(ab);
  if (!(dist > 0.0f)) {
    if (dist != dist) *status |= STATUS_NAN; /* a NaN point, not a coincident one */
    return vec3_splat(1.0f);
  }
  return vec3_exp_neg(march_optical_depth_limited(KERNEL_CONTEXT_ARG, a, vec3_scale(ab, 1.0f / dist), dist, steps,
                                                  tau_limit));
}

/* σs/σt per channel (0 where σt = 0). */
static inline vec3 lobe_albedo(NV_CONSTANT const medium_params* m) {
  const vec3 sig_s = vec3_from4(m->sigma_s);
  const vec3 sig_t = vec3_add(vec3_from4(m->sigma_a), sig_s);
  return vec3_make(sig_t.x > 0.0f ? sig_s.x / sig_t.x : 0.0f, sig_t.y > 0.0f ? sig_s.y / sig_t.y : 0.0f,
                   sig_t.z > 0.0f ? sig_s.z / sig_t.z : 0.0f);
}

/* Lobe direction i: the canonical direction q (about +Z) in the frame (tx, ty, ω). */
static inline vec3 lobe_direction(vec3 tx, vec3 ty, vec3 dir, nv_float4 q) {
  return vec3_add(vec3_add(vec3_scale(tx, q.x), vec3_scale(ty, q.y)), vec3_scale(dir, q.z));
}

/* Eq. 7 (header comment, steps 1-4), bit for bit as the dissertation's reproduction records it. */
static inline vec3 lobe_radiance_eq7(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                     NV_PRIVATE const lobe_params* lp, NV_PRIVATE const node_grid_params* lc,
                                     NV_GLOBAL const nv_float4* dirs, NV_GLOBAL const float* light_cache, vec3 origin,
                                     vec3 dir, vec3 tx, vec3 ty, vec3 Lb, NV_PRIVATE const medium_segment* seg) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const medium_params* m = &s->medium;
  /* 1. First hit. */
  float t_x0;
  if (!lobe_first_hit(KERNEL_CONTEXT_ARG, seg, mp->steps, &t_x0)) return Lb;
  const vec3 x0 = vec3_madd(origin, dir, t_x0);

  /* 2. Lobe centre, depth clamped to the rest of the segment inside the box. */
  const float mean_sigma_t = vec3_average(medium_sigma_t(m));
  const float rest = seg->t1 - t_x0;
  const float depth = lp->depth_factor < mean_sigma_t * rest ? lp->depth_factor / mean_sigma_t : rest;
  const vec3 c = vec3_madd(x0, dir, depth);

  /* 4. Sums over the lobe points. */
  const int n = lp->points;
  const int view_term = !vec3_is_zero(Lb);
  const float tau_limit = mp->min_transmittance > 0.0f
                              ? -nv_log(mp->min_transmittance / nv_fmax(1.0f, vec3_max_component(Lb)))
                              : NV_INFINITY;
  vec3 tr_sum = vec3_splat(0.0f), in_sum = vec3_splat(0.0f);
  for (int i = 0; i < n; ++i) {
    const vec3 d = lobe_direction(tx, ty, dir, dirs[i]);
    const vec3 P = vec3_madd(c, d, lp->radius);
    if (view_term)
      tr_sum = vec3_add(tr_sum, lobe_transmittance_between(KERNEL_CONTEXT_ARG, x0, P, lp->view_steps, tau_limit));
    march_light_sum(KERNEL_CONTEXT_ARG, mp, lc, light_cache, P, d, MARCH_LIGHTS_LOBE, &in_sum);
  }
  const float fn = (float)n;
  const vec3 tr_mean = vec3_make(tr_sum.x / fn, tr_sum.y / fn, tr_sum.z / fn);
  const vec3 in_mean = vec3_make(in_sum.x / fn, in_sum.y / fn, in_sum.z / fn);
  return vec3_add(vec3_mul(Lb, tr_mean), vec3_mul(lobe_albedo(m), in_mean));
}

/* Whether the ball of world radius r about c lies inside the medium's box (C4 then moves no point).
 * Moving a point by r moves index coordinate a by at most r·|row a of world_to_index| (Cauchy-Schwarz);
 * conservative: a ball near a face falls back to the per-point test, so the pixels are that test's. */
static inline int lobe_ball_inside(NV_CONSTANT const medium_params* m, vec3 c, float r) {
  const vec3 p = affine_point(m->world_to_index, c), dims = vec3_from4(m->dims);
  const float pc[3] = {p.x, p.y, p.z}, size[3] = {dims.x, dims.y, dims.z};
  for (int a = 0; a < 3; ++a) {
    const nv_float4 row = m->world_to_index.row[a];
    const float reach = r * nv_sqrt(row.x * row.x + row.y * row.y + row.z * row.z);
    if (!(pc[a] - reach > 0.0f && pc[a] + reach < size[a])) return 0;
  }
  return 1;
}

/* The corrected estimator (header comment, "Corrected"). */
static inline vec3 lobe_radiance_corrected(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                           NV_PRIVATE const lobe_params* lp, NV_PRIVATE const node_grid_params* lc,
                                           NV_GLOBAL const nv_float4* dirs, NV_GLOBAL const float* light_cache,
                                           vec3 origin, vec3 dir, vec3 tx, vec3 ty, vec3 Lb,
                                           NV_PRIVATE const medium_segment* seg) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE uint* status = &ctx->status;
  NV_CONSTANT const medium_params* m = &s->medium;
  /* C1-C2. One march: T_v and t_c = Σ w_k S_k t_k / Σ w_k S_k, w_k = T(before k)·(1 − e^{−σ̄t,k Δ})
   * (channel means), S_k the lights' in-scattering at sample k (Σ w_k t_k / Σ w_k where no light reaches). */
  const float tau_limit = mp->min_transmittance > 0.0f
                              ? -nv_log(mp->min_transmittance / nv_fmax(1.0f, vec3_max_component(Lb)))
                              : NV_INFINITY;
  march_iter it = march_begin(KERNEL_CONTEXT_ARG, seg, lp->view_steps);
  *status |= it.status;
  vec3 tau = vec3_splat(0.0f);
  float w_sum = 0.0f, wt_sum = 0.0f, ws_sum = 0.0f, wst_sum = 0.0f, t_step;
  while (march_next(&it, KERNEL_CONTEXT_ARG, &t_step)) {
    /* C2's sub-steps (header comment). */
    const vec3 dtau_step = vec3_scale(march_sigma_t(KERNEL_CONTEXT_ARG, seg, t_step), it.delta);
    const float x = it.majorant * vec3_average(medium_sigma_t(m)) * it.delta;
    const int subs = x > 1.0f ? (int)nv_fmin(x + 1.0f, (float)LOBE_SUBSTEPS) : 1;
    const float sub = it.delta / (float)subs;
    for (int j = 0; j < subs; ++j) {
      const float t = subs == 1 ? t_step : t_step + ((float)j + 0.5f - 0.5f * (float)subs) * sub;
      const vec3 dtau = subs == 1 ? dtau_step : vec3_scale(march_sigma_t(KERNEL_CONTEXT_ARG, seg, t), sub);
      const float w = nv_exp(-vec3_average(tau)) * (1.0f - nv_exp(-vec3_average(dtau)));
      vec3 S = vec3_splat(0.0f);
      if (w > 0.0f)
        march_light_sum(KERNEL_CONTEXT_ARG, mp, lc, light_cache, vec3_madd(origin, dir, t), dir, MARCH_LIGHTS_LOBE,
                        &S);
      const float ws = w * vec3_average(S);
      w_sum += w;
      wt_sum += w * t;
      ws_sum += ws;
      wst_sum += ws * t;
      tau = vec3_add(tau, dtau);
    }
    if (nv_fmin(tau.x, nv_fmin(tau.y, tau.z)) > tau_limit) break;
  }
  if (!(w_sum > 0.0f)) {
    if (w_sum != w_sum) *status |= STATUS_NAN; /* a NaN density, not empty space */
    return Lb;
  }
  const vec3 Tv = vec3_exp_neg(tau);
  const vec3 c = vec3_madd(origin, dir, ws_sum > 0.0f ? wst_sum / ws_sum : wt_sum / w_sum);

  /* C3-C4. Points pulled in to the box along d_i; no intersection when the ball is inside (bench/RESULTS.md). */
  const float r = lp->radius / vec3_average(medium_sigma_t(m));
  const int n = lp->points;
  const int ball_inside = lobe_ball_inside(m, c, r);
  vec3 in_sum = vec3_splat(0.0f);
  for (int i = 0; i < n; ++i) {
    const vec3 d = lobe_direction(tx, ty, dir, dirs[i]);
    medium_segment inside;
    const float reach = ball_inside ? r : medium_intersect(m, c, d, 0.0f, r, &inside) ? inside.t1 : 0.0f;
    march_light_sum(KERNEL_CONTEXT_ARG, mp, lc, light_cache, vec3_madd(c, d, reach), d, MARCH_LIGHTS_LOBE, &in_sum);
  }
  const float fn = (float)n;
  const vec3 in_mean = vec3_make(in_sum.x / fn, in_sum.y / fn, in_sum.z / fn);
  /* L = L_b·T_v + (1 − T_v)·albedo·S̄ (C1). */
  const vec3 opacity = vec3_sub(vec3_splat(1.0f), Tv);
  return vec3_add(vec3_mul(Lb, Tv), vec3_mul(vec3_mul(opacity, lobe_albedo(m)), in_mean));
}

/* The lobe's frame (t, b, ω) about unit ω = `dir` (step 3): t = `right` made perpendicular to ω, b = ω × t;
 * along ±right (no camera ray, which leans forward, but a caller's may be) any perpendicular frame serves. */
static inline void lobe_frame(vec3 dir, vec3 right, NV_PRIVATE vec3* tx, NV_PRIVATE vec3* ty) {
  const vec3 perp = vec3_madd(right, dir, -vec3_dot(right, dir));
  const float len = vec3_length(perp);
  if (len > 1e-6f) {
    *tx = vec3_scale(perp, 1.0f / len);
  } else {
    vec3 unused;
    vec3_basis(dir, tx, &unused);
  }
  *ty = vec3_cross(dir, *tx);
}

/* Radiance of the view ray from `origin` along unit `dir`; `right`: the camera's unit right vector
 * (lobe_frame); `dirs`: lp->points unit directions about +Z. */
static inline vec3 lobe_radiance(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp,
                                 NV_PRIVATE const lobe_params* lp, NV_PRIVATE const node_grid_params* lc,
                                 NV_GLOBAL const nv_float4* dirs, NV_GLOBAL const float* light_cache, vec3 origin,
                                 vec3 dir, vec3 right) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_CONSTANT const light_params* lights = ctx->lights;
  /* L_b; the view ray stops at the first (opaque) light surface it meets. */
  vec3 Lb;
  medium_segment seg;
  if (!march_view(s, lights, origin, dir, &Lb, &seg) || lp->points < 1) return Lb;

  /* 3. Right-handed frame (t, b, ω). */
  vec3 tx, ty;
  lobe_frame(dir, right, &tx, &ty);
  const int corrected = lp->variant == LOBE_CORRECTED; /* else LOBE_EQ7, the host's only other variant */
  const vec3 L = corrected
                     ? lobe_radiance_corrected(KERNEL_CONTEXT_ARG, mp, lp, lc, dirs, light_cache, origin, dir, tx, ty, Lb, &seg)
                     : lobe_radiance_eq7(KERNEL_CONTEXT_ARG, mp, lp, lc, dirs, light_cache, origin, dir, tx, ty, Lb, &seg);
#ifdef EMISSION
  /* The medium's own light over `steps` samples in both variants: corrected's view_steps (16) alias flames. */
  return vec3_add(L, march_emission(KERNEL_CONTEXT_ARG, &seg, mp->steps, mp->min_transmittance));
#else
  return L;
#endif
}

/* The pixel (px, py), ray through its centre (no jitter); a non-finite result is reported, then 0. */
static inline vec3 lobe_pixel(KERNEL_CONTEXT_PARAM, NV_PRIVATE const march_params* mp, NV_PRIVATE const lobe_params* lp,
                              NV_PRIVATE const node_grid_params* lc, NV_GLOBAL const nv_float4* dirs,
                              NV_GLOBAL const float* light_cache, int px, int py) {
  NV_CONSTANT const scene_params* s = ctx->scene;
  NV_PRIVATE uint* status = &ctx->status;
  const ray3 r = camera_pixel_centre_ray(&s->camera, px, py);
  return status_finite_or_zero(
      status, lobe_radiance(KERNEL_CONTEXT_ARG, mp, lp, lc, dirs, light_cache, r.origin, r.dir, vec3_from4(s->camera.right)));
}

#endif
