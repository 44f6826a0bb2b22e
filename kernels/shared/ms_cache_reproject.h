/* ms_cache_reproject.h: the view layout's cache (ms_cache_view.h) carried over a camera move. The view
 * cache's nodes are aimed at one camera: its columns are the camera's rays and each node holds the
 * in-scattering towards it, so a moved camera needs a new cache. Building it takes many frames
 * (host/render/device_ms_cache.cpp, budgeted refinement); meanwhile the nodes of the new layout are read
 * from the old cache at the same world points (the reprojection of temporal reuse in real-time engines:
 * Hillaire 2015, "Physically based and unified volumetric rendering in Frostbite", reprojects its
 * froxels' scattering the same way), and that prior fades out as the new paths come in (the blend).
 *
 * Reprojection (ms_view_reproject_node): a new node stands for its slice; its point is where the slice
 * holds half of what the pixel sees of it (T midway between the slice's ends, τ linear in distance
 * across it: ms_view_node_depth). That point is projected into the old image (camera_project); in each
 * of the four old columns around it the old node whose slice holds its distance from the old camera is
 * read (the first slice before the medium, the last past it), bilinearly, columns without medium
 * dropping out as in a lookup. The old nodes' path counts, mixed the same way, say what the value is
 * worth; a point outside the old image or behind its camera reads the nearest columns' value worth no
 * paths (the new paths replace it at once). The value is blurred by the old slices' width along the
 * new rays; the same camera gives back every node exactly.
 *
 * Direction: an old node holds the in-scattering towards the old camera, J(w_old), and the new pose
 * wants J(w_new), w the direction from the point to the camera. For an isotropic phase function they
 * are equal; for a peaked one (HG's lobe is about 1 − g radians wide) they differ within a few degrees
 * in a cloud (bench/RESULTS.md). Each node also holds ∇J (MS_VIEW_TURN), estimated from its own paths by
 * the score of their directions: J(w) = E[L·p(s·w)/q(s)] over directions s drawn with density q, so
 * ∇_w J = E[L·(p(s·w)/q(s))·(d ln p/dμ)·(s − μw)] (the likelihood-ratio estimator; the direct light's
 * own change is left out). The value read is J·(1 + ∇J·(w_new − w_old)/J), the first-order change,
 * its factor kept within [1/2, 2].
 *
 * Worth: what is left is second order, a relative bias of about x² for a turn of x = c/w phase widths
 * (c = |w_new − w_old| = 2·sin(θ/2), w = phase_width: 1 − |g| rad for HG). The mean of n new paths
 * has a relative variance v/n, v = (mean of L² − J²)/J² a path (the old node's, from its paths), so
 * the prior is worth as many paths as make that equal its bias squared, n = v/x⁴, and never more than
 * the old node held. A few degrees keep the old paths in a cloud; a turn of several widths leaves a
 * fraction of a path, so the first new paths replace it; a thin medium, whose paths are less noisy,
 * trusts its prior less at the same turn (bench/RESULTS.md).
 *
 * Blend (ms_view_blend_node): with n new paths at a node (`target` of them to come), its
 * prior of m paths counts m·(1 − n/N): the drawn value is the weighted mean, the prior's share falls
 * as the new paths come in and is 0 when they are all in, so the cache ends as one built at the new
 * pose from nothing, bit for bit (the host then drops the prior). */
#ifndef NARVAL_MS_CACHE_REPROJECT_H
#define NARVAL_MS_CACHE_REPROJECT_H

#include "shared/ms_cache_view.h"

/* Distance along node v's column to where its slice holds half of what the pixel sees of it. */
static inline float ms_view_node_depth(NV_GLOBAL const float* v) {
  const float a = v[MS_VIEW_TAU], b = v[MS_VIEW_TAU_END];
  const float mid = -nv_log(0.5f * (nv_exp(-a) + nv_exp(-b)));
  const float f = b > a ? nv_fmin(1.0f, nv_fmax(0.0f, (mid - a) / (b - a))) : 0.5f;
  return v[MS_VIEW_T] + f * (v[MS_VIEW_T_END] - v[MS_VIEW_T]);
}

/* Node `node` of `placed` (the cache `mc` just placed for camera `cam`; the medium's `phase`) into `out`, its values
 * and count read from `previous`, the cache `old_mc` drawn for camera `old` (a view layout of any size:
 * the viewer draws smaller frames while the camera moves) ("Reprojection"). */
