// The exact accumulator (kernels/shared/accum.h, render/accumulator.h): each sample rounds once to
// 128-bit fixed point, sums are integers, so any split and order of the same samples gives the same
// bits, and the mean is the exact one rounded once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "render/accumulator.h"
#include "shared/accum.h"

namespace narval {
namespace {

using int128 = __int128;

// The 128-bit value of (lo, hi), two's complement.
int128 value(uint64_t lo, uint64_t hi) { return int128((unsigned __int128)hi << 64 | lo); }

// An independent rounding of x·2^64 (frexp instead of the float's bits): x = m·2^e with m an
// integer of at most 24 bits, so x·2^64 = m·2^(e+64); below 2^0 it rounds half up on |x|.
int128 oracle(float x) {
  int e = 0;
  const double f = std::frexp(double(std::fabs(x)), &e);  // |x| = f·2^e, f in [0.5, 1)
  const int128 m = int128(std::ldexp(f, 24));              // exact: a float has 24 bits
  const int shift = e - 24 + 64;
  int128 v = 0;
  if (shift >= 0) v = m << shift;
  else if (shift > -120) v = (m + (int128(1) << (-shift - 1))) >> (-shift);
  return x < 0 ? -v : v;
}

TEST(AccumFixed, EachSampleIsRoundedOnceToTwoToTheMinus64) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
  std::uniform_int_distribution<int> exponent(-90, 39);  // |x| from below 2^-65 up to 2^39
  for (int i = 0; i < 200000; ++i) {
    const float x = std::ldexp(mantissa(rng), exponent(rng));
    uint64_t lo = 0, hi = 0;
    ASSERT_EQ(accum_fixed_add(&lo, &hi, x), 0) << x;
    ASSERT_TRUE(value(lo, hi) == oracle(x)) << "x = " << x;
  }
  // Exactly representable: 1 is 2^64 units, -0.5 is -2^63, 2^-64 one unit, 2^-66 rounds to 0.
  uint64_t lo = 0, hi = 0;
  accum_fixed_add(&lo, &hi, 1.0f);
  EXPECT_EQ(lo, 0u);
  EXPECT_EQ(hi, 1u);
  accum_fixed_add(&lo, &hi, -1.5f);
  EXPECT_TRUE(value(lo, hi) == -(int128(1) << 63));
  lo = hi = 0;
  accum_fixed_add(&lo, &hi, std::ldexp(1.0f, -64));
  EXPECT_EQ(lo, 1u);
  accum_fixed_add(&lo, &hi, std::ldexp(1.0f, -66));
  EXPECT_EQ(lo, 1u);
}

// x and -x cancel exactly, across the carry between the two words (lo wraps when 2^-64 units pass
// 2^64, i.e. at |x| = 1).
TEST(AccumFixed, OppositeSamplesCancelToZeroAcrossTheCarry) {
  uint64_t lo = 0, hi = 0;
  const float xs[] = {0.75f, 1.25f, 3.0e-7f, 12345.678f, 0.5f};
  for (float x : xs) accum_fixed_add(&lo, &hi, x);
  for (float x : xs) accum_fixed_add(&lo, &hi, -x);
  EXPECT_EQ(lo, 0u);
  EXPECT_EQ(hi, 0u);
}

// Out of range: NaN, ±inf and |x| ≥ 2^40 are not added and say so; the largest float below 2^40 is.
TEST(AccumFixed, NonFiniteAndOutOfRangeSamplesAreRejected) {
  uint64_t lo = 0, hi = 0;
  for (float x : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                  -std::numeric_limits<float>::infinity(), std::ldexp(1.0f, 40), -std::ldexp(1.0f, 40), 3.0e38f}) {
    EXPECT_EQ(accum_fixed_add(&lo, &hi, x), 1) << x;
    EXPECT_EQ(lo, 0u);
    EXPECT_EQ(hi, 0u);
  }
  const float largest = std::nextafter(std::ldexp(1.0f, 40), 0.0f);
  EXPECT_EQ(accum_fixed_add(&lo, &hi, largest), 0);
  EXPECT_TRUE(value(lo, hi) == int128(largest) << 64);

