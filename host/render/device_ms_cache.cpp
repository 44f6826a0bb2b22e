#include "render/device_ms_cache.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cl/device_allocation.h"
#include "render/majorant_options.h"
#include "render/node_grid_layout.h"
#include "render/render_common.h"
#include "shared/ms_cache.h"
#include "shared/ms_cache_view.h"

namespace narval {

void DeviceMsCache::refine(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params,
                           int targetPaths, int pathsPerLaunch, const std::string& sceneFile,
                           const MsCacheAllocation& allocation) {
  const node_grid_params& c = params.grid;
  if (c.nx <= 0) throw std::invalid_argument("DeviceMsCache::refine: the cache is off (nx = 0)");
  const size_t nodes = nodeGridCount(c);
  // The paths see the whole scene but the camera (medium, grid, lights, bounces, seed, background),
  // and the camera too when they aim at it (MS_CACHE_CLOSURE_CAMERA, and always in the view layout:
  // the cache starts over when it moves or the image changes size).
  const bool towardsCamera = params.closure == MS_CACHE_CLOSURE_CAMERA;
  scene_params pathScene = dev.scene.params;
  if (!towardsCamera) pathScene.camera = camera_params{};
  pathScene.max_bounces = std::max(0, pathScene.max_bounces - 1);  // the march's sample is the first event
  std::string key = rawBytes(pathScene) + rawBytes(dev.scene.grid) + rawBytes(c) + dev.buildOptions() +
                    (towardsCamera ? "camera" : "uniform") + std::to_string(params.layout) + "/" +
                    std::to_string(params.tile) + (params.direct ? "/direct" : "") + "/guide" +
                    rawBytes(params.guide);
  const bool view = params.layout == MS_CACHE_LAYOUT_VIEW;
  if (allocation.perceptual && !view)
    throw std::invalid_argument("DeviceMsCache::refine: the perceptual allocation needs the view layout");
  if (allocation.perceptual)
    key += "/perceptual" + std::to_string(allocation.meanPaths) + "/" + toneMappingName(allocation.toneMapping) +
           rawBytes(allocation.exposure);
  filterOn_ = view && params.filter > 0;
  twicingOn_ = filterOn_ && params.filter_twicing;
  for (int l = 0; l < pathScene.num_lights; ++l) key += rawBytes(dev.scene.lights[size_t(l)]);
  if (key != key_) {
    bytes_ = nodes * MS_CACHE_STRIDE * sizeof(float);
    site_ = AllocationSite{sceneFile, view ? "renderer.raymarch.msCache.tile" : "renderer.raymarch.msCache.resolution",
                              "a multiple-scattering cache of " + std::to_string(c.nx) + "x" + std::to_string(c.ny) +
                                  "x" + std::to_string(c.nz) + " nodes"};
    buffer_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
    filtered_ = twiced_ = cl::Buffer();  // allocated by the filter when it is on
    filteredKey_.clear();
    rt.queue.enqueueFillBuffer(buffer_, cl_float(0), 0, bytes_);
    program_ = buildProgram(rt, "ms_cache.cl", dev.buildOptions());
    kernel_ = NamedKernel(program_, "ms_cache_build");
    walkMajorants(rt, dev, pathScene);
    sceneBuf_ = constantBuffer(rt, pathScene);
    const medium_params& m = pathScene.medium;
    const double ss = double(m.sigma_s.x) + m.sigma_s.y + m.sigma_s.z;
    const double st = ss + double(m.sigma_a.x) + m.sigma_a.y + m.sigma_a.z;
    albedo_ = st > 0 ? ss / st : 0.0;
    statusBuf_ = cl::Buffer(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
    rt.queue.enqueueFillBuffer(statusBuf_, cl_uint(0), 0, sizeof(cl_uint));
    paths_ = budgetMin_ = budgetMax_ = 0;
    allocation_ = allocation;
    ++rebuilds_;
    key_ = key;
    if (view) {  // the nodes' places along their columns, once (ms_cache_view.h, "Layout")
      NamedKernel place(program_, "ms_cache_place_view");
      dev.bind(place);
      place.set("scene", sceneBuf_);
      place.set("grid_majorants", majorantBuf_);
      place.set("ms_cache", params);
      place.set("cache", buffer_);
      place.set("status_word", statusBuf_);
      buildMs_ += launchOverNodes(rt, place.get(), size_t(c.nx) * size_t(c.ny), "the multiple-scattering cache",
                                  deviceSceneBytes(dev.scene) + bytes_);
    }
  }
  int launches = targetPaths;
  if (allocation_.perceptual) {  // the pilot first, then the budgets from it, then the launches they need
    const int pilot = msAllocationPilot(allocation_.meanPaths);
    if (paths_ < pilot) addPaths(rt, dev, params, std::min(targetPaths, pilot), pathsPerLaunch);
    if (budgetMax_ == 0 && paths_ >= pilot && targetPaths > pilot) setBudgets(rt, params);
    launches = budgetMax_ == 0 ? paths_ : allocatedLaunches(targetPaths);
  }
  if (paths_ < launches) addPaths(rt, dev, params, launches, pathsPerLaunch);
  if (filterOn_) filter(rt, params);
}

int DeviceMsCache::paths() const {
  if (!allocation_.perceptual || budgetMax_ == 0) return paths_;
  if (paths_ >= budgetMax_) return allocation_.meanPaths;
  // Between the pilot and the largest budget, pro rata: the caller's progress towards the mean.
  const int pilot = msAllocationPilot(allocation_.meanPaths);
  return pilot + int(int64_t(paths_ - pilot) * (allocation_.meanPaths - pilot) / (budgetMax_ - pilot));
}

// The budgets (ms_cache_allocation.h) from the pilot's means, written into every node of their
// column (MS_VIEW_BUDGET): one read-back and one write of the whole cache, once per cache.
void DeviceMsCache::setBudgets(ClRuntime& rt, const ms_cache_params& params) {
  const node_grid_params& c = params.grid;
  std::vector<float> nodes(bytes_ / sizeof(float));
  rt.queue.enqueueReadBuffer(buffer_, CL_TRUE, 0, bytes_, nodes.data());
  const std::vector<int> budgets = msPerceptualBudgets(msColumnPilots(nodes, c, albedo_), c.nx, c.ny, allocation_);
  const size_t columns = size_t(c.nx) * size_t(c.ny);
  budgetMin_ = allocation_.meanPaths;
  for (size_t col = 0; col < columns; ++col) {
    if (budgets[col] <= 0) continue;
    budgetMin_ = std::min(budgetMin_, budgets[col]);
    budgetMax_ = std::max(budgetMax_, budgets[col]);
    for (int s = 0; s < c.nz; ++s) nodes[(size_t(s) * columns + col) * MS_CACHE_STRIDE + MS_VIEW_BUDGET] = float(budgets[col]);
  }
  if (budgetMax_ == 0) budgetMin_ = budgetMax_ = allocation_.meanPaths;  // no column holds medium
  rt.queue.enqueueWriteBuffer(buffer_, CL_TRUE, 0, bytes_, nodes.data());
}

// The launch index a target of `targetPaths` mean paths stands for once the budgets are set: the
// largest budget at the mean, pro rata between the pilot and it (paths() is its inverse).
int DeviceMsCache::allocatedLaunches(int targetPaths) const {
  const int mean = allocation_.meanPaths, pilot = msAllocationPilot(mean);
  if (targetPaths >= mean) return budgetMax_;
  if (targetPaths <= pilot) return targetPaths;
  return pilot + int((int64_t(targetPaths - pilot) * (budgetMax_ - pilot) + (mean - pilot) - 1) / (mean - pilot));
}

// The paths are the path tracer's, so they walk its majorant grid (majorant_options.h: 32 cells on
// CPUs, where it measured best), not the march's 16 cells, whose occupied cells place the march's
// samples: the build is faster (bench/RESULTS.md). Built once per grid (its cost in proportion to the
// voxels), not at every start-over: the view cache starts over whenever the camera moves.
void DeviceMsCache::walkMajorants(ClRuntime& rt, const DeviceSceneBuffers& dev, scene_params& pathScene) {
  const int target = pathtraceMajorantResolution(rt.selected.info);
  const std::string key = rawBytes(dev.scene.grid) + "/" + std::to_string(target);
  if (key != walkedKey_) {
    DeviceScene walked = dev.scene;
    walkedOwn_ = setMajorantResolution(walked, target);  // false: no grid, or the march's is that one
    if (walkedOwn_) {
      walkedGrid_ = walked.params.medium.majorant_grid;
      walkedBuf_ = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                              sizeof(float) * walked.majorants.size(), walked.majorants.data());
    }
    walkedKey_ = key;
  }
  if (walkedOwn_) pathScene.medium.majorant_grid = walkedGrid_;
  majorantBuf_ = walkedOwn_ ? walkedBuf_ : dev.majorantBuf;
}

void DeviceMsCache::addPaths(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params,
                             int targetPaths, int pathsPerLaunch) {
  const size_t nodes = nodeGridCount(params.grid);
  dev.bind(kernel_);
  kernel_.set("scene", sceneBuf_);  // the scene the paths see (one bounce fewer, the path tracer's majorant grid)
  kernel_.set("grid_majorants", majorantBuf_);
  kernel_.set("ms_cache", params);
  kernel_.set("cache", buffer_);
  kernel_.set("status_word", statusBuf_);
  while (paths_ < targetPaths) {
    const int count = std::min(std::max(1, pathsPerLaunch), targetPaths - paths_);
    kernel_.set("first", cl_uint(paths_));
    kernel_.set("count", cl_uint(count));
    buildMs_ += launchOverNodes(rt, kernel_.get(), nodes, "the multiple-scattering cache",
                                deviceSceneBytes(dev.scene) + bytes_);
    paths_ += count;
  }
  status_ |= readStatusWord(rt, statusBuf_);
}

void DeviceMsCache::filter(ClRuntime& rt, const ms_cache_params& params) {
  if (!filtered_()) filtered_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
  if (twicingOn_ && !twiced_()) twiced_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
  const std::string key = std::to_string(paths_) + "/" + rawBytes(params.filter) +
                          rawBytes(params.filter_tolerance) + (twicingOn_ ? "/twiced" : "");
  if (key == filteredKey_) return;
  NamedKernel filter(program_, "ms_cache_filter_view");
  filter.set("ms_cache", params);
  filter.set("cache", buffer_);
  const size_t columns = size_t(params.grid.nx) * size_t(params.grid.ny);
  // S(J), then with twicing 2·S(J) − S(S(J)) from it, the weights both times the running means'
  // (ms_cache_filter.h, "Twicing").
  filter.set("values", buffer_);
  filter.set("residual", cl_int(0));
  filter.set("filtered", filtered_);
  buildMs_ += launchOverNodes(rt, filter.get(), columns, "the multiple-scattering cache", 2 * bytes_);
  if (twicingOn_) {
    filter.set("values", filtered_);
    filter.set("residual", cl_int(1));
    filter.set("filtered", twiced_);
    buildMs_ += launchOverNodes(rt, filter.get(), columns, "the multiple-scattering cache", 3 * bytes_);
  }
  filteredKey_ = key;
}

}  // namespace narval
