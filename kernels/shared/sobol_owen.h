/* sobol_owen.h: a progressive two-dimensional low-discrepancy sequence, Sobol's first two dimensions
 * with hash-based Owen scrambling (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
 * Used for the few leading dimensions of many paths at one point on which their result depends
 * smoothly (the multiple-scattering cache's paths: where in its slice a path starts, the direction
 * it leaves in, the light point its next-event estimate aims at; ms_cache_build.h); the rest of a
 * path draws from its counter-based stream (rng.h) as before.
 *
 * Sobol's first two dimensions form a (0,2)-sequence in base 2: every aligned block of 2^m indices,
 * [c·2^m, (c+1)·2^m), is a (0,m,2)-net (each of the 2^m elementary intervals [a/2^j, (a+1)/2^j) ×
 * [b/2^{m−j}, (b+1)/2^{m−j}) holds exactly one point). Owen scrambling (a random permutation of each
 * binary digit, chosen by the digits above it) keeps the net property and makes each point uniform
 * on the unit square, so an estimate over the points is unbiased; scrambling the index the same way
 * maps the first 2^m indices onto one aligned block, so every power-of-two prefix of the sequence is
 * still a net (the property a progressive build needs), and different index seeds decorrelate pairs
 * of dimensions drawn with the same index ("padding", pbrt-v4's PaddedSobolSampler).
 * Hash: Laine and Karras's bit-mixing permutation (2011, "Stratified sampling for stochastic
 * transparency") on the bit-reversed value, with Burley's constants: addition and multiplication by
 * an even constant then xor carry information only towards higher bits, so on the reversed value
 * each output digit depends on the input digits above it alone, which is Owen's scrambling. */
#ifndef NARVAL_SOBOL_OWEN_H
#define NARVAL_SOBOL_OWEN_H

#include "shared/compat.h"

static inline uint sobol_owen_reverse_bits(uint x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
  return (x >> 16) | (x << 16);
}

/* Owen scrambling of x read as a binary fraction 0.x₃₁x₃₀…, by seed. */
static inline uint sobol_owen_scramble(uint x, uint seed) {
  x = sobol_owen_reverse_bits(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return sobol_owen_reverse_bits(x);
}

/* Sobol's dimension 0 (the van der Corput sequence: the index's bits reversed) and dimension 1
 * (direction numbers v_1 = 2^31, v_{j+1} = v_j xor v_j/2, from the primitive polynomial x + 1), as
 * 32-bit binary fractions. */
static inline uint sobol_owen_dim0(uint index) { return sobol_owen_reverse_bits(index); }
static inline uint sobol_owen_dim1(uint index) {
  uint x = 0u;
  for (uint v = 0x80000000u; index != 0u; index >>= 1, v ^= v >> 1)
    if (index & 1u) x ^= v;
  return x;
}

/* A 32-bit binary fraction as a float in [0, 1): its top 24 bits (rng_uniform's convention). */
static inline float sobol_owen_to_unit(uint x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* Point `index` of the scrambled sequence keyed by three seeds (the index's and each axis's). */
static inline void sobol_owen_2d(uint index, uint seed_index, uint seed_x, uint seed_y, NV_PRIVATE float* u1,
                                 NV_PRIVATE float* u2) {
  const uint i = sobol_owen_scramble(index, seed_index);
  *u1 = sobol_owen_to_unit(sobol_owen_scramble(sobol_owen_dim0(i), seed_x));
  *u2 = sobol_owen_to_unit(sobol_owen_scramble(sobol_owen_dim1(i), seed_y));
}

#endif
