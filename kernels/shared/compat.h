/* compat.h: the one place where OpenCL C and C++ differ (Cycles' kernel/device/<x>/compat.h idea).
 * Every other header in kernels/shared/ is plain C that compiles as OpenCL C 1.2 and as C++17, so
 * host unit tests exercise the very code the device runs. Rules for shared headers: functions are
 * `static inline`, prefixed by module, and use no references, templates or overloads. */
#ifndef NARVAL_COMPAT_H
#define NARVAL_COMPAT_H

#ifdef __OPENCL_C_VERSION__
#define NV_DEVICE 1
#define NV_GLOBAL __global
#define NV_CONSTANT __constant
#define NV_PRIVATE
/* No contraction into FMA: host and device then round alike, and results do not depend on which
 * device fuses what. */
#pragma OPENCL FP_CONTRACT OFF
typedef float3 vec3;
typedef ulong nv_ulong; /* 64-bit unsigned (counters, tracking.h) */
#define vec3_make(x, y, z) ((float3)((x), (y), (z)))
#define nv_sqrt sqrt
#define nv_exp exp
#define nv_log log
#define nv_expm1 expm1
#define nv_log1p log1p
#define nv_fabs fabs
#define nv_fmin fmin
#define nv_fmax fmax
#define nv_sin sin
#define nv_cos cos
#define nv_tan tan
#define nv_floor floor
#define nv_isfinite isfinite
#define nv_pow pow
#define nv_float_bits(x) as_uint(x)
#else
#include <math.h>
#include <stdint.h>
#include <string.h>
#define NV_GLOBAL
#define NV_CONSTANT
#define NV_PRIVATE
typedef uint32_t uint;
typedef uint64_t nv_ulong;
typedef struct vec3 {
  float x, y, z;
} vec3;
static inline vec3 vec3_make(float x, float y, float z) {
  vec3 v;
  v.x = x;
  v.y = y;
  v.z = z;
  return v;
}
/* The float versions of libm, called by their C names so host and device round alike. */
#define nv_sqrt sqrtf
#define nv_exp expf
#define nv_log logf
#define nv_expm1 expm1f
#define nv_log1p log1pf
#define nv_fabs fabsf
#define nv_fmin fminf
#define nv_fmax fmaxf
#define nv_sin sinf
#define nv_cos cosf
#define nv_tan tanf
#define nv_floor floorf
#define nv_isfinite isfinite
#define nv_pow powf
/* The IEEE-754 bits of a float (OpenCL's as_uint). */
static inline uint32_t nv_float_bits(float x) {
  uint32_t bits;
  memcpy(&bits, &x, sizeof bits);
  return bits;
}
#endif

#define NV_PI 3.14159265358979323846f
#define NV_INV_PI 0.31830988618379067154f
#define NV_INV_4PI 0.07957747154594766788f
#define NV_INFINITY (1.0e30f * 1.0e30f)

#endif
