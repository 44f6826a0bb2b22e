/* vec3.h: three-component float vectors, written as functions so the same code runs on the device
 * (float3) and the host (struct vec3). nv_float4 is the storage type for vectors in structs that
 * cross host and device: four plain floats, 4-byte aligned on both sides (see structs.h). */
#ifndef NARVAL_VEC3_H
#define NARVAL_VEC3_H

#include "shared/compat.h"

typedef struct nv_float4 {
  float x, y, z, w;
} nv_float4;

static inline vec3 vec3_from4(nv_float4 v) { return vec3_make(v.x, v.y, v.z); }
static inline nv_float4 vec3_to4(vec3 v, float w) {
  nv_float4 r;
  r.x = v.x;
  r.y = v.y;
  r.z = v.z;
  r.w = w;
  return r;
}
static inline vec3 vec3_splat(float s) { return vec3_make(s, s, s); }
static inline vec3 vec3_add(vec3 a, vec3 b) { return vec3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 vec3_sub(vec3 a, vec3 b) { return vec3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 vec3_mul(vec3 a, vec3 b) { return vec3_make(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 vec3_div(vec3 a, vec3 b) { return vec3_make(a.x / b.x, a.y / b.y, a.z / b.z); }
static inline vec3 vec3_scale(vec3 a, float s) { return vec3_make(a.x * s, a.y * s, a.z * s); }
/* a + b * s */
static inline vec3 vec3_madd(vec3 a, vec3 b, float s) {
  return vec3_make(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static inline float vec3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 vec3_cross(vec3 a, vec3 b) {
  return vec3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float vec3_length(vec3 a) { return nv_sqrt(vec3_dot(a, a)); }
static inline vec3 vec3_normalize(vec3 a) { return vec3_scale(a, 1.0f / vec3_length(a)); }
static inline float vec3_max_component(vec3 a) { return nv_fmax(a.x, nv_fmax(a.y, a.z)); }
static inline float vec3_average(vec3 a) { return (a.x + a.y + a.z) * (1.0f / 3.0f); }
static inline vec3 vec3_min(vec3 a, vec3 b) {
  return vec3_make(nv_fmin(a.x, b.x), nv_fmin(a.y, b.y), nv_fmin(a.z, b.z));
}
static inline vec3 vec3_max(vec3 a, vec3 b) {
  return vec3_make(nv_fmax(a.x, b.x), nv_fmax(a.y, b.y), nv_fmax(a.z, b.z));
}
static inline vec3 vec3_exp_neg(vec3 a) {
  return vec3_make(nv_exp(-a.x), nv_exp(-a.y), nv_exp(-a.z));
}
static inline int vec3_is_finite(vec3 a) {
  return nv_isfinite(a.x) && nv_isfinite(a.y) && nv_isfinite(a.z);
}
static inline int vec3_is_zero(vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }

/* Builds an orthonormal basis (t, b, n) around unit n without branching on a threshold
 * (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"). */
static inline void vec3_basis(vec3 n, NV_PRIVATE vec3* t, NV_PRIVATE vec3* b) {
  const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  *t = vec3_make(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = vec3_make(c, sign + n.y * n.y * a, -n.y);
}

/* Row-major 3x4 affine map stored as three rows (x, y, z, translation). */
typedef struct nv_affine {
  nv_float4 row[3];
} nv_affine;

static inline vec3 affine_point(nv_affine m, vec3 p) {
  return vec3_make(m.row[0].x * p.x + m.row[0].y * p.y + m.row[0].z * p.z + m.row[0].w,
                   m.row[1].x * p.x + m.row[1].y * p.y + m.row[1].z * p.z + m.row[1].w,
                   m.row[2].x * p.x + m.row[2].y * p.y + m.row[2].z * p.z + m.row[2].w);
}
static inline vec3 affine_vector(nv_affine m, vec3 v) {
  return vec3_make(m.row[0].x * v.x + m.row[0].y * v.y + m.row[0].z * v.z,
                   m.row[1].x * v.x + m.row[1].y * v.y + m.row[1].z * v.z,
                   m.row[2].x * v.x + m.row[2].y * v.y + m.row[2].z * v.z);
}

#endif
