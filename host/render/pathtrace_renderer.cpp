#include "render/pathtrace_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "cl/device_allocation.h"
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

PathtraceRenderer::PathtraceRenderer(ClRuntime& rt, const Scene& scene, SceneGrids grid,
                                     const RenderOptions& options)
    : rt_(rt), view_(scene), options_(options), dev_(rt, scene, grid), begin_(options.sampleBegin) {
  checkMajorantOptions(options);
  const int W = scene.renderer.width, H = scene.renderer.height;
  const AccumulatorState* resume = options.resumeFrom;
  const size_t pixels = size_t(W) * size_t(H);
  if (resume && (resume->words.size() != pixels * kAccumulatorWords || resume->samples > scene.renderer.spp ||
                 resume->begin != options.sampleBegin))
    throw std::invalid_argument("renderPathtrace: the state to resume from does not fit this render");
  warnings_ = dev_.scene.warnings;
  stats_ = initialStats("pathtrace", rt, scene);
  recordGridStorage(stats_, dev_);
  stats_.majorant = resolveMajorant(options.majorant, rt.selected.info);
  stats_.counters.on = options.counters;
  applyMajorantResolution(rt, dev_,
                          options.majorantResolution > 0 ? options.majorantResolution
                                                         : pathtraceMajorantResolution(rt.selected.info),
                          stats_);
  program_ = buildProgram(
      rt, "pathtrace.cl",
      dev_.buildOptions(stats_.majorant, options.counters),
      nullptr, &stats_.programFromCache);
  kernel_ = NamedKernel(program_, "pathtrace");
  statusBuf_ = cl::Buffer(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
  dev_.bind(kernel_);
  allocateAccumulator();
  if (resume) {
    rt.queue.enqueueWriteBuffer(accumBuf_, CL_FALSE, 0, accumulatorBytes(), resume->words.data());
    rt.queue.enqueueFillBuffer(statusBuf_, cl_uint(resume->status), 0, sizeof(cl_uint));
    first_ = done_ = resume->samples;
  }
  rt.queue.finish();
}

size_t PathtraceRenderer::accumulatorBytes() const {
  return size_t(view_.renderer.width) * size_t(view_.renderer.height) * kAccumulatorWords * sizeof(cl_ulong);
}

void PathtraceRenderer::allocateAccumulator() {
  const int W = view_.renderer.width, H = view_.renderer.height;
  const size_t pixels = size_t(W) * size_t(H);
  const AllocationSite site{view_.sourcePath, "renderer.resolution",
                            "an accumulator of " + std::to_string(W) + "x" + std::to_string(H) + " pixels"};
  if (accumBuf_() == nullptr || accumBuf_.getInfo<CL_MEM_SIZE>() != accumulatorBytes()) {
    accumBuf_ = allocateBuffer(rt_, CL_MEM_READ_WRITE, accumulatorBytes(), site);
    kernel_.set("accum", accumBuf_);
    kernel_.set("status_word", statusBuf_);
    // -DCOUNTERS: three ulongs per pixel, each work-item adding to its own (pathtrace.cl).
    if (options_.counters) {
      counterBuf_ = allocateBuffer(rt_, CL_MEM_READ_WRITE, pixels * 3 * sizeof(cl_ulong),
                                   {view_.sourcePath, "renderer.resolution",
                                    "collision counters of " + std::to_string(W) + "x" + std::to_string(H) +
                                        " pixels"});
      kernel_.set("counter_buf", counterBuf_);
    }
  }
  reset();
}

void PathtraceRenderer::reset() {
  const size_t pixels = size_t(view_.renderer.width) * size_t(view_.renderer.height);
  rt_.queue.enqueueFillBuffer(accumBuf_, cl_ulong(0), 0, accumulatorBytes());
  rt_.queue.enqueueFillBuffer(statusBuf_, cl_uint(0), 0, sizeof(cl_uint));
  if (options_.counters) rt_.queue.enqueueFillBuffer(counterBuf_, cl_ulong(0), 0, pixels * 3 * sizeof(cl_ulong));
  first_ = done_ = 0;
}

void PathtraceRenderer::setView(const Scene& view) {
  const bool resized = view.renderer.width != view_.renderer.width || view.renderer.height != view_.renderer.height;
  dev_.scene.params.camera = buildCamera(view);
  rt_.queue.enqueueWriteBuffer(dev_.sceneBuf, CL_TRUE, 0, sizeof(scene_params), &dev_.scene.params);
  view_ = view;
  stats_.width = view.renderer.width;
  stats_.height = view.renderer.height;
  if (resized)
    allocateAccumulator();
  else
    reset();
}

double PathtraceRenderer::addSamples(int count) {
  const int W = view_.renderer.width, H = view_.renderer.height;
  const size_t pixels = size_t(W) * size_t(H);
  const size_t deviceBytes = deviceSceneBytes(dev_.scene) + accumulatorBytes() +
                             (options_.counters ? pixels * 3 * sizeof(cl_ulong) : 0);
  kernel_.set("sample_begin", cl_uint(begin_ + done_));
  kernel_.set("sample_count", cl_uint(count));
  const cl::Event ev = launchAndWait(rt_, kernel_.get(), paddedGlobalRange(W, H, options_), localRange(options_),
                                     "pathtrace", deviceBytes);
  done_ += count;
  ++stats_.passes;
  const double ms = eventSeconds(ev) * 1e3;
  stats_.kernelSeconds += ms * 1e-3;
  return ms;
}

void PathtraceRenderer::readBack(RenderResult& into) {
  const int W = view_.renderer.width, H = view_.renderer.height;
  const size_t pixels = size_t(W) * size_t(H);
  AccumulatorState& acc = into.accumulator;
  acc.begin = begin_;
  acc.samples = done_;
  acc.words.resize(pixels * kAccumulatorWords);
  rt_.queue.enqueueReadBuffer(accumBuf_, CL_TRUE, 0, accumulatorBytes(), acc.words.data());
  rt_.queue.enqueueReadBuffer(statusBuf_, CL_TRUE, 0, sizeof(cl_uint), &into.stats.status);
  acc.status = into.stats.status;
  into.stats.spp = done_;
  into.stats.sampleBegin = begin_;
  into.stats.sppRequested = view_.renderer.spp;
  into.stats.resumedFromSpp = first_;
  into.stats.interrupted = done_ < view_.renderer.spp;
  into.stats.nanPixels = 0;
  if (done_ > 0) into.image = accumulatorImage(acc, W, H, &into.stats.nanPixels);
  if (options_.counters) {
    std::vector<cl_ulong> counts(pixels * 3);
    rt_.queue.enqueueReadBuffer(counterBuf_, CL_TRUE, 0, counts.size() * sizeof(cl_ulong), counts.data());
    into.stats.counters.tentative = into.stats.counters.real = into.stats.counters.densityLookups = 0;
    for (size_t i = 0; i < pixels; ++i) {
      into.stats.counters.tentative += counts[3 * i + 0];
      into.stats.counters.real += counts[3 * i + 1];
      into.stats.counters.densityLookups += counts[3 * i + 2];
    }
  }
}

RenderResult renderPathtrace(ClRuntime& rt, const Scene& scene, SceneGrids grid,
                             const RenderOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  PathtraceRenderer renderer(rt, scene, grid, options);
  renderer.stats().buildSeconds = secondsSince(t0);
  const int W = scene.renderer.width, H = scene.renderer.height, spp = scene.renderer.spp;
  RenderResult result;
  result.warnings = renderer.warnings();
  const int perPass = options.samplesPerPass > 0 ? options.samplesPerPass : pathtraceSamplesPerPass(W, H, spp);
  const int first = renderer.samples();
  std::vector<double> kernelMs, wallMs;  // per pass: with one sample per pass, per frame
  const auto tLoop = std::chrono::steady_clock::now();
  // Samples [done, done + count) per pass (counted from options.sampleBegin); the kernel adds them
  // exactly (accum.h), so any split of the same samples (passes, interruption and --resume, parts
  // merged by `narval merge`) gives the same bits.
  while (renderer.samples() < spp && !cancelled(options)) {
    const int count = std::min(perPass, spp - renderer.samples());
    const auto tPass = std::chrono::steady_clock::now();
    kernelMs.push_back(renderer.addSamples(count));
    wallMs.push_back(secondsSince(tPass) * 1e3);
    if (options.progress) options.progress(renderer.samples(), spp);
    if (renderer.samples() < spp && options.snapshot && options.snapshotDue && options.snapshotDue()) {
      RenderResult partial;
      partial.stats = renderer.stats();
      renderer.readBack(partial);
      partial.mediumMask = renderer.mediumMask();  // a partial EXR is a render's file like the last
      options.snapshot(partial);
    }
  }
  result.stats = renderer.stats();
  renderer.readBack(result);
  result.mediumMask = renderer.mediumMask();
  RenderStats& st = result.stats;
  st.seconds = secondsSince(tLoop);
  st.frames = frameTimings(kernelMs, wallMs);
  st.samplesPerSecond = st.seconds > 0 ? double(W) * H * (renderer.samples() - first) / st.seconds : 0.0;
  return result;
}

}  // namespace narval
