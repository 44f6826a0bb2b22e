// render_types.h: what every renderer takes (options) and gives back (image + statistics).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/accumulator.h"

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
  // pathtrace: continue from this state (same scene, size and seed; its begin is sampleBegin)
  // instead of from zero.
  const AccumulatorState* resumeFrom = nullptr;
  // pathtrace: the majorant delta and ratio tracking sample against (kernels/shared/tracking.h):
  // "grid" (per cell of the majorant grid, walked by DDA), "global" (one σ̄ over the box), or "auto"
  // (by device type, measured: render/majorant_options.h). Each is its own kernel build; both are
  // unbiased and deterministic, with different random streams.
  std::string majorant = "auto";
  // Majorant grid cells along the grid's longest axis (chooseMajorantResolution); 0 = automatic
  // (path tracer: pathtraceMajorantResolution; real-time kernels: kDefaultMajorantResolution). Also
  // the real-time kernels' empty-space skipping granularity.
  int majorantResolution = 0;
  // pathtrace: asked after every pass but the last whether to read the samples so far back; when
  // it says yes, `snapshot` gets them as a partial result (image, accumulator, the stats so far,
  // `interrupted` set), e.g. for a display server or --write-partial-images. Reading back between
  // passes changes no pixel.
  std::function<bool()> snapshotDue;
  std::function<void(const struct RenderResult&)> snapshot;
  // pathtrace: build with -DCOUNTERS and report collision and lookup counts in RenderStats.
  bool counters = false;
};

// Per-frame timings of a --frames run. The first frame (program build on first launch, warm-up)
// is reported apart; median/min/max cover the others (or the first when there is only one).
struct FrameTimings {
  int count = 0;
  double firstKernelMs = 0, firstWallMs = 0;
  double medianKernelMs = 0, minKernelMs = 0, maxKernelMs = 0;
  double medianWallMs = 0, minWallMs = 0, maxWallMs = 0;
};

struct RenderStats {
  std::string algorithm, device;
  // Grid storage the kernels were built for, "image", "buffer" or "bricks": renderer.storage
  // resolved for the device and the grid (DeviceSceneBuffers::storage, recordGridStorage in
  // render_common.h); shown even when the medium has no grid to store.
  std::string storage;
  // The grid on the device: bytes in its storage (0 without a grid); with bricks, how many 8³ bricks
  // the grid has and how many hold density (the pool).
  size_t gridBytes = 0, bricks = 0, bricksOccupied = 0;
  int width = 0, height = 0, bounces = 0;
  int spp = 0;                 // samples per pixel in the image (pathtrace: resumed ones included)
  int sampleBegin = 0;         // pathtrace: the image's samples are [sampleBegin, sampleBegin + spp)
  int sppRequested = 0;        // what the scene asked for; more than spp when interrupted
  int resumedFromSpp = 0;      // pathtrace --resume: samples per pixel the render started from
  bool interrupted = false;    // stopped by RenderOptions::cancel before the requested samples
  double seconds = 0;          // wall clock of the sample loop (after build and upload)
  double kernelSeconds = 0;    // sum of OpenCL profiling intervals of the launches
  double buildSeconds = 0;     // program build (or cache load) and upload
  double samplesPerSecond = 0; // width·height·spp / seconds
  int passes = 0;              // launches in this run (frames for the real-time algorithms)
  uint32_t status = 0;         // OR of STATUS_* bits reported by the kernels
  long long nanPixels = 0;     // non-finite pixels in the final image
  bool programFromCache = false;
  FrameTimings frames;         // filled by frame-timed runs (--frames)
  // Majorant of the path tracer's tracking ("grid" or "global"; the real-time kernels always skip
  // with the grid) and the majorant grid's cells per axis (0 0 0 without a grid).
  std::string majorant;
  int majorantCells[3] = {0, 0, 0};
  int majorantResolution = 0;  // the target the cells were built for (chooseMajorantResolution); 0: no grid
  // RenderOptions::counters (pathtrace): sums over all pixels of this run's samples (not those of a
  // resumed state): delta/spectral-tracking tentative collisions, real (absorbing or scattering)
  // collisions, density lookups of delta and ratio tracking (kernels/shared/tracking.h).
  bool counters = false;
  uint64_t collisionsTentative = 0, collisionsReal = 0, densityLookups = 0;
  // Real-time kernels: the light-transmittance cache (render/light_cache.h): cells per axis (0 0 0:
  // off), device bytes, light slabs built in this run (one per light unless something changed
  // between frames) and their build time, reported apart from the frame times.
  int lightCacheCells[3] = {0, 0, 0};
  size_t lightCacheBytes = 0;
  int lightCacheBuilds = 0;
  double lightCacheMs = 0;
  // raymarch with multipleScattering "cache" (render/ms_cache.h): cells per axis (0 0 0: off),
  // paths per node, times it was started (1), its build time apart from the frames.
  // With layout "view" (msCacheView): columns, rows and slices instead of cells.
  int msCacheCells[3] = {0, 0, 0};
  bool msCacheView = false;
  int msCachePaths = 0, msCacheBuilds = 0;
  double msCacheMs = 0;
  // The view layout's filter (kernels/shared/ms_cache_filter.h): σ_s in columns (0: off) and k.
  float msCacheFilter = 0, msCacheFilterTolerance = 0;
  bool msCacheFilterTwicing = false;
  // The share of the paths' first directions drawn towards the lights (kernels/shared/phase_guide.h).
  float msCacheGuide = 0;
  // The view layout's perceptual allocation (render/ms_cache_allocation.h): its smallest and largest
  // paths per column (0, 0: the even share).
  int msCacheBudgetMin = 0, msCacheBudgetMax = 0;
};

struct RenderResult {
  ImageRGB image;               // empty when interrupted before the first pass
  AccumulatorState accumulator; // pathtrace only
  RenderStats stats;
  std::vector<std::string> warnings;  // from preparing the scene for the device
};

}  // namespace narval
