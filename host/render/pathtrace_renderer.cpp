#include "render/pathtrace_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "render/device_scene.h"
#include "render/render_common.h"

namespace narval {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int pathtraceSamplesPerPass(int width, int height, int spp) {
  const long long pixels = std::max(1LL, (long long)width * height);
  const long long perPass = std::max(1LL, (1LL << 20) / pixels);
  return int(std::min<long long>(perPass, std::max(1, spp)));
}

RenderResult renderPathtrace(ClRuntime& rt, const Scene& scene, const DenseGrid* grid,
                             const RenderOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const int W = scene.renderer.width, H = scene.renderer.height, spp = scene.renderer.spp;
  const DeviceSceneBuffers dev(rt, scene, grid);

  RenderResult result;
  result.warnings = dev.scene.warnings;
  result.stats = initialStats("pathtrace", rt, scene);
  RenderStats& st = result.stats;

  cl::Program program = buildProgram(rt, "pathtrace.cl", dev.scene.buildOptions, nullptr, &st.programFromCache);
  cl::Kernel kernel(program, "pathtrace");

  const size_t pixels = size_t(W) * size_t(H);
  cl::Buffer sumBuf(rt.context, CL_MEM_READ_WRITE, pixels * 4 * sizeof(float));
  cl::Buffer compBuf(rt.context, CL_MEM_READ_WRITE, pixels * 4 * sizeof(float));
  cl::Buffer statusBuf(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
  rt.queue.enqueueFillBuffer(sumBuf, 0.0f, 0, pixels * 4 * sizeof(float));
  rt.queue.enqueueFillBuffer(compBuf, 0.0f, 0, pixels * 4 * sizeof(float));
  rt.queue.enqueueFillBuffer(statusBuf, cl_uint(0), 0, sizeof(cl_uint));
  dev.bind(kernel);
  const cl_uint arg = DeviceSceneBuffers::kFirstFreeArg;
  kernel.setArg(arg + 0, sumBuf);
  kernel.setArg(arg + 1, compBuf);
  kernel.setArg(arg + 4, statusBuf);
  rt.queue.finish();
  st.buildSeconds = secondsSince(t0);

  const cl::NDRange global = paddedGlobalRange(W, H, options), local = localRange(options);
  const int perPass = options.samplesPerPass > 0 ? options.samplesPerPass : pathtraceSamplesPerPass(W, H, spp);
  std::vector<double> kernelMs, wallMs;  // per pass: with one sample per pass, per frame
  const auto tLoop = std::chrono::steady_clock::now();
  for (int done = 0; done < spp;) {
    const int count = std::min(perPass, spp - done);
    kernel.setArg(arg + 2, cl_uint(done));
    kernel.setArg(arg + 3, cl_uint(count));
    const auto tPass = std::chrono::steady_clock::now();
    cl::Event ev;
    rt.queue.enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &ev);
    ev.wait();
    wallMs.push_back(secondsSince(tPass) * 1e3);
    kernelMs.push_back(eventSeconds(ev) * 1e3);
    st.kernelSeconds += kernelMs.back() * 1e-3;
    done += count;
    ++st.passes;
    if (options.progress) options.progress(done, spp);
  }
  std::vector<float> sums(pixels * 4);
  rt.queue.enqueueReadBuffer(sumBuf, CL_TRUE, 0, sums.size() * sizeof(float), sums.data());
  rt.queue.enqueueReadBuffer(statusBuf, CL_TRUE, 0, sizeof(cl_uint), &st.status);
  st.seconds = secondsSince(tLoop);
  st.frames = frameTimings(kernelMs, wallMs);
  st.samplesPerSecond = st.seconds > 0 ? double(pixels) * spp / st.seconds : 0.0;

  result.image = imageFromRgba(sums, W, H, float(spp), &st.nanPixels);
  return result;
}

}  // namespace narval
