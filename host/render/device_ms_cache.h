// device_ms_cache.h: the ray marcher's multiple-scattering cache on the device (kernels/shared/ms_cache.h:
// the math; kernels/ms_cache.cl adds paths): per node, the running mean of paths started there by the path
// tracer's own code. Progressive: refine() adds paths per node (a viewer may call it every frame), starting
// over only when the medium, grid, lights, bounces, seed, background or layout change.
#pragma once

#include <string>

#include "cl/cl_runtime.h"
#include "cl/device_allocation.h"
#include "render/device_scene.h"
#include "render/ms_cache_allocation.h"
#include "shared/structs.h"

namespace narval {

class DeviceMsCache {
 public:
  // Brings the cache to at least `targetPaths` paths per node for the scene on `dev` and params.grid (nx > 0),
  // in launches of at most `pathsPerLaunch`, starting over when the scene changed; InputError (naming
  // `sceneFile` and renderer.raymarch.msCache.resolution) when over the device's largest allocation. With
  // allocation.perceptual (view layout; ms_cache_allocation.h) nodes take the pilot, then columns their budgets
  // (averaging allocation.meanPaths, towards which `targetPaths` counts; paths() reaches it once all are spent).
  void refine(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params, int targetPaths,
              int pathsPerLaunch, const std::string& sceneFile, const MsCacheAllocation& allocation = {});
  // What the march reads: the running means or, with the view layout's filter (params.filter > 0;
  // kernels/shared/ms_cache_filter.h), their filtered copy, twiced when params.filter_twicing is set.
  const cl::Buffer& buffer() const { return twicingOn_ ? twiced_ : filterOn_ ? filtered_ : buffer_; }
  const cl::Buffer& means() const { return buffer_; }  // the running means, unfiltered
  int paths() const;                               // paths per node so far (allocated: their mean, pro rata)
  // The perceptual allocation's smallest and largest budget (0, 0 before it is set or when off).
  int budgetMin() const { return budgetMin_; }
  int budgetMax() const { return budgetMax_; }
  int rebuilds() const { return rebuilds_; }       // times it started over (1 for one scene)
  double buildMs() const { return buildMs_; }      // launch time by profiling events, all launches
  size_t bytes() const { return bytes_; }
  uint32_t status() const { return status_; }

 private:
  void addPaths(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params, int targetPaths,
                int pathsPerLaunch);
  // The filtered copy, when the paths or settings changed.
  void filter(ClRuntime& rt, const ms_cache_params& params);
  // The perceptual allocation (ms_cache.cpp): budgets after the pilot, and the launch index `targetPaths` maps to.
  void setBudgets(ClRuntime& rt, const ms_cache_params& params);
  int allocatedLaunches(int targetPaths) const;
  // The majorant grid the paths walk into pathScene and majorantBuf_ (ms_cache.cpp).
  void walkMajorants(ClRuntime& rt, const DeviceSceneBuffers& dev, scene_params& pathScene);

  std::string key_;
  AllocationSite site_;  // what an allocation failure names (the scene file and key)
  cl::Program program_;
  NamedKernel kernel_;
  cl::Buffer buffer_, filtered_, twiced_, sceneBuf_, majorantBuf_, statusBuf_;
  std::string walkedKey_;                // the grid and resolution walkedBuf_ was built for
  bool walkedOwn_ = false;               // the paths walk walkedGrid_ (else the march's grid)
  majorant_grid_params walkedGrid_{};
  cl::Buffer walkedBuf_;
  bool filterOn_ = false, twicingOn_ = false;
  std::string filteredKey_;  // the paths and filter settings the filtered copy was made from
  int paths_ = 0, rebuilds_ = 0;  // paths_: the launches' path index (every node's count, unless budgeted)
  MsCacheAllocation allocation_;
  double albedo_ = 0;  // the medium's grey albedo σs/σt (channel sums), which the allocation's Y takes
  int budgetMin_ = 0, budgetMax_ = 0;  // set: the budgets are in the nodes
  double buildMs_ = 0;
  size_t bytes_ = 0;
  uint32_t status_ = 0;
};

}  // namespace narval
