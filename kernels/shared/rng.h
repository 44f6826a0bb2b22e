/* rng.h: counter-based random numbers, Philox4x32-10 (Salmon et al. 2011, "Parallel random
 * numbers: as easy as 1, 2, 3"). A stream is keyed by the seed and addressed by (pixel, sample,
 * draw): a pixel's value depends on nothing else, not on work-group size, launch order or how the
 * samples are split into passes (DESIGN.md, pathtrace). */
#ifndef NARVAL_RNG_H
#define NARVAL_RNG_H

#include "shared/compat.h"

#define RNG_PHILOX_M0 0xD2511F53u
#define RNG_PHILOX_M1 0xCD9E8D57u
#define RNG_PHILOX_W0 0x9E3779B9u
#define RNG_PHILOX_W1 0xBB67AE85u

static inline uint rng_mulhi(uint a, uint b) {
#ifdef NV_DEVICE
  return mul_hi(a, b);
#else
  return (uint)(((uint64_t)a * (uint64_t)b) >> 32);
#endif
}

/* Philox4x32 with 10 rounds: counter c[4], key k[2] -> out[4]. */
static inline void rng_philox4x32(const NV_PRIVATE uint* c_in, uint k0, uint k1, NV_PRIVATE uint* out) {
  uint c0 = c_in[0], c1 = c_in[1], c2 = c_in[2], c3 = c_in[3];
  for (int round = 0; round < 10; ++round) {
    const uint hi0 = rng_mulhi(RNG_PHILOX_M0, c0), lo0 = RNG_PHILOX_M0 * c0;
    const uint hi1 = rng_mulhi(RNG_PHILOX_M1, c2), lo1 = RNG_PHILOX_M1 * c2;
    c0 = hi1 ^ c1 ^ k0;
    c1 = lo1;
    c2 = hi0 ^ c3 ^ k1;
    c3 = lo0;
    k0 += RNG_PHILOX_W0;
    k1 += RNG_PHILOX_W1;
  }
  out[0] = c0;
  out[1] = c1;
  out[2] = c2;
  out[3] = c3;
}

typedef struct rng_state {
  uint counter[4]; /* pixel, sample, block of four draws, 0 */
  uint key0, key1; /* seed */
  uint buffer[4];
  uint used;       /* draws consumed from buffer (4: refill) */
} rng_state;

static inline rng_state rng_init(uint seed, uint pixel, uint sample) {
  rng_state r;
  r.counter[0] = pixel;
  r.counter[1] = sample;
  r.counter[2] = 0u;
  r.counter[3] = 0u;
  r.key0 = seed;
  r.key1 = 0x6E617276u; /* "narv": a fixed second key word */
  r.used = 4u;
  r.buffer[0] = r.buffer[1] = r.buffer[2] = r.buffer[3] = 0u;
  return r;
}

static inline uint rng_next_uint(NV_PRIVATE rng_state* r) {
  if (r->used == 4u) {
    rng_philox4x32(r->counter, r->key0, r->key1, r->buffer);
    r->counter[2] += 1u;
    r->used = 0u;
  }
  return r->buffer[r->used++];
}

/* Uniform in [0, 1): the top 24 bits, exactly representable, never 1. */
static inline float rng_uniform(NV_PRIVATE rng_state* r) {
  return (float)(rng_next_uint(r) >> 8) * (1.0f / 16777216.0f);
}

#endif
