#include "render/pathtrace_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "render/device_allocation.h"
#include "render/device_scene.h"
#include "render/majorant_options.h"
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
  checkMajorantOptions(options);
  DeviceSceneBuffers dev(rt, scene, grid);
  const size_t pixels = size_t(W) * size_t(H), accumBytes = pixels * 4 * sizeof(float);
  const AccumulatorState* resume = options.resumeFrom;
  if (resume && (resume->sum.size() != pixels * 4 || resume->comp.size() != pixels * 4 || resume->samples > spp))
    throw std::invalid_argument("renderPathtrace: the state to resume from does not fit this render");

  RenderResult result;
  result.warnings = dev.scene.warnings;
  result.stats = initialStats("pathtrace", rt, scene);
  RenderStats& st = result.stats;
  recordGridStorage(st, dev);
  st.majorant = resolveMajorant(options.majorant, rt.selected.info);
  st.counters = options.counters;
  applyMajorantResolution(rt, dev,
                          options.majorantResolution > 0 ? options.majorantResolution
                                                         : pathtraceMajorantResolution(rt.selected.info),
                          st);

  cl::Program program = buildProgram(
      rt, "pathtrace.cl",
      joinBuildOptions(dev.scene.buildOptions, pathtraceMajorantBuildOptions(st.majorant, options.counters)), nullptr,
      &st.programFromCache);
  cl::Kernel kernel(program, "pathtrace");

  const AllocationSite site{scene.sourcePath, "renderer.resolution",
                            "an accumulator of " + std::to_string(W) + "x" + std::to_string(H) + " RGBA floats"};
  cl::Buffer sumBuf = allocateBuffer(rt, CL_MEM_READ_WRITE, accumBytes, site);
  cl::Buffer compBuf = allocateBuffer(rt, CL_MEM_READ_WRITE, accumBytes, site);
  cl::Buffer statusBuf(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
  if (resume) {
    rt.queue.enqueueWriteBuffer(sumBuf, CL_FALSE, 0, accumBytes, resume->sum.data());
    rt.queue.enqueueWriteBuffer(compBuf, CL_FALSE, 0, accumBytes, resume->comp.data());
  } else {
    rt.queue.enqueueFillBuffer(sumBuf, 0.0f, 0, accumBytes);
    rt.queue.enqueueFillBuffer(compBuf, 0.0f, 0, accumBytes);
  }
  rt.queue.enqueueFillBuffer(statusBuf, cl_uint(resume ? resume->status : 0u), 0, sizeof(cl_uint));
  dev.bind(kernel);
  const cl_uint arg = DeviceSceneBuffers::kFirstFreeArg;
  kernel.setArg(arg + 0, sumBuf);
  kernel.setArg(arg + 1, compBuf);
  kernel.setArg(arg + 4, statusBuf);
  // -DCOUNTERS: three ulongs per pixel, each work-item adding to its own (pathtrace.cl).
  const size_t counterBytes = options.counters ? pixels * 3 * sizeof(cl_ulong) : 0;
  cl::Buffer counterBuf;
  if (options.counters) {
    counterBuf = allocateBuffer(rt, CL_MEM_READ_WRITE, counterBytes,
                                {scene.sourcePath, "renderer.resolution",
                                 "collision counters of " + std::to_string(W) + "x" + std::to_string(H) + " pixels"});
    rt.queue.enqueueFillBuffer(counterBuf, cl_ulong(0), 0, counterBytes);
    kernel.setArg(arg + 5, counterBuf);
  }
  rt.queue.finish();
  st.buildSeconds = secondsSince(t0);

  const cl::NDRange global = paddedGlobalRange(W, H, options), local = localRange(options);
  const size_t deviceBytes = deviceSceneBytes(dev.scene) + 2 * accumBytes + counterBytes;
  const int perPass = options.samplesPerPass > 0 ? options.samplesPerPass : pathtraceSamplesPerPass(W, H, spp);
  const int first = resume ? resume->samples : 0;
  std::vector<double> kernelMs, wallMs;  // per pass: with one sample per pass, per frame
  const auto tLoop = std::chrono::steady_clock::now();
  int done = first;
  // The accumulator after `done` samples into `into` (what the kernel has added: the image, the
  // state --resume continues from, the status bits and the sample counts).
  auto readBack = [&](RenderResult& into) {
    AccumulatorState& acc = into.accumulator;
    acc.samples = done;
    acc.sum.resize(pixels * 4);
    acc.comp.resize(pixels * 4);
    rt.queue.enqueueReadBuffer(sumBuf, CL_TRUE, 0, accumBytes, acc.sum.data());
    rt.queue.enqueueReadBuffer(compBuf, CL_TRUE, 0, accumBytes, acc.comp.data());
    rt.queue.enqueueReadBuffer(statusBuf, CL_TRUE, 0, sizeof(cl_uint), &into.stats.status);
    acc.status = into.stats.status;
    into.stats.spp = done;
    into.stats.sppRequested = spp;
    into.stats.resumedFromSpp = first;
    into.stats.interrupted = done < spp;
    if (done > 0) into.image = imageFromRgba(acc.sum, W, H, float(done), &into.stats.nanPixels);
  };
  // Samples [done, done + count) per pass; the kernel adds them in index order, so any split of
  // the same samples (passes, interruption and --resume) gives the same bits.
  while (done < spp && !cancelled(options)) {
    const int count = std::min(perPass, spp - done);
    kernel.setArg(arg + 2, cl_uint(done));
    kernel.setArg(arg + 3, cl_uint(count));
    const auto tPass = std::chrono::steady_clock::now();
    const cl::Event ev = launchAndWait(rt, kernel, global, local, "pathtrace", deviceBytes);
    wallMs.push_back(secondsSince(tPass) * 1e3);
    kernelMs.push_back(eventSeconds(ev) * 1e3);
    st.kernelSeconds += kernelMs.back() * 1e-3;
    done += count;
    ++st.passes;
    if (options.progress) options.progress(done, spp);
    if (done < spp && options.snapshot && options.snapshotDue && options.snapshotDue()) {
      RenderResult partial;
      partial.stats = st;
      readBack(partial);
      options.snapshot(partial);
    }
  }
  readBack(result);
  if (options.counters) {
    std::vector<cl_ulong> counts(pixels * 3);
    rt.queue.enqueueReadBuffer(counterBuf, CL_TRUE, 0, counterBytes, counts.data());
    for (size_t i = 0; i < pixels; ++i) {
      st.collisionsTentative += counts[3 * i + 0];
      st.collisionsReal += counts[3 * i + 1];
      st.densityLookups += counts[3 * i + 2];
    }
  }
  st.seconds = secondsSince(tLoop);
  st.frames = frameTimings(kernelMs, wallMs);
  st.samplesPerSecond = st.seconds > 0 ? double(pixels) * (done - first) / st.seconds : 0.0;
  return result;
}

}  // namespace narval
