/* accum.h: exact accumulation of a pixel's samples (DESIGN.md, pathtrace). Each sample's RGB is
 * rounded once to 128-bit two's-complement fixed point (units of 2^-64) and added as an integer.
 * Integer addition is associative, so the sum of samples [0, N) is the same bits whether they were
 * added in one launch, in many, or in separate processes whose sums are added afterwards
 * (`narval merge`): the split of a render never changes its pixels. Float (even compensated)
 * summation cannot promise that, since it depends on the order of the additions.
 *
 * Range: a sample component must satisfy |x| < 2^40 (about 1.1e12); the sum then stays below 2^63
 * for up to 2^23 samples per pixel at that bound. Resolution 2^-64: components below 2^-65 round to
 * 0, an error far below any radiance a float image can show after dividing by the sample count.
 * A NaN, infinite or out-of-range component is not added; the sample is counted instead, and the
 * host shows a pixel with any such sample as NaN (as a float sum would have). */
#ifndef NARVAL_ACCUM_H
#define NARVAL_ACCUM_H

#include "shared/compat.h"

/* 64-bit words per pixel in the accumulator buffer: R, G, B as (low, high) word pairs, then the
 * count of samples that were not added, then a word of padding (64-byte rows, aligned loads). */
#define ACCUM_WORDS 8
#define ACCUM_REJECTED_WORD 6

/* |x| < 2^40: the largest float exponent field accepted is 127 + 39. */
#define ACCUM_MAX_EXPONENT_FIELD 166u

/* Adds round(x·2^64) to the 128-bit value (*lo, *hi); returns 0, or 1 without adding anything when
 * x is NaN, infinite or |x| ≥ 2^40. Round half up on the magnitude, so x and -x add opposite values. */
static inline int accum_fixed_add(NV_PRIVATE nv_ulong* lo, NV_PRIVATE nv_ulong* hi, float x) {
  const uint bits = nv_float_bits(x);
  const uint exponent = (bits >> 23) & 0xffu;
  if (exponent > ACCUM_MAX_EXPONENT_FIELD) return 1; /* NaN and inf have exponent 255 */
  if (exponent == 0u) return 0; /* zero and subnormals (< 2^-126) round to 0 */
  const nv_ulong mantissa = (nv_ulong)((bits & 0x7fffffu) | 0x800000u);
  /* |x| = mantissa·2^(exponent-150), so |x|·2^64 = mantissa·2^k with k = exponent - 86. */
  const int k = (int)exponent - 86;
  nv_ulong add_lo, add_hi;
  if (k >= 64) {
    add_lo = 0;
    add_hi = mantissa << (k - 64);
  } else if (k > 0) {
    add_lo = mantissa << k;
    add_hi = mantissa >> (64 - k);
  } else if (k == 0) {
    add_lo = mantissa;
    add_hi = 0;
  } else if (k >= -24) {
    add_lo = (mantissa + ((nv_ulong)1 << (-k - 1))) >> (-k);
    add_hi = 0;
  } else {
    return 0; /* below 2^-65 */
  }
  if (bits >> 31) { /* negative: subtract, borrowing from the high word */
    *hi -= add_hi + (*lo < add_lo ? 1u : 0u);
    *lo -= add_lo;
  } else {
    const nv_ulong sum = *lo + add_lo;
    *hi += add_hi + (sum < add_lo ? 1u : 0u);
    *lo = sum;
  }
  return 0;
}

/* Adds one sample's RGB to a pixel's ACCUM_WORDS words. */
static inline void accum_add_sample(NV_PRIVATE nv_ulong* words, vec3 L) {
  int rejected = accum_fixed_add(&words[0], &words[1], L.x);
  rejected |= accum_fixed_add(&words[2], &words[3], L.y);
  rejected |= accum_fixed_add(&words[4], &words[5], L.z);
  words[ACCUM_REJECTED_WORD] += (nv_ulong)rejected;
}

#endif