  uint64_t words[ACCUM_WORDS] = {};
  accum_add_sample(words, vec3_make(1.0f, std::numeric_limits<float>::quiet_NaN(), 2.0f));
  accum_add_sample(words, vec3_make(1.0f, 1.0f, 1.0f));
  EXPECT_EQ(words[ACCUM_REJECTED_WORD], 1u);
  AccumulatorState acc;
  acc.samples = 2;
  acc.words.assign(words, words + ACCUM_WORDS);
  long long nan = 0;
  const ImageRGB img = accumulatorImage(acc, 1, 1, &nan);
  EXPECT_EQ(nan, 1);
  EXPECT_TRUE(std::isnan(img.rgb[0]) && std::isnan(img.rgb[1]) && std::isnan(img.rgb[2]));
}

// One pixel's 20000 samples (heavy-tailed, both signs, 2^-70 to 2^30) summed in one run, in three
// uneven parts added afterwards, and in reverse order: the same 128 bits, which are the exact sum
// of the rounded samples. The mean is that sum over N rounded once: within half an ulp of the
// double mean of the samples, since each rounding moves a sample by at most 2^-65.
TEST(AccumFixed, AnySplitAndOrderOfTheSamplesGivesTheSameBits) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<vec3> samples;
  for (int i = 0; i < 20000; ++i) {
    const float heavy = std::ldexp(1.0f, int(u(rng) * 100.0f) - 70);
    samples.push_back(vec3_make(heavy * (u(rng) < 0.1f ? -1.0f : 1.0f), u(rng), 1.0f / (1e-3f + u(rng))));
  }
  auto sum = [&](size_t a, size_t b, bool reverse) {
    AccumulatorState s;
    s.begin = int(a);
    s.samples = int(b - a);
    s.words.assign(ACCUM_WORDS, 0);
    for (size_t k = 0; k < b - a; ++k) accum_add_sample(s.words.data(), samples[reverse ? b - 1 - k : a + k]);
    return s;
  };
  const AccumulatorState whole = sum(0, samples.size(), false);
  AccumulatorState parts = sum(0, 7, false);
  addAccumulator(parts, sum(7, 12345, true));
  addAccumulator(parts, sum(12345, samples.size(), false));
  EXPECT_EQ(parts.samples, whole.samples);
  EXPECT_EQ(parts.words, whole.words);
  EXPECT_EQ(sum(0, samples.size(), true).words, whole.words);

  int128 exact[3] = {0, 0, 0};
  double mean[3] = {0, 0, 0};
  for (const vec3& s : samples) {
    const float c[3] = {s.x, s.y, s.z};
    for (int k = 0; k < 3; ++k) {
      exact[k] += oracle(c[k]);
      mean[k] += double(c[k]) / double(samples.size());
    }
  }
  long long nan = 0;
  const ImageRGB img = accumulatorImage(whole, 1, 1, &nan);
  EXPECT_EQ(nan, 0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(value(whole.words[2 * k], whole.words[2 * k + 1]) == exact[k]) << "channel " << k;
    EXPECT_NEAR(img.rgb[k], mean[k], std::fabs(mean[k]) * 1e-6 + 1e-12) << "channel " << k;
  }
}

// 10^6 copies of 0.1f: float summation drifts by 1% (each addition near 1e5 rounds 0.1 to a
// multiple of 2^-7); the exact sum's mean is 0.1f itself.
TEST(AccumFixed, AMillionTenthsAverageToExactlyATenth) {
  uint64_t words[ACCUM_WORDS] = {};
  float naive = 0.0f;
  for (int i = 0; i < 1000000; ++i) {
    accum_add_sample(words, vec3_make(0.1f, 0.1f, 0.1f));
    naive += 0.1f;
  }
  AccumulatorState acc;
  acc.samples = 1000000;
  acc.words.assign(words, words + ACCUM_WORDS);
  long long nan = 0;
  const ImageRGB img = accumulatorImage(acc, 1, 1, &nan);
  EXPECT_EQ(img.rgb[0], 0.1f);
  EXPECT_GT(std::fabs(naive / 1e6f - 0.1f) / 0.1f, 1e-3) << "naive float summation should drift: " << naive;
}

}  // namespace
}  // namespace narval
