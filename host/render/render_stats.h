// render_stats.h: what a render reports, one struct per concern, each serialised by one function
// (its keys of --stats-json, flat: "light_cache_cells") and, where `narval render` prints a line
// for it, described by one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace narval {

// Per-frame timings of a --frames run. The first frame (program build on first launch, warm-up)
// is reported apart; median/min/max cover the others (or the first when there is only one).
struct FrameTimings {
  int count = 0;
  double firstKernelMs = 0, firstWallMs = 0;
  double medianKernelMs = 0, minKernelMs = 0, maxKernelMs = 0;
  double medianWallMs = 0, minWallMs = 0, maxWallMs = 0;
};

// RenderOptions::counters (pathtrace): sums over all pixels of this run's samples (not those of a
// resumed state): delta/spectral-tracking tentative collisions, real (absorbing or scattering)
// collisions, density lookups of delta and ratio tracking (kernels/shared/tracking.h).
struct CollisionCounts {
  bool on = false;
  uint64_t tentative = 0, real = 0, densityLookups = 0;
};

// The real-time kernels' light-transmittance cache (render/device_light_cache.h): cells per axis
// (0 0 0: off), device bytes, light slabs built in this run (one per light unless something changed
// between frames) and their build time, reported apart from the frame times.
struct LightCacheStats {
  int cells[3] = {0, 0, 0};
  size_t bytes = 0;
  int builds = 0;
  double ms = 0;
};

// The ray marcher's multiple-scattering cache (render/device_ms_cache.h): cells per axis (0 0 0:
// off; the view layout: columns, rows and slices), paths per node, times it was started (1), its
// build time apart from the frames; the view layout's filter (σ_s in columns, 0: off; twicing).
struct MsCacheStats {
  int cells[3] = {0, 0, 0};
  bool view = false;
  int paths = 0, builds = 0;
  double progress = 0;  // the share of its paths built (below 1 while a budgeted build is under way)
  double ms = 0;
  float filter = 0;
  bool filterTwicing = false;
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
  // Majorant of the path tracer's tracking ("grid" or "global"; the real-time kernels always skip
  // with the grid) and the majorant grid's cells per axis (0 0 0 without a grid).
  std::string majorant;
  int majorantCells[3] = {0, 0, 0};
  int majorantResolution = 0;  // the target the cells were built for (chooseMajorantResolution); 0: no grid
  FrameTimings frames;         // filled by frame-timed runs (--frames)
  CollisionCounts counters;
  LightCacheStats lightCache;
  MsCacheStats msCache;
};

// --frames: per-frame milliseconds, the first frame (build, warm-up) apart ("ms_per_frame").
nlohmann::json framesJson(const FrameTimings& f);
// Each part's keys, added to `j` (the counters' only when they were on).
void addJson(nlohmann::json& j, const CollisionCounts& c);
void addJson(nlohmann::json& j, const LightCacheStats& c);
void addJson(nlohmann::json& j, const MsCacheStats& c);
// --stats-json: everything above but the frames, with the scene's seed and file.
nlohmann::json statsJson(const RenderStats& s, uint32_t seed, const std::string& scenePath);

// The line `narval render` prints for a cache it built in this run ("" when it built none).
std::string describe(const LightCacheStats& c);
std::string describe(const MsCacheStats& c);

}  // namespace narval
