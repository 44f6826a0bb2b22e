// native_render.h: the native baseline (issue 6, item 4): the very kernel code of
// kernels/shared/*.h compiled as C++ and run on host threads, for the same DeviceScene the OpenCL
// drivers upload (render/scene_upload.h buildDeviceScene). Header-only so the unit tests
// (tests/unit/native_render_test.cpp) and the narval-native program (native_render.cpp) share it
// without another library.
//
// What each algorithm runs per pixel, as the device does (kernels/*.cl):
// - pathtrace: pathtrace_sample for samples 0..spp-1 into the exact fixed-point sum (accum.h),
//   image = its mean as the device driver reads it back (accumulatorImage). The device splits the
//   samples into launches, but integer sums do not depend on the split, so the sums are the same
//   function of the per-sample values.
// - raymarch / lobe: raymarch_pixel / lobe_pixel, one deterministic value per pixel.
// Same seed, same per-sample random numbers (Philox keyed by pixel and sample: rng.h). The only
// arithmetic differences from PoCL are its libm (exp, log, sin, cos, pow) against glibc's.
//
// The grid is the host grid_view of grid.h: grid_trilinear on the float array, the arithmetic of
// the device's buffer storage (renderer.storage "buffer", the default on PoCL), bit for bit.
// Majorants, chosen to follow the device's build:
// - pathtrace, grid medium, majorant "grid": the majorant cells (DDA), as the default kernel;
// - pathtrace, majorant "global" or a homogeneous medium (the device builds -DMEDIUM_HOMOGENEOUS,
//   which takes the global majorant): no cells in the grid_view (tracking.h's host test);
// - raymarch / lobe: always the cells (march.h skips empty space with them; the device binds the
//   one-cell buffer for a homogeneous medium, and so does this).
//
// Work distribution: rows handed out by an atomic counter to N std::threads; each pixel's value
// depends only on the pixel, so any thread count gives the same bits (tested).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "shared/compat.h"
// -DNARVAL_NATIVE_INLINE_MINMAX (narval-native-tuned; off elsewhere): compat.h maps nv_fmin/nv_fmax
// to glibc's fminf/fmaxf, which g++ does not inline without -ffinite-math-only, so every density
// lookup (grid_trilinear clamps its coordinate) makes six library calls (~10% of the native time
// by perf, and they block inlining around the lookup). These are fminf/fmaxf's semantics (a NaN
// operand yields the other one), inline; only the sign of a zero from fmin(-0, +0) may differ from
// glibc's, and no pixel of the bench scenes changed. A fix that belongs in compat.h's host branch.
#ifdef NARVAL_NATIVE_INLINE_MINMAX
static inline float native_fminf(float a, float b) { return (a < b || b != b) ? a : b; }
static inline float native_fmaxf(float a, float b) { return (a > b || b != b) ? a : b; }
#undef nv_fmin
#undef nv_fmax
#define nv_fmin native_fminf
#define nv_fmax native_fmaxf
#endif

#include "image/image.h"
#include "render/accumulator.h"
#include "render/device_light_cache.h"
#include "render/lobe_directions.h"
#include "render/realtime_renderer.h"
#include "render/render_common.h"
#include "render/scene_upload.h"
#include "shared/accum.h"
#include "shared/lobe.h"
#include "shared/pathtrace.h"
#include "shared/raymarch.h"

