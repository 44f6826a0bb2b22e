// render_types.h: what every renderer takes (options) and gives back (image + statistics).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"

namespace narval {

struct RenderOptions {
  int localSizeX = 8, localSizeY = 8;  // work-group shape; never changes the pixels
  int samplesPerPass = 0;              // pathtrace: 0 = automatic (pathtraceSamplesPerPass)
  // Called after every pass with (samples done, samples requested) per pixel.
  std::function<void(int, int)> progress;
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
  int width = 0, height = 0, spp = 0, bounces = 0;
  double seconds = 0;          // wall clock of the sample loop (after build and upload)
  double kernelSeconds = 0;    // sum of OpenCL profiling intervals of the launches
  double buildSeconds = 0;     // program build (or cache load) and upload
  double samplesPerSecond = 0; // width·height·spp / seconds
  int passes = 0;
  uint32_t status = 0;         // OR of STATUS_* bits reported by the kernels
  long long nanPixels = 0;     // non-finite pixels in the final image
  bool programFromCache = false;
  FrameTimings frames;         // filled by frame-timed runs (--frames)
};

struct RenderResult {
  ImageRGB image;
  RenderStats stats;
  std::vector<std::string> warnings;  // from preparing the scene for the device
};

}  // namespace narval
