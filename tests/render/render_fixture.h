// render_fixture.h: helpers for rendering small analytic scenes on the default OpenCL device.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "cl/cl_runtime.h"
#include "render/pathtrace_renderer.h"
#include "scene/scene.h"
#include "unit/stat_util.h"

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

// Mean and standard error of the image mean for channel c (pixels as independent samples).
struct ChannelStats {
  double mean = 0, stderrOfMean = 0;
};
inline ChannelStats channelStats(const ImageRGB& img, int c) {
  MeanAccumulator acc;
  for (size_t i = 0, n = size_t(img.width) * img.height; i < n; ++i) acc.add(img.rgb[i * 3 + c]);
  const MeanSe r = acc.result();
  ChannelStats st;
  st.mean = r.mean;
  st.stderrOfMean = r.se;
  return st;
}

}  // namespace narval::test