static inline void ms_view_reproject_node(NV_CONSTANT const camera_params* cam, phase_params phase,
                                          NV_PRIVATE const camera_params* old,
                                          NV_PRIVATE const ms_cache_params* mc, NV_PRIVATE const ms_cache_params* old_mc,
                                          NV_GLOBAL const float* previous, NV_GLOBAL const float* placed, int node,
                                          NV_GLOBAL float* out) {
  NV_PRIVATE const node_grid_params* c = &mc->grid;
  NV_PRIVATE const node_grid_params* oc = &old_mc->grid;
  const size_t slice_stride = (size_t)oc->nx * (size_t)oc->ny * MS_CACHE_STRIDE;
  NV_GLOBAL const float* v = placed + (size_t)node * MS_CACHE_STRIDE;
  for (int i = 0; i < MS_CACHE_STRIDE; ++i) out[i] = v[i];
  for (int i = 0; i < 4; ++i) out[i] = 0.0f;
  if (!(v[MS_VIEW_TAU] >= 0.0f)) return;
  const ray3 r = ms_view_column_ray(cam, mc->tile, node % c->nx, (node / c->nx) % c->ny);
  const vec3 x = vec3_madd(r.origin, r.dir, ms_view_node_depth(v));
  float px, py;
  if (!camera_project(old, x, &px, &py)) return;
  const int inside = px >= 0.0f && py >= 0.0f && px <= (float)old->width && py <= (float)old->height;
  const float t = vec3_length(vec3_sub(x, vec3_from4(old->position)));
  const ms_view_columns cols = ms_view_locate_at(old_mc, px, py);
  const vec3 turn = vec3_sub(vec3_normalize(vec3_sub(vec3_from4(cam->position), x)),
                             vec3_normalize(vec3_sub(vec3_from4(old->position), x)));
  const float widths = vec3_length(turn) / phase_width(phase), x4 = widths * widths * widths * widths; /* ("Worth") */
  vec3 sum = vec3_splat(0.0f);
  float count = 0.0f, weight = 0.0f;
  for (int k = 0; k < 4; ++k) {
    NV_GLOBAL const float* col = previous + (size_t)cols.column[k] * MS_CACHE_STRIDE;
    if (!(cols.w[k] > 0.0f) || col[MS_VIEW_TAU] < 0.0f) continue;
    int s = 0;
    while (s + 1 < oc->nz && col[(size_t)(s + 1) * slice_stride + MS_VIEW_T] <= t) ++s;
    NV_GLOBAL const float* o = col + (size_t)s * slice_stride;
    const vec3 J = vec3_make(o[0], o[1], o[2]);
    const float grey = vec3_average(J);
    const vec3 gradient = vec3_make(o[MS_VIEW_TURN], o[MS_VIEW_TURN + 1], o[MS_VIEW_TURN + 2]);
    const float change = grey > 0.0f ? vec3_dot(gradient, turn) / grey : 0.0f;
    sum = vec3_add(sum, vec3_scale(J, cols.w[k] * nv_fmin(2.0f, nv_fmax(0.5f, 1.0f + change))));
    const float v = grey > 0.0f ? nv_fmax(0.0f, o[MS_CACHE_SQUARE] - grey * grey) / (grey * grey) : 0.0f;
    count += cols.w[k] * (v < o[3] * x4 ? v / x4 : o[3]);
    weight += cols.w[k];
  }
  if (!(weight > 0.0f)) return;
  out[0] = sum.x / weight;
  out[1] = sum.y / weight;
  out[2] = sum.z / weight;
  out[3] = inside ? count / weight : 0.0f;
}

/* Node `fresh` (the new paths' running means, or their filtered copy) drawn with its reprojected
 * `prior` into `out` ("Blend"); nodes without medium are fresh's. */
static inline void ms_view_blend_node(NV_GLOBAL const float* prior, NV_GLOBAL const float* fresh, int target,
                                      NV_GLOBAL float* out) {
  for (int i = 0; i < MS_CACHE_STRIDE; ++i) out[i] = fresh[i];
  if (!(fresh[MS_VIEW_TAU] >= 0.0f)) return;
  const float n = fresh[3];
  const float m = prior[3] * nv_fmax(0.0f, 1.0f - n / nv_fmax((float)target, 1.0f));
  if (!(n > 0.0f)) { /* no new path yet: the prior alone */
    for (int i = 0; i < 4; ++i) out[i] = prior[i];
    return;
  }
  if (!(m > 0.0f)) return; /* the prior has faded: fresh's, as they are */
  for (int i = 0; i < 3; ++i) out[i] = (m * prior[i] + n * fresh[i]) / (m + n);
  out[3] = m + n;
}

#endif
