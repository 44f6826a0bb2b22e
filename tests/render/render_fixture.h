// render_fixture.h: helpers for rendering small analytic scenes on the default OpenCL device.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "cl/cl_runtime.h"
#include "render/pathtrace_renderer.h"
#include "scene/scene.h"

namespace narval::test {

// One runtime for the whole test binary: building contexts is slow on PoCL.
inline ClRuntime& runtime() {
  static std::unique_ptr<ClRuntime> rt = std::make_unique<ClRuntime>("");
  return *rt;
}

inline Scene sceneFromJson(const std::string& json) { return parseScene(json, "test_scene.json"); }

inline RenderResult render(const Scene& scene, const DenseGrid* grid = nullptr, int lx = 8, int ly = 8) {
  RenderOptions o;
  o.localSizeX = lx;
  o.localSizeY = ly;
  return renderPathtrace(runtime(), scene, grid, o);
}

// Mean and standard error of the image mean for channel c.
struct ChannelStats {
  double mean = 0, stderrOfMean = 0;
};
inline ChannelStats channelStats(const ImageRGB& img, int c) {
  const size_t n = size_t(img.width) * img.height;
  double s = 0, s2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double v = img.rgb[i * 3 + c];
    s += v;
    s2 += v * v;
  }
  ChannelStats st;
  st.mean = s / n;
  st.stderrOfMean = std::sqrt(std::max(0.0, s2 / n - st.mean * st.mean) / (n - 1));
  return st;
}

}  // namespace narval::test
