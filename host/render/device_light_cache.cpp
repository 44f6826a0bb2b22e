#include "render/device_light_cache.h"

#include <algorithm>
#include <cstring>

#include "cl/device_allocation.h"
#include "render/node_grid_layout.h"
#include "render/render_common.h"
#include "shared/light_cache.h"

namespace narval {

node_grid_params lightCacheLayout(const DeviceScene& ds, int resolution, double shadowRaysPerFrame,
                                  size_t maxAllocBytes) {
  int cells = resolution == kLightCacheAuto ? kLightCacheAutoResolution : resolution;
  for (;;) {
    const node_grid_params c = nodeGridLayout(ds, cells);
    if (resolution != kLightCacheAuto) return c;
    const size_t bytes = nodeGridCount(c) * size_t(std::max(1, ds.params.num_lights)) * sizeof(float);
    if (bytes <= maxAllocBytes || cells <= 1)
      return double(nodeGridCount(c)) > shadowRaysPerFrame ? node_grid_params{} : c;
    cells /= 2;
  }
}

std::vector<float> buildLightCacheOnHost(const DeviceScene& ds, const grid_view* grid, const march_params& march,
                                         const node_grid_params& c) {
  const int nodes = node_grid_count(&c);
  std::vector<float> cache(size_t(nodes) * size_t(ds.params.num_lights));
  kernel_context ctx = kernel_context_host(&ds.params, ds.lights.data(), nullptr, grid);
  for (int l = 0; l < ds.params.num_lights; ++l)
    for (int n = 0; n < nodes; ++n)
      cache[size_t(l) * size_t(nodes) + size_t(n)] =
          light_cache_build_node(&ctx, &c, march.shadow_steps, march.shadow_area_samples, march.shadow_weighting,
                                 &ds.lights[size_t(l)], n);
  return cache;
}

void DeviceLightCache::update(ClRuntime& rt, const DeviceSceneBuffers& dev, const march_params& march,
                              const node_grid_params& c, const std::string& sceneFile) {
  if (c.nx <= 0) throw std::invalid_argument("DeviceLightCache::update: the cache is off (nx = 0)");
  const int numLights = dev.scene.params.num_lights;
  const size_t nodes = nodeGridCount(c);
  // Everything a slab depends on besides its light. The grid is identified by its address: a
  // DeviceSceneBuffers keeps its grid for its life, and a new scene makes a new one.
  const std::string key = rawBytes(dev.scene.params.medium) + rawBytes(dev.scene.grid) + rawBytes(c) +
                          rawBytes(march.shadow_steps) + rawBytes(march.shadow_area_samples) + dev.buildOptions() +
                          rawBytes(numLights) + rawBytes(march.shadow_weighting) +
                          // weighted by the phase towards the camera: the camera too
                          (march.shadow_weighting == SHADOW_WEIGHTING_PHASE ? rawBytes(dev.scene.params.camera) : "");
  const bool all = key != mediumKey_;
  if (all) {
    bytes_ = std::max<size_t>(1, nodes * size_t(numLights)) * sizeof(float);
    const AllocationSite site{sceneFile, "renderer.lightCache.resolution",
                              "a light-transmittance cache of " + std::to_string(c.nx) + "x" + std::to_string(c.ny) +
                                  "x" + std::to_string(c.nz) + " nodes for " + std::to_string(numLights) + " lights"};
    buffer_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site);
    program_ = buildProgram(rt, "light_cache.cl", dev.buildOptions());
    kernel_ = NamedKernel(program_, "light_cache_build");
    statusBuf_ = cl::Buffer(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
    lights_.assign(size_t(numLights), light_params{});
  }
  std::vector<int> stale;
  for (int l = 0; l < numLights; ++l)
    if (all || std::memcmp(&lights_[size_t(l)], &dev.scene.lights[size_t(l)], sizeof(light_params)) != 0)
      stale.push_back(l);
  if (stale.empty()) return;
  rt.queue.enqueueFillBuffer(statusBuf_, cl_uint(0), 0, sizeof(cl_uint));
  dev.bind(kernel_);
  kernel_.set("march", march);
  kernel_.set("light_cache", c);
  kernel_.set("cache", buffer_);
  kernel_.set("status_word", statusBuf_);
  for (int l : stale) {
    kernel_.set("light", cl_int(l));
    buildMs_ +=
        launchOverNodes(rt, kernel_.get(), nodes, "the light-transmittance cache", deviceSceneBytes(dev.scene) + bytes_);
    lights_[size_t(l)] = dev.scene.lights[size_t(l)];
    ++slabsBuilt_;
  }
  status_ |= readStatusWord(rt, statusBuf_);
  mediumKey_ = key;
}

}  // namespace narval
