// rng_test.cpp: the counter-based generator of kernels/shared/rng.h on the host (the very code the
// device compiles): Philox4x32-10 against the Random123 known-answer vectors, uniformity of
// rng_uniform, independence of neighbouring (pixel, sample) streams, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "shared/rng.h"
#include "unit/stat_util.h"

namespace {

// Statistics helpers (gammaQ, equalCellsChiSquarePValue, correlation): tests/unit/stat_util.h.
using namespace narval::test;

struct Kat {
  uint32_t ctr[4];
  uint32_t key[2];
  uint32_t expected[4];
};

// ---- tests ----

// The helpers themselves: tabulated χ² tail P(χ²₁₀ > 18.307038) = 0.05, and for 999 dof at the
// Wilson–Hilferty 0.001 quantile 999·(1 − 2/(9·999) + 3.090232·√(2/(9·999)))³ = 1142.865 the exact
// tail 9.98828e-4 (mpmath.gammainc(499.5, 571.4325, inf, regularized=True)); the correlation of
// y = x (1) and y = −x (−1).
TEST(RngStatHelpers, KnownValues) {
  EXPECT_NEAR(gammaQ(5.0, 18.307038 / 2.0), 0.05, 1e-6);
  EXPECT_NEAR(gammaQ(999.0 / 2.0, 1142.865 / 2.0), 9.98828e-4, 1e-8);
  const std::vector<double> x = {1, 2, 3, 5}, y = {-1, -2, -3, -5};
  EXPECT_NEAR(correlation(x, x), 1.0, 1e-12);
  EXPECT_NEAR(correlation(x, y), -1.0, 1e-12);
}

// Random123 1.14, tests/kat_vectors, the three "philox4x32 10" lines (columns: counter[4], key[2],
// expected output[4]):
//   00000000 00000000 00000000 00000000  00000000 00000000  -> 6627e8d5 e169c58d bc57ac4c 9b00dbd8
//   ffffffff ffffffff ffffffff ffffffff  ffffffff ffffffff  -> 408f276d 41c83b0e a20bc7c6 6d5451fd
//   243f6a88 85a308d3 13198a2e 03707344  a4093822 299f31d0  -> d16cfe09 94fdcceb 5001e420 24126ea1
// (the last counter/key are the hex digits of π).
TEST(RngPhilox, MatchesRandom123KnownAnswers) {
  const Kat kats[] = {
      {{0x00000000u, 0x00000000u, 0x00000000u, 0x00000000u},
       {0x00000000u, 0x00000000u},
       {0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u}},
      {{0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu},
       {0xffffffffu, 0xffffffffu},
       {0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu}},
      {{0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u},
       {0xa4093822u, 0x299f31d0u},
       {0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u}},
  };
  for (const Kat& k : kats) {
    uint ctr[4] = {k.ctr[0], k.ctr[1], k.ctr[2], k.ctr[3]};
    uint out[4] = {0, 0, 0, 0};
    rng_philox4x32(ctr, k.key[0], k.key[1], out);
    for (int i = 0; i < 4; ++i)
      EXPECT_EQ(out[i], k.expected[i]) << "counter " << std::hex << k.ctr[0] << ", word " << i;
    // The counter is an input only.
    for (int i = 0; i < 4; ++i) EXPECT_EQ(ctr[i], k.ctr[i]);
  }
}

// The stream layout rng.h documents: draws 4b..4b+3 of (seed, pixel, sample) are Philox of counter
// (pixel, sample, b, 0) under key (seed, 0x6E617276), in order. This is what makes a pixel's value
// independent of launch order and pass splitting.
TEST(RngStream, IsPhiloxOfPixelSampleBlock) {
  const uint seed = 42u, pixel = 123457u, sample = 99u;
  rng_state r = rng_init(seed, pixel, sample);
  for (uint block = 0; block < 5; ++block) {
    const uint ctr[4] = {pixel, sample, block, 0u};
    uint expected[4];
    rng_philox4x32(ctr, seed, 0x6E617276u, expected);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(rng_next_uint(&r), expected[i]) << "block " << block << ", word " << i;
  }
}

// rng_uniform = (x >> 8) · 2^-24: exact, in [0, 1). White-box on the buffer: x = 0 -> 0,
// x = 0xffffffff -> (2^24 − 1)/2^24 = 0.99999994 < 1, x = 0x80000000 -> 0.5, x = 0xff -> 0 (the low
// 8 bits are dropped).
TEST(RngUniform, MapsTopBitsIntoHalfOpenUnitInterval) {
  rng_state r = rng_init(0u, 0u, 0u);
  r.buffer[0] = 0u;
  r.buffer[1] = 0xffffffffu;
  r.buffer[2] = 0x80000000u;
  r.buffer[3] = 0xffu;
  r.used = 0u;
  EXPECT_EQ(rng_uniform(&r), 0.0f);
  const float top = rng_uniform(&r);
  EXPECT_EQ(top, 16777215.0f / 16777216.0f);
  EXPECT_LT(top, 1.0f);
  EXPECT_EQ(rng_uniform(&r), 0.5f);
  EXPECT_EQ(rng_uniform(&r), 0.0f);
}

// 10⁶ draws of one stream: all in [0, 1), mean 1/2 within 4σ (σ = √(1/12/N) = 2.9e-4; two-sided
// false-alarm 6.3e-5), and a χ² test over 1000 equal bins (expected 1000 per bin, dof 999) at
// significance 1e-3 / 2 (Šidák-style split with the cross-pixel test below).
TEST(RngUniform, OneStreamIsUniform) {
  const int n = 1000000, bins = 1000;
  rng_state r = rng_init(7u, 31u, 5u);
  std::vector<double> counts(bins, 0.0);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const float u = rng_uniform(&r);
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += u;
    counts[static_cast<int>(u * bins)] += 1.0;
  }
  const double sigma = std::sqrt(1.0 / 12.0 / n);
  EXPECT_NEAR(sum / n, 0.5, 4.0 * sigma);
  double chi2 = 0.0;
  const double p = equalCellsChiSquarePValue(counts, &chi2);
  EXPECT_GE(p, 1e-3 / 2) << "chi2 = " << chi2;
  RecordProperty("p_value_one_stream", std::to_string(p));
}