namespace narval::native {

struct NativeOptions {
  Algorithm algorithm = Algorithm::Pathtrace;
  int threads = 0;                      // 0: std::thread::hardware_concurrency()
  std::string majorant = "grid";        // pathtrace: grid | global (as narval render --majorant)
  int spp = 1;                          // pathtrace samples per pixel
  RealtimeParams realtime;              // raymarch / lobe (realtimeParams(scene))
  std::vector<float> lightCache;        // raymarch / lobe with realtime.lightCache.nx > 0: the
                                        // cache's slabs (buildLightCacheOnHost)
  std::vector<float> msCache;           // stays empty: the multiple-scattering cache is device-only
                                        // (prepareRealtimeInputs refuses it), so never read
  std::vector<nv_float4> lobeDirections; // lobe: the canonical directions (lobeDirections(...))
};

struct NativeResult {
  ImageRGB image;
  uint32_t status = 0;      // OR of STATUS_* bits
  long long nanPixels = 0;  // non-finite pixels in the image
  double seconds = 0;       // wall clock from the first thread's start to the last one's end
  int threads = 0;
};

inline int nativeThreadCount(int requested) {
  if (requested > 0) return requested;
  const unsigned hc = std::thread::hardware_concurrency();
  return hc > 0 ? int(hc) : 1;
}

// The grid_view the device's kernel build corresponds to (see the notes above).
inline grid_view nativeGridView(const DeviceScene& ds, const NativeOptions& o) {
  grid_view g{};
  g.data = ds.grid ? ds.grid->data.data() : nullptr;
  g.nx = ds.grid ? ds.grid->nx : 1;
  g.ny = ds.grid ? ds.grid->ny : 1;
  g.nz = ds.grid ? ds.grid->nz : 1;
  const bool pathtrace = o.algorithm == Algorithm::Pathtrace;
  const bool cells = pathtrace ? (ds.grid != nullptr && o.majorant == "grid") : true;
  g.majorants = cells && !ds.majorants.empty() ? ds.majorants.data() : nullptr;
  return g;
}

// The real-time inputs the device driver (realtime_renderer.cpp) prepares: parameters, lobe
// directions and the light cache's slabs, for o.algorithm (nothing for pathtrace).
inline void prepareRealtimeInputs(const Scene& scene, const DeviceScene& ds, NativeOptions& o) {
  if (!isRealtime(o.algorithm)) return;
  Scene asked = scene;  // the blocks of o.algorithm, whatever the scene names
  asked.renderer.algorithm = o.algorithm;
  o.realtime = realtimeParams(asked, ds);
  if (o.algorithm == Algorithm::Lobe) o.lobeDirections = lobeDirections(o.realtime.lobe.points, ds.params, scene.renderer.seed);
  if (o.realtime.msCache.grid.nx > 0)
    throw std::invalid_argument("narval-native: the multiple-scattering cache is built on OpenCL devices only");
  if (o.realtime.lightCache.nx > 0) {
    const grid_view gv = nativeGridView(ds, o);
    o.lightCache = buildLightCacheOnHost(ds, &gv, o.realtime.march, o.realtime.lightCache);
  }
}

// Renders ds with the shared headers on host threads. Throws std::invalid_argument for an unknown
// majorant, or lobe without directions.
inline NativeResult renderNative(const DeviceScene& ds, const NativeOptions& o) {
  const Algorithm alg = o.algorithm;
  if (o.majorant != "grid" && o.majorant != "global")
    throw std::invalid_argument("renderNative: majorant must be grid or global, got '" + o.majorant + "'");
  if (alg == Algorithm::Lobe && o.lobeDirections.empty())
    throw std::invalid_argument("renderNative: lobe needs its directions");
  if (isRealtime(alg) && o.realtime.lightCache.nx > 0 && o.lightCache.empty())
    throw std::invalid_argument("renderNative: the light cache is on but was not built");
  const scene_params* sp = &ds.params;
  const light_params* lights = ds.lights.data();
  const int W = sp->camera.width, H = sp->camera.height;
  const int spp = std::max(1, o.spp);
  const grid_view gv = nativeGridView(ds, o);
  const grid_view* grid = &gv;
  const RealtimeParams* rp = &o.realtime;
  const nv_float4* dirs = o.lobeDirections.data();
  const float* cache = o.lightCache.data();

  // RGBA: the pixel's value (pathtrace: the mean of its samples), A = 0.
  std::vector<float> rgba(size_t(W) * size_t(H) * 4, 0.0f);
  std::atomic<int> nextRow{0};
  std::atomic<uint32_t> statusAll{0};
  auto worker = [&]() {
    kernel_context ctx = kernel_context_host(sp, lights, nullptr, grid);  // one per thread: its status
    for (int y = nextRow.fetch_add(1, std::memory_order_relaxed); y < H;
         y = nextRow.fetch_add(1, std::memory_order_relaxed)) {
      float* row = rgba.data() + size_t(y) * size_t(W) * 4;
      for (int x = 0; x < W; ++x) {
        vec3 L = vec3_splat(0.0f);
        switch (alg) {
          case Algorithm::Pathtrace: {  // the kernel's exact sum (accum.h), its mean as the host takes it
            AccumulatorState sum;
            sum.samples = spp;
            sum.words.assign(ACCUM_WORDS, 0);
            for (int s = 0; s < spp; ++s) accum_add_sample(sum.words.data(), pathtrace_sample(&ctx, x, y, uint(s)));
            long long rejected = 0;
            const ImageRGB mean = accumulatorImage(sum, 1, 1, &rejected);
            L = vec3_make(mean.rgb[0], mean.rgb[1], mean.rgb[2]);
            break;
          }
          case Algorithm::Raymarch:
            L = raymarch_pixel(&ctx, &rp->march, &rp->lightCache, &rp->msCache, cache, o.msCache.data(), x, y);
            break;
          case Algorithm::Lobe: L = lobe_pixel(&ctx, &rp->march, &rp->lobe, &rp->lightCache, dirs, cache, x, y); break;
        }
        row[size_t(x) * 4 + 0] = L.x;
        row[size_t(x) * 4 + 1] = L.y;
        row[size_t(x) * 4 + 2] = L.z;
      }
    }
    statusAll.fetch_or(ctx.status, std::memory_order_relaxed);
  };

  NativeResult r;
  r.threads = nativeThreadCount(o.threads);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  pool.reserve(size_t(r.threads));
  for (int i = 0; i < r.threads; ++i) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.status = statusAll.load();
  r.image = imageFromRgba(rgba, W, H, 1.0f, &r.nanPixels);
  return r;
}

}  // namespace narval::native
