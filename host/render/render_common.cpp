#include "render/render_common.h"

#include <algorithm>
#include <cmath>

#include "cl/device_allocation.h"
#include "render/device_grid.h"

namespace narval {

RenderStats initialStats(const std::string& algorithm, const ClRuntime& rt, const Scene& scene) {
  RenderStats st;
  st.algorithm = algorithm;
  st.device = rt.selected.info.name;
  st.width = scene.renderer.width;
  st.height = scene.renderer.height;
  st.spp = st.sppRequested = scene.renderer.spp;
  st.bounces = scene.renderer.bounces;
  st.storage = gridStorageName(resolveGridStorage(scene.renderer.storage, rt.selected.info));
  return st;
}

void recordGridStorage(RenderStats& st, const DeviceSceneBuffers& dev) {
  st.storage = gridStorageName(dev.storage);
  st.gridBytes = dev.scene.grid ? dev.scene.gridBytes : 0;
  st.bricks = dev.bricks;
  st.bricksOccupied = dev.bricksOccupied;
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

size_t deviceSceneBytes(const DeviceScene& scene) {
  return sizeof(scene_params) + scene.lights.size() * sizeof(light_params) + scene.majorants.size() * sizeof(float) +
         (!scene.grid ? 0 : scene.gridBytes ? scene.gridBytes : scene.grid->voxelCount() * sizeof(float));
}

cl::Event launchAndWait(ClRuntime& rt, const cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local,
                        const std::string& what, size_t deviceBytes) {
  cl::Event ev;
  try {
    rt.queue.enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &ev);
    ev.wait();
  } catch (const cl::Error& e) {
    // A launch that failed while running reports its own error as the event's (negative) status.
    cl_int status = 0;
    if (e.err() == CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST &&
        ev.getInfo(CL_EVENT_COMMAND_EXECUTION_STATUS, &status) == CL_SUCCESS && status < 0)
      rethrowLaunchError(cl::Error(status, "kernel execution"), rt.selected.info, what, deviceBytes);
    rethrowLaunchError(e, rt.selected.info, what, deviceBytes);
  }
  return ev;
}

std::vector<std::string> statusWarnings(uint32_t status) {
  std::vector<std::string> w;
  if (status & STATUS_NAN) w.push_back("the kernel produced non-finite samples (dropped)");
  if (status & STATUS_NEGATIVE_PDF) w.push_back("the kernel met a non-positive pdf");
  if (status & STATUS_ITERATION_CAP) w.push_back("a loop hit its iteration cap (tracking walk or majorant DDA)");
  if (status & STATUS_UNKNOWN_KIND)
    w.push_back("a phase function or light kind the kernels do not know reached them (it sent no light)");
  return w;
}

bool cancelled(const RenderOptions& options) { return options.cancel && options.cancel->load(); }

}  // namespace narval