// The first draw of 10⁶ consecutive pixels (one draw per stream): uniform by the same χ² test. This
// is what a one-sample-per-pixel image sees.
TEST(RngUniform, FirstDrawsAcrossPixelsAreUniform) {
  const int n = 1000000, bins = 1000;
  std::vector<double> counts(bins, 0.0);
  double sum = 0.0;
  for (int p = 0; p < n; ++p) {
    rng_state r = rng_init(7u, static_cast<uint>(p), 0u);
    const float u = rng_uniform(&r);
    sum += u;
    counts[static_cast<int>(u * bins)] += 1.0;
  }
  EXPECT_NEAR(sum / n, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / n));
  double chi2 = 0.0;
  const double p = equalCellsChiSquarePValue(counts, &chi2);
  EXPECT_GE(p, 1e-3 / 2) << "chi2 = " << chi2;
}

// Neighbouring streams are uncorrelated. For M = 2·10⁵ base streams and the first 8 draws of each,
// pair draw j of (seed, pixel, sample) with draw j of a neighbour: (pixel + 1), (sample + 1),
// (seed + 1), and within one stream draw j with draw j + 1 (which crosses a Philox block every 4).
// Under independence the sample correlation r of n = 1.6·10⁶ pairs is ~N(0, 1/n); |r| < 4/√n has
// two-sided false-alarm probability 6.3e-5 per pair type, 2.5e-4 for the four (Bonferroni).
// A 32×32 χ² of the (pixel, pixel + 1) first-draw pairs also catches non-linear dependence
// (expected 195 per cell, dof 1023, significance 1e-3).
TEST(RngStreams, NeighboursAreUncorrelated) {
  const int m = 200000, draws = 8;
  const uint seed = 2024u;
  auto stream = [](uint s, uint pixel, uint sample, std::vector<double>* out) {
    rng_state r = rng_init(s, pixel, sample);
    for (int j = 0; j < draws + 1; ++j) out->push_back(rng_uniform(&r));
  };
  std::vector<double> base, nextPixel, nextSample, nextSeed;
  std::vector<double> x, yPixel, ySample, ySeed, xLag, yLag;
  std::vector<double> pairCounts(32 * 32, 0.0);
  for (int i = 0; i < m; ++i) {
    const uint pixel = static_cast<uint>(i) * 3u, sample = static_cast<uint>(i % 17);
    base.clear();
    nextPixel.clear();
    nextSample.clear();
    nextSeed.clear();
    stream(seed, pixel, sample, &base);
    stream(seed, pixel + 1u, sample, &nextPixel);
    stream(seed, pixel, sample + 1u, &nextSample);
    stream(seed + 1u, pixel, sample, &nextSeed);
    for (int j = 0; j < draws; ++j) {
      x.push_back(base[j]);
      yPixel.push_back(nextPixel[j]);
      ySample.push_back(nextSample[j]);
      ySeed.push_back(nextSeed[j]);
      xLag.push_back(base[j]);
      yLag.push_back(base[j + 1]);
    }
    pairCounts[static_cast<int>(base[0] * 32) * 32 + static_cast<int>(nextPixel[0] * 32)] += 1.0;
  }
  const double bound = 4.0 / std::sqrt(static_cast<double>(x.size()));
  const double rPixel = correlation(x, yPixel), rSample = correlation(x, ySample);
  const double rSeed = correlation(x, ySeed), rLag = correlation(xLag, yLag);
  EXPECT_LT(std::fabs(rPixel), bound) << "pixel neighbours";
  EXPECT_LT(std::fabs(rSample), bound) << "sample neighbours";
  EXPECT_LT(std::fabs(rSeed), bound) << "seed neighbours";
  EXPECT_LT(std::fabs(rLag), bound) << "consecutive draws";
  double chi2 = 0.0;
  const double p = equalCellsChiSquarePValue(pairCounts, &chi2);
  EXPECT_GE(p, 1e-3) << "chi2 = " << chi2;
  RecordProperty("correlations", std::to_string(rPixel) + " " + std::to_string(rSample) + " " +
                                     std::to_string(rSeed) + " " + std::to_string(rLag));
}

