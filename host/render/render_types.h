// render_types.h: what every renderer takes (options) and gives back (image + statistics, render_stats.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/accumulator.h"
#include "render/render_stats.h"

namespace narval {

struct RenderOptions {
  int localSizeX = 8, localSizeY = 8;  // work-group shape; never changes the pixels
  int samplesPerPass = 0;              // pathtrace: 0 = automatic (pathtraceSamplesPerPass)
  // Called after every pass with (samples done, samples requested) per pixel.
  std::function<void(int, int)> progress;
  // Checked before every pass (frame): once true, the render stops and returns what it has.
  const std::atomic<bool>* cancel = nullptr;
  // pathtrace: the first sample index (--samples A:B); the render adds scene.renderer.spp samples
  // from there. Samples are numbered per pixel, so [A, B) of one render are those of any other.
  int sampleBegin = 0;
  // pathtrace: continue from this state (same scene, size and seed; its begin is sampleBegin), not zero.
  const AccumulatorState* resumeFrom = nullptr;
  // pathtrace: the majorant of delta and ratio tracking (kernels/shared/tracking.h): "grid" (per cell, walked
  // by DDA), "global" (one σ̄ over the box) or "auto" (by device type, measured: render/majorant_options.h).
  // Each is its own kernel build; both are unbiased and deterministic, with different random streams.
  std::string majorant = "auto";
  // Majorant grid cells on the longest axis (chooseMajorantResolution; real-time: the empty-space skip step);
  // 0 = automatic (path tracer: pathtraceMajorantResolution, real-time: kDefaultMajorantResolution).
  int majorantResolution = 0;
  // pathtrace: asked after every pass but the last whether to read back the samples so far; if so,
  // `snapshot` gets them as a partial result (image, accumulator, stats so far, `interrupted` set), e.g.
  // for a display server or --write-partial-images. Reading back between passes changes no pixel.
  std::function<bool()> snapshotDue;
  std::function<void(const struct RenderResult&)> snapshot;
  // pathtrace: build with -DCOUNTERS and report collision and lookup counts in RenderStats.
  bool counters = false;
  // Real-time (renderRealtime): a frame's budget in ms (0: none). With one, the multiple-scattering
  // cache is built over the frames in what each leaves of it (RealtimeRenderer::renderFrame), and a
  // frame's wall time holds its share of the build.
  double frameBudgetMs = 0;
  // raymarch with the multiple-scattering cache: start it from this snapshot (ms_cache_file.h, read and
  // checked by the caller) and/or give the cache as the last frame read it.
  const struct MsCacheSnapshot* msCacheIn = nullptr;
  struct MsCacheSnapshot* msCacheOut = nullptr;
};

struct RenderResult {
  ImageRGB image;               // empty when interrupted before the first pass
  AccumulatorState accumulator; // pathtrace only
  RenderStats stats;
  std::vector<std::string> warnings;  // from preparing the scene for the device
  std::vector<uint32_t> mediumMask;   // per pixel, render/medium_mask.h: set where an EXR is written, else empty
};

}  // namespace narval
