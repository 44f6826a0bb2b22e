#include "render/render_common.h"

#include <algorithm>
#include <cmath>

namespace narval {

RenderStats initialStats(const std::string& algorithm, const ClRuntime& rt, const Scene& scene) {
  RenderStats st;
  st.algorithm = algorithm;
  st.device = rt.selected.info.name;
  st.width = scene.renderer.width;
  st.height = scene.renderer.height;
  st.spp = scene.renderer.spp;
  st.bounces = scene.renderer.bounces;
  return st;
}

cl::NDRange localRange(const RenderOptions& o) {
  return cl::NDRange(size_t(std::max(1, o.localSizeX)), size_t(std::max(1, o.localSizeY)));
}

cl::NDRange paddedGlobalRange(int width, int height, const RenderOptions& o) {
  const size_t lx = size_t(std::max(1, o.localSizeX)), ly = size_t(std::max(1, o.localSizeY));
  return cl::NDRange((size_t(width) + lx - 1) / lx * lx, (size_t(height) + ly - 1) / ly * ly);
}

ImageRGB imageFromRgba(const std::vector<float>& rgba, int width, int height, float divisor, long long* nanPixels) {
  ImageRGB img;
  img.width = width;
  img.height = height;
  const size_t pixels = size_t(width) * size_t(height);
  img.rgb.resize(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
      img.rgb[i * 3 + c] = rgba[i * 4 + c] / divisor;
      finite = finite && std::isfinite(img.rgb[i * 3 + c]);
    }
    *nanPixels += finite ? 0 : 1;
  }
  return img;
}

namespace {
// Median, min and max of v (v non-empty); the median of an even count is the mean of the middle two.
void summarize(std::vector<double> v, double* median, double* lo, double* hi) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  *median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  *lo = v.front();
  *hi = v.back();
}
}  // namespace

FrameTimings frameTimings(const std::vector<double>& kernelMs, const std::vector<double>& wallMs) {
  FrameTimings t;
  t.count = int(kernelMs.size());
  if (kernelMs.empty()) return t;
  t.firstKernelMs = kernelMs.front();
  t.firstWallMs = wallMs.front();
  const size_t skip = kernelMs.size() > 1 ? 1 : 0;
  summarize({kernelMs.begin() + skip, kernelMs.end()}, &t.medianKernelMs, &t.minKernelMs, &t.maxKernelMs);
  summarize({wallMs.begin() + skip, wallMs.end()}, &t.medianWallMs, &t.minWallMs, &t.maxWallMs);
  return t;
}

double eventSeconds(const cl::Event& e) {
  return double(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() - e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
         1e-9;
}

}  // namespace narval
