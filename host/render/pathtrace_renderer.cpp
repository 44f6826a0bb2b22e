#include "render/pathtrace_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "render/device_grid.h"
#include "render/scene_upload.h"

namespace narval {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

size_t roundUp(size_t n, size_t m) { return (n + m - 1) / m * m; }

}  // namespace

int pathtraceSamplesPerPass(int width, int height, int spp) {
  const long long pixels = std::max(1LL, (long long)width * height);
  const long long perPass = std::max(1LL, (1LL << 20) / pixels);
  return int(std::min<long long>(perPass, std::max(1, spp)));
}

RenderResult renderPathtrace(ClRuntime& rt, const Scene& scene, const DenseGrid* grid,
                             const RenderOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const DeviceScene ds = buildDeviceScene(scene, grid);
  const int W = scene.renderer.width, H = scene.renderer.height, spp = scene.renderer.spp;

  RenderResult result;
  result.warnings = ds.warnings;
  RenderStats& st = result.stats;
  st.algorithm = "pathtrace";
  st.device = rt.selected.info.name;
  st.width = W;
  st.height = H;
  st.spp = spp;
  st.bounces = scene.renderer.bounces;

  cl::Program program = buildProgram(rt, "pathtrace.cl", ds.buildOptions, nullptr, &st.programFromCache);
  cl::Kernel kernel(program, "pathtrace");

  const size_t pixels = size_t(W) * size_t(H);
  cl::Buffer sceneBuf(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(scene_params),
                      const_cast<scene_params*>(&ds.params));
  cl::Buffer lightBuf(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(light_params) * ds.lights.size(),
                      const_cast<light_params*>(ds.lights.data()));
  cl::Buffer sumBuf(rt.context, CL_MEM_READ_WRITE, pixels * 4 * sizeof(float));
  cl::Buffer compBuf(rt.context, CL_MEM_READ_WRITE, pixels * 4 * sizeof(float));
  cl::Buffer statusBuf(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
  rt.queue.enqueueFillBuffer(sumBuf, 0.0f, 0, pixels * 4 * sizeof(float));
  rt.queue.enqueueFillBuffer(compBuf, 0.0f, 0, pixels * 4 * sizeof(float));
  rt.queue.enqueueFillBuffer(statusBuf, cl_uint(0), 0, sizeof(cl_uint));

  kernel.setArg(0, sceneBuf);
  kernel.setArg(1, lightBuf);
  cl::Image3D gridImage;
  if (ds.grid) {
    gridImage = uploadGrid(rt, *ds.grid);
    kernel.setArg(2, gridImage);
  } else {
    kernel.setArg(2, cl_int(0));
  }
  kernel.setArg(3, sumBuf);
  kernel.setArg(4, compBuf);
  kernel.setArg(7, statusBuf);
  rt.queue.finish();
  st.buildSeconds = secondsSince(t0);

  // OpenCL 1.2 wants the global size to be a multiple of the local size: pad, the kernel guards.
  const size_t lx = size_t(std::max(1, options.localSizeX)), ly = size_t(std::max(1, options.localSizeY));
  const cl::NDRange global(roundUp(size_t(W), lx), roundUp(size_t(H), ly)), local(lx, ly);
  const int perPass = pathtraceSamplesPerPass(W, H, spp);
  const auto tLoop = std::chrono::steady_clock::now();
  for (int done = 0; done < spp;) {
    const int count = std::min(perPass, spp - done);
    kernel.setArg(5, cl_uint(done));
    kernel.setArg(6, cl_uint(count));
    cl::Event ev;
    rt.queue.enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &ev);
    ev.wait();
    st.kernelSeconds += double(ev.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                               ev.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-9;
    done += count;
    ++st.passes;
    if (options.progress) options.progress(done, spp);
  }
  std::vector<float> sums(pixels * 4);
  rt.queue.enqueueReadBuffer(sumBuf, CL_TRUE, 0, sums.size() * sizeof(float), sums.data());
  rt.queue.enqueueReadBuffer(statusBuf, CL_TRUE, 0, sizeof(cl_uint), &st.status);
  st.seconds = secondsSince(tLoop);
  st.samplesPerSecond = st.seconds > 0 ? double(pixels) * spp / st.seconds : 0.0;

  ImageRGB& img = result.image;
  img.width = W;
  img.height = H;
  img.rgb.resize(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
      img.rgb[i * 3 + c] = sums[i * 4 + c] / float(spp);
      finite = finite && std::isfinite(img.rgb[i * 3 + c]);
    }
    st.nanPixels += finite ? 0 : 1;
  }
  return result;
}

}  // namespace narval