// Control for the test above: the bound is tight enough to see a weak real dependence. Pairs
// (x, y) with y = x for every 50th pair and independent otherwise have correlation 0.02, i.e. 25
// standard errors at n = 1.6·10⁶, far beyond 4/√n = 0.0032.
TEST(RngStreams, CorrelationBoundDetectsWeakDependence) {
  const int n = 1600000;
  rng_state a = rng_init(1u, 0u, 0u), b = rng_init(2u, 0u, 0u);
  std::vector<double> x(n), y(n);
  for (int i = 0; i < n; ++i) {
    x[i] = rng_uniform(&a);
    y[i] = (i % 50 == 0) ? x[i] : rng_uniform(&b);
  }
  EXPECT_GT(std::fabs(correlation(x, y)), 4.0 / std::sqrt(static_cast<double>(n)));
}

// Determinism: the same (seed, pixel, sample) gives the same sequence, bit for bit, however the
// streams are interleaved; changing any of the three changes it.
TEST(RngStreams, AreDeterministicAndDistinct) {
  auto draws = [](uint seed, uint pixel, uint sample) {
    rng_state r = rng_init(seed, pixel, sample);
    std::vector<uint> v;
    for (int i = 0; i < 64; ++i) v.push_back(rng_next_uint(&r));
    return v;
  };
  const std::vector<uint> ref = draws(5u, 1000u, 3u);
  EXPECT_EQ(draws(5u, 1000u, 3u), ref);
  // Interleaved with another stream: no hidden shared state.
  rng_state r1 = rng_init(5u, 1000u, 3u), r2 = rng_init(6u, 1u, 1u);
  for (int i = 0; i < 64; ++i) {
    (void)rng_next_uint(&r2);
    EXPECT_EQ(rng_next_uint(&r1), ref[i]) << i;
  }
  EXPECT_NE(draws(6u, 1000u, 3u), ref);
  EXPECT_NE(draws(5u, 1001u, 3u), ref);
  EXPECT_NE(draws(5u, 1000u, 4u), ref);
  // (pixel, sample) and (sample, pixel) are different streams: the counter words are not symmetric.
  EXPECT_NE(draws(5u, 3u, 1000u), ref);
}

}  // namespace
