// exr_bits.h: bit-for-bit comparison of EXR channels as stored: R, G and B as 32-bit floats, the
// path tracer's accumulator channels (accum.*) and the medium mask (medium) as 32-bit unsigned ints
// (render/render_exr.h, render/medium_mask.h).
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "image/image.h"

namespace narval::test {

// The path tracer's accumulator channels (render_exr.cpp).
inline std::vector<std::string> accumulatorChannels() {
  std::vector<std::string> names;
  for (const char* c : {"R", "G", "B"})
    for (int w = 0; w < 4; ++w) names.push_back(std::string("accum.") + c + ".w" + std::to_string(w));
  names.push_back("accum.rejected");
  return names;
}

// How many values of channel `name` differ between the EXRs `a` and `b` in their stored bits
// (-1 when the sizes differ).
inline long long differingValues(const std::string& a, const std::string& b, const std::string& name) {
  auto count = [](const auto& x, const auto& y) -> long long {
    if (x.size() != y.size()) return -1;
    long long n = 0;
    for (size_t k = 0; k < x.size(); ++k) n += std::memcmp(&x[k], &y[k], sizeof x[k]) != 0;
    return n;
  };
  if (name.rfind("accum.", 0) == 0 || name == "medium")
    return count(readExrUintChannels(a, {name}).at(0).values, readExrUintChannels(b, {name}).at(0).values);
  return count(readExrChannels(a, {name}).at(0).values, readExrChannels(b, {name}).at(0).values);
}

// Every channel in `names` (default: R, G, B, the accumulator and the medium mask) equal bit for bit.
inline void expectSameBits(const std::string& a, const std::string& b, std::vector<std::string> names = {}) {
  if (names.empty()) {
    names = accumulatorChannels();
    names.insert(names.begin(), {"R", "G", "B"});
    names.push_back("medium");
  }
  for (const std::string& n : names) EXPECT_EQ(differingValues(a, b, n), 0) << a << " and " << b << ": channel " << n;
}

}  // namespace narval::test
