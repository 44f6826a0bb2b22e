// accumulator.h: the path tracer's per-pixel sums as the kernel keeps them (kernels/shared/accum.h:
// 128-bit fixed point per channel and a count of samples that could not be added), what an EXR
// stores for --resume and `narval merge`, and the arithmetic on them. Sums of disjoint sample
// ranges add exactly, so a render split any way and merged has the bits of one run.
#pragma once

#include <cstdint>
#include <vector>

#include "image/image.h"
#include "shared/accum.h"

namespace narval {

// The samples [begin, begin + samples) of every pixel, summed: ACCUM_WORDS uint64 words per pixel
// (accum.h), row 0 first.
struct AccumulatorState {
  int begin = 0;    // the first sample index
  int samples = 0;  // how many, from begin on
  uint32_t status = 0;  // STATUS_* bits met so far
  std::vector<uint64_t> words;
  int end() const { return begin + samples; }
};

// 64-bit words per pixel.
constexpr int kAccumulatorWords = ACCUM_WORDS;

// `into` += `part` pixel by pixel (128-bit integer sums with carry, and the counts of rejected
// samples), covering [into.begin, part.end()) afterwards; the caller checks that the ranges meet
// (part.begin == into.end()) and the sizes agree. Exact, so the order of the additions never matters.
void addAccumulator(AccumulatorState& into, const AccumulatorState& part);

// The mean of the samples: sum / samples per channel, rounded once through double; a pixel with a
// sample that could not be added (NaN, infinite, |x| ≥ 2^40) is NaN, counted into *nanPixels.
ImageRGB accumulatorImage(const AccumulatorState& acc, int width, int height, long long* nanPixels);

}  // namespace narval
