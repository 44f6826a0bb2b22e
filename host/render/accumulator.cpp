#include "render/accumulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace narval {

void addAccumulator(AccumulatorState& into, const AccumulatorState& part) {
  if (into.words.size() != part.words.size())
    throw std::invalid_argument("addAccumulator: the accumulators have different sizes");
  for (size_t p = 0; p < into.words.size(); p += kAccumulatorWords) {
    uint64_t* a = &into.words[p];
    const uint64_t* b = &part.words[p];
    for (int c = 0; c < 3; ++c) {
      const uint64_t lo = a[2 * c] + b[2 * c];
      a[2 * c + 1] += b[2 * c + 1] + (lo < b[2 * c] ? 1u : 0u);
      a[2 * c] = lo;
    }
    a[ACCUM_REJECTED_WORD] += b[ACCUM_REJECTED_WORD];
  }
  into.samples += part.samples;
  into.status |= part.status;
}

ImageRGB accumulatorImage(const AccumulatorState& acc, int width, int height, long long* nanPixels) {
  ImageRGB img;
  img.width = width;
  img.height = height;
  const size_t pixels = size_t(width) * size_t(height);
  if (acc.words.size() != pixels * kAccumulatorWords)
    throw std::invalid_argument("accumulatorImage: the accumulator does not fit the image size");
  img.rgb.resize(pixels * 3);
  const double n = double(std::max(1, acc.samples));
  for (size_t i = 0; i < pixels; ++i) {
    const uint64_t* w = &acc.words[i * kAccumulatorWords];
    const bool rejected = w[ACCUM_REJECTED_WORD] != 0;
    for (int c = 0; c < 3; ++c) {
      // value = hi + lo·2^-64 with hi signed (two's complement across the pair).
      const double sum = double(int64_t(w[2 * c + 1])) + std::ldexp(double(w[2 * c]), -64);
      img.rgb[i * 3 + c] = rejected ? std::numeric_limits<float>::quiet_NaN() : float(sum / n);
    }
    *nanPixels += rejected ? 1 : 0;
  }
  return img;
}

}  // namespace narval
