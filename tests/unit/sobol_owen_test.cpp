// sobol_owen_test.cpp: the scrambled Sobol pairs of kernels/shared/sobol_owen.h on the host (the
// very code the device compiles): the net property every power-of-two prefix must keep, which is
// what the multiple-scattering cache's paths rely on (ms_cache_build.h), checked exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "shared/sobol_owen.h"

namespace {

// Unscrambled values against Sobol's own first points: dimension 0 is the van der Corput sequence
// 0, 1/2, 1/4, 3/4, 1/8, 5/8, 3/8, 7/8; dimension 1 xors the direction numbers v1 = 1/2, v2 = 3/4,
// v3 = 5/8 of the index's set bits: index 3 gives 1/2 xor 3/4 = 1/4, 5 gives 1/2 xor 5/8 = 1/8,
// 6 gives 3/4 xor 5/8 = 3/8, 7 gives 1/4 xor 5/8 = 7/8.
TEST(SobolOwen, UnscrambledFirstPoints) {
  const double d0[] = {0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
  const double d1[] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (uint32_t i = 0; i < 8; ++i) {
    EXPECT_EQ(sobol_owen_dim0(i) / 4294967296.0, d0[i]) << i;
    EXPECT_EQ(sobol_owen_dim1(i) / 4294967296.0, d1[i]) << i;
  }
}

// Owen scrambling permutes each digit by the digits above it: two values that share their top j
// digits still share them after scrambling (and the map is a bijection: no two inputs collide).
TEST(SobolOwen, ScrambleIsNestedAndBijective) {
  std::mt19937 gen(7);
  for (int trial = 0; trial < 2000; ++trial) {
    const uint32_t seed = gen(), a = gen(), b = gen();
    const int j = static_cast<int>(gen() % 33u);
    const uint32_t mask = j == 0 ? 0u : ~0u << (32 - j);  // the top j digits
    const uint32_t b_same_top = (a & mask) | (b & ~mask);
    EXPECT_EQ(sobol_owen_scramble(a, seed) & mask, sobol_owen_scramble(b_same_top, seed) & mask);
  }
  std::set<uint32_t> seen;
  for (uint32_t x = 0; x < 1u << 16; ++x) seen.insert(sobol_owen_scramble(x << 16, 0x9e3779b9u) >> 16);
  EXPECT_EQ(seen.size(), 1u << 16);
}

// The first 2^m points of any scrambled pair form a (0,m,2)-net: each of the 2^m elementary
// intervals of every shape 2^j × 2^{m−j} holds exactly one point (so every power-of-two prefix of a
// node's paths is stratified in each pair, whatever its seeds).
TEST(SobolOwen, EveryPowerOfTwoPrefixIsANet) {
  std::mt19937 gen(11);
  for (int trial = 0; trial < 20; ++trial) {
    const uint32_t si = gen(), sx = gen(), sy = gen();
    for (int m = 0; m <= 10; ++m) {
      const uint32_t n = 1u << m;
      std::vector<float> x(n), y(n);
      for (uint32_t k = 0; k < n; ++k) sobol_owen_2d(k, si, sx, sy, &x[k], &y[k]);
      for (int j = 0; j <= m; ++j) {
        std::vector<int> count(n, 0);
        for (uint32_t k = 0; k < n; ++k) {
          ASSERT_GE(x[k], 0.0f);
          ASSERT_LT(x[k], 1.0f);
          ASSERT_GE(y[k], 0.0f);
          ASSERT_LT(y[k], 1.0f);
          const auto cx = static_cast<uint32_t>(std::ldexp(x[k], j));
          const auto cy = static_cast<uint32_t>(std::ldexp(y[k], m - j));
          ++count[cx + (cy << j)];
        }
        for (uint32_t c = 0; c < n; ++c) ASSERT_EQ(count[c], 1) << "m " << m << " j " << j << " cell " << c;
      }
    }
  }
}

// Padding: two pairs drawn with the same index but different seeds are not copies of each other.
// Over the first 256 points the correlation of pair A's x with pair B's x is that of independent
// uniforms (standard deviation 1/√256 = 1/16 for the sample correlation): |r| < 4/16 at 4σ
// (two-sided, 6e-5 for a Gaussian).
TEST(SobolOwen, PairsWithOtherSeedsAreDecorrelated) {
  std::mt19937 gen(3);
  for (int trial = 0; trial < 5; ++trial) {
    uint32_t a[3], b[3];
    for (int i = 0; i < 3; ++i) a[i] = static_cast<uint32_t>(gen()), b[i] = static_cast<uint32_t>(gen());
    const int n = 256;
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    for (uint32_t k = 0; k < static_cast<uint32_t>(n); ++k) {
      float xa, ya, xb, yb;
      sobol_owen_2d(k, a[0], a[1], a[2], &xa, &ya);
      sobol_owen_2d(k, b[0], b[1], b[2], &xb, &yb);
      sa += xa;
      sb += xb;
      saa += xa * xa;
      sbb += xb * xb;
      sab += xa * xb;
    }
    const double cov = sab / n - (sa / n) * (sb / n);
    const double r = cov / std::sqrt((saa / n - sa * sa / n / n) * (sbb / n - sb * sb / n / n));
    EXPECT_LT(std::fabs(r), 0.25) << trial;
  }
}

// What the stratification buys, on an integrand like a cache path's: a smooth function of the pair,
// f(x, y) = e^{−3x}·(1 + y²), whose integral is (1 − e^{−3})/3 · 4/3. Over 64 scrambled point sets
// of 256 points the root-mean-square error is below a tenth of plain Monte Carlo's, whose standard
// deviation is σ_f/16 (σ_f² = E f² − (E f)², E f² = (1 − e^{−6})/6 · (1 + 2/3 + 1/5)).
TEST(SobolOwen, SmoothIntegrandConvergesFasterThanRandom) {
  const double ef = (1.0 - std::exp(-3.0)) / 3.0 * (4.0 / 3.0);
  const double ef2 = (1.0 - std::exp(-6.0)) / 6.0 * (1.0 + 2.0 / 3.0 + 1.0 / 5.0);
  const double mc_sd = std::sqrt(ef2 - ef * ef) / 16.0;
  std::mt19937 gen(5);
  double sq = 0.0;
  for (int set = 0; set < 64; ++set) {
    const uint32_t si = gen(), sx = gen(), sy = gen();
    double sum = 0.0;
    for (uint32_t k = 0; k < 256; ++k) {
      float x, y;
      sobol_owen_2d(k, si, sx, sy, &x, &y);
      sum += std::exp(-3.0 * x) * (1.0 + static_cast<double>(y) * y);
    }
    sq += (sum / 256 - ef) * (sum / 256 - ef);
  }
  EXPECT_LT(std::sqrt(sq / 64), 0.1 * mc_sd);
}

}  // namespace
