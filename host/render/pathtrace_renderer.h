// pathtrace_renderer.h: drives kernels/pathtrace.cl: upload, passes, exact accumulation.
#pragma once

#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "render/device_scene.h"
#include "render/medium_mask.h"
#include "render/render_types.h"
#include "scene/scene.h"
#include "volume/dense_grid.h"

namespace narval {

// Samples per launch: about 2^20 paths, at least 1, at most spp. It depends only on the image size
// and spp, never on timings, so a render's pixels are the same on every run.
int pathtraceSamplesPerPass(int width, int height, int spp);

// A path tracer held across passes: the program and the scene on the device are built once; the
// accumulator gathers samples pass by pass, and setView (another camera or resolution) starts it
// over. `narval render` runs one to its spp (renderPathtrace), the viewer one that restarts on
// every camera move, so both draw with the same code and the same bits for the same samples.
class PathtraceRenderer {
 public:
  // Builds the program and uploads the scene; the accumulator starts from options.resumeFrom or 0.
  PathtraceRenderer(ClRuntime& rt, const Scene& scene, SceneGrids grid, const RenderOptions& options = {});
  // The scene with another camera or renderer.resolution (its medium, lights and settings unchanged):
  // the accumulator starts over from 0 samples.
  void setView(const Scene& view);
  // Starts over from 0 samples.
  void reset();
  // One launch adding the next `count` samples (indices from RenderOptions::sampleBegin +
  // samples()) to every pixel, waited for; returns its milliseconds by profiling event.
  double addSamples(int count);
  int samples() const { return done_; }
  // The accumulator so far into `into` (image, the state --resume continues from, status, counts).
  void readBack(RenderResult& into);
  const RenderStats& stats() const { return stats_; }
  RenderStats& stats() { return stats_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  const DeviceScene& deviceScene() const { return dev_.scene; }
  // The current camera's medium mask (render/medium_mask.h): what an EXR of the image holds beside
  // it. Asked for by whoever writes one, not per frame: a host ray per pixel.
  std::vector<uint32_t> mediumMask() { return mask_.pixels(dev_.scene); }

 private:
  void allocateAccumulator();
  size_t accumulatorBytes() const;
  ClRuntime& rt_;
  Scene view_;
  RenderOptions options_;
  DeviceSceneBuffers dev_;
  MediumMask mask_;
  cl::Program program_;
  NamedKernel kernel_;
  cl::Buffer accumBuf_, statusBuf_, counterBuf_;
  int begin_ = 0;               // the first sample index (RenderOptions::sampleBegin)
  int first_ = 0, done_ = 0;    // samples resumed from, and accumulated, from begin_ on
  RenderStats stats_;
  std::vector<std::string> warnings_;
};

// Renders `scene` (already validated; `grid` is the volume's grid or null) on rt's device.
RenderResult renderPathtrace(ClRuntime& rt, const Scene& scene, SceneGrids grid,
                             const RenderOptions& options = {});

}  // namespace narval
