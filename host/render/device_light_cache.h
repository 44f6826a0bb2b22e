// device_light_cache.h: the real-time kernels' light-transmittance cache on the device (math and layout:
// kernels/shared/light_cache.h; kernels/light_cache.cl builds it): per light, a grid of nodes over the
// medium's box holding the column density to the light, read instead of marching shadow rays. update()
// rebuilds only the slabs whose inputs (medium, grid, layout, shadow step count, that light) changed, so
// frames and camera moves rebuild nothing and moving one light rebuilds its slab alone.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "render/device_scene.h"
#include "render/scene_upload.h"
#include "shared/grid.h"
#include "shared/structs.h"

namespace narval {

// renderer.lightCache.resolution "auto": longest-axis cells, measured (bench/realtime.py tuning; bench/RESULTS.md).
constexpr int kLightCacheAutoResolution = 64;

// The cache's layout: `resolution` cells on the medium box's longest world-space axis, the others in
// proportion (at least one), nodes = cells + 1 per axis; nx = 0 (no cache) for resolution 0 or no medium.
// kLightCacheAuto starts at kLightCacheAutoResolution, halving until every light's slabs fit `maxAllocBytes`
// (the device's largest allocation), and is off where a frame marches fewer shadow rays per light
// (`shadowRaysPerFrame`) than the cache has nodes: building it would march more than it saves, and the
// marched shadows are exact. An explicit resolution is kept (update() then throws if it does not fit).
node_grid_params lightCacheLayout(const DeviceScene& ds, int resolution, double shadowRaysPerFrame,
                                  size_t maxAllocBytes = SIZE_MAX);

// The column densities of every light's slab computed on the host with the shared header (what the
// device builds; unit tests and the native baseline use it). `grid` reads the medium's density.
std::vector<float> buildLightCacheOnHost(const DeviceScene& ds, const grid_view* grid, const march_params& march,
                                         const node_grid_params& layout);

class DeviceLightCache {
 public:
  // Brings the cache of `layout` (nx > 0) up to date for the scene on `dev` and the shadow rays of
  // `march`; a no-op when nothing it was built from changed. Throws InputError (naming `sceneFile` and
  // renderer.lightCache.resolution) when the cache exceeds the device's largest allocation.
  void update(ClRuntime& rt, const DeviceSceneBuffers& dev, const march_params& march, const node_grid_params& layout,
              const std::string& sceneFile);
  const cl::Buffer& buffer() const { return buffer_; }
  int slabsBuilt() const { return slabsBuilt_; }  // light slabs built over this object's life
  // Launch time by profiling events, as frames are timed (no program build or first-launch driver compile).
  double buildMs() const { return buildMs_; }
  size_t bytes() const { return bytes_; }
  uint32_t status() const { return status_; }     // STATUS_* bits the builds met

 private:
  std::string mediumKey_;  // medium, grid identity, layout and shadow steps the slabs were built from
  std::vector<light_params> lights_;  // each slab's light when it was built
  cl::Program program_;
  NamedKernel kernel_;
  cl::Buffer buffer_, statusBuf_;
  int slabsBuilt_ = 0;
  double buildMs_ = 0;
  size_t bytes_ = 0;
  uint32_t status_ = 0;
};

}  // namespace narval
