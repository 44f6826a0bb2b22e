// device_ms_cache.h: the ray marcher's multiple-scattering cache on the device (kernels/shared/ms_cache.h:
// the math; kernels/ms_cache.cl adds paths): per node, the running mean of paths started there by the path
// tracer's own code. Progressive: refine() adds paths per node (a viewer may call it every frame), starting
// over only when the medium, grid, lights, bounces, seed, background or layout change.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "cl/device_allocation.h"
#include "render/device_scene.h"
#include "shared/structs.h"

namespace narval {

// A cache's nodes and progress, as read back for a file (render/ms_cache_file.h) and restored from one.
struct MsCacheSnapshot {
  std::vector<float> nodes;  // MS_CACHE_STRIDE floats per node (ms_cache.h, "Storage")
  int paths = 0, sweepPaths = 0;
  uint64_t sweepNode = 0, placed = 0;  // the sweep under way; the view layout's columns placed
  camera_params camera{};  // the view layout's: the camera its nodes are placed and aimed for
};

// The most paths per node one build launch adds, unless a caller asks for fewer (tests): it bounds
// a launch's time (a GPU's watchdog, an interrupt between launches); the cache is the same for any split.
constexpr int kMsCachePathsPerLaunch = 32;

class DeviceMsCache {
 public:
  // Brings the cache to at least `targetPaths` paths per node for the scene on `dev` and params.grid (nx > 0),
  // in launches of at most `pathsPerLaunch`, starting over when the scene changed; InputError (naming
  // `sceneFile` and renderer.raymarch.msCache.resolution) when over the device's largest allocation.
  // With budgetMs > 0 it stops once about that much build time (by profiling events) is spent, in slices
  // of nodes sized by the last slice's cost per node and path (at least one slice a call, so every call
  // progresses): a viewer's frame never waits for a whole launch. Budgeted sweeps add as many paths as
  // the nodes hold (1, 1, 2, 4, ... up to pathsPerLaunch), so the noise halves sweep by sweep. A node's
  // paths are the same whatever the slices and sweeps, so the cache after K paths is too, bit for bit.
  void refine(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params, int targetPaths,
              int pathsPerLaunch, const std::string& sceneFile, double budgetMs = 0);
  // The nodes and progress so far (one read-back).
  MsCacheSnapshot snapshot(ClRuntime& rt) const;
  // The next start (the first refine) takes `snapshot` for its nodes and progress instead of zeros: a
  // cache built before, for the same scene and settings (the caller checks them: ms_cache_file.h); the
  // refine goes on from its paths. A view layout's built for another camera is the prior of a camera
  // move instead (below). InputError when its node count is not the start's.
  void restoreAtStart(MsCacheSnapshot snapshot) { restore_ = std::move(snapshot); }
  // What the march reads: the running means or, with the view layout's filter (params.filter > 0;
  // kernels/shared/ms_cache_filter.h), their filtered copy, twiced when params.filter_twicing is set.
  // A budgeted refine makes the filtered copy over several calls; until the first is done, the means.
  // After a view cache's camera or image size changed in a budgeted refine (or it was restored from
  // another camera's), the cache drawn before reprojected to the new nodes, faded out as their new
  // paths come in, and dropped once they are all in (kernels/shared/ms_cache_reproject.h).
  const cl::Buffer& buffer() const {
    if (priorOn_) return blended_ ? drawn_ : prior_;
    return filterOn_ && frontReady_ ? front_ : buffer_;
  }
  bool reprojected() const { return priorOn_; }  // a camera move's prior is drawn
  const cl::Buffer& means() const { return buffer_; }  // the running means, unfiltered
  int paths() const { return paths_; }             // paths per node so far
  // paths() plus the share of the sweep under way (a budgeted refine may stop between its slices).
  double pathsDone() const;
  int launches() const { return launches_; }       // build launches so far, slices included
  // A budgeted refine has yet to make the filtered copy of the paths so far (the view layout's filter).
  bool filterPending() const { return filterOn_ && (filterPass_ > 0 || filteredPaths_ != paths_); }
  int rebuilds() const { return rebuilds_; }       // times it started over (1 for one scene)
  double buildMs() const { return buildMs_; }      // launch time by profiling events, all launches
  size_t bytes() const { return bytes_; }
  uint32_t status() const { return status_; }

 private:
  void addPaths(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params, int targetPaths,
                int pathsPerLaunch);
  // The filtered copy, when the paths or settings changed (budgeted: continued over calls).
  void filter(ClRuntime& rt, const ms_cache_params& params);
  bool place(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params);
  void restore(ClRuntime& rt, const ms_cache_params& params);
  double filterSlice(ClRuntime& rt, const ms_cache_params& params, const cl::Buffer& means, bool second,
                     const cl::Buffer& mid, const cl::Buffer& out, size_t first, size_t end);
  void filterAll(ClRuntime& rt, const ms_cache_params& params, const cl::Buffer& means, cl::Buffer& out);
  // A camera move's prior (ms_cache_reproject.h): previous_ into prior_, once the new nodes are placed;
  // then drawn_, the prior blended with the new paths, until `done`.
  void reproject(ClRuntime& rt, const ms_cache_params& params);
  void blend(ClRuntime& rt, const ms_cache_params& params, int target, bool done);
  void launchEveryNode(ClRuntime& rt, const NamedKernel& k, const ms_cache_params& params);
  // Budgeted slices (device_ms_cache.cpp).
  size_t activeBefore(size_t n) const;
  size_t sliceEnd(size_t first, size_t end, double units) const;
  void countActive(ClRuntime& rt, const ms_cache_params& params);
  double unitsThatFit(double msPerUnit, double pilot, size_t lastUnits) const;
  // The majorant grid the paths walk into pathScene and majorantBuf_ (ms_cache.cpp).
  void walkMajorants(ClRuntime& rt, const DeviceSceneBuffers& dev, scene_params& pathScene);

  std::string key_, restKey_;  // restKey_: key_ less the camera
  camera_params camera_{};      // the camera the paths see (the view layout's: its nodes are placed for it)
  // A camera move's prior: previous_, the cache drawn for previousCamera_, until reprojected into prior_;
  // drawn_ its blend with the new paths (blendedKey_: the paths it was made from).
  bool reprojectPending_ = false, priorOn_ = false, blended_ = false;
  camera_params previousCamera_{};
  ms_cache_params placedParams_{}, previousParams_{};  // the start's (its nodes), and previous_'s
  cl::Buffer previous_, prior_, drawn_;
  std::string blendedKey_;
  std::optional<MsCacheSnapshot> restore_;  // restoreAtStart's, until the start takes it
  AllocationSite site_;  // what an allocation failure names (the scene file and key)
  cl::Program program_;
  std::string programOptions_;
  size_t placed_ = 0;  // view layout: columns placed so far
  NamedKernel kernel_, placeKernel_, filterKernel_, reprojectKernel_, blendKernel_;  // once per program
  cl::Buffer buffer_, sceneBuf_, majorantBuf_, statusBuf_;
  // The filtered copy: front_ is what the march reads once frontReady_; back_ the one being made, mid_
  // twicing's first pass. filterPass_: 0 none under way, 1 the first pass, 2 twicing's second.
  cl::Buffer front_, back_, mid_;
  bool frontReady_ = false;
  int filterPass_ = 0;
  size_t filterColumn_ = 0;
  std::string filteringKey_;
  int filteringPaths_ = -1, filteredPaths_ = -1;
  std::string walkedKey_;                // the grid and resolution walkedBuf_ was built for
  bool walkedOwn_ = false;               // the paths walk walkedGrid_ (else the march's grid)
  majorant_grid_params walkedGrid_{};
  cl::Buffer walkedBuf_;
  bool filterOn_ = false, twicingOn_ = false;
  std::string filteredKey_;  // the paths and filter settings the filtered copy was made from
  int paths_ = 0, rebuilds_ = 0;  // paths_: the launches' path index (every node's count, unless budgeted)
  // The sweep under way: nodes [0, sweepNode_) hold paths_ + sweepPaths_ paths, the rest paths_.
  size_t sweepNode_ = 0;
  int sweepPaths_ = 0;  // 0: no sweep under way
  int launches_ = 0;
  bool budgeted_ = false;     // the refine under way has a budget
  double budgetLeftMs_ = 0;   // its build time left
  // The last slice's cost per active node and path (per active column: the filter's), which sizes the
  // next, kept across start-overs; its active units; the view layout's active columns, prefix-summed.
  double msPerNodePath_ = 0, msPerColumn_ = 0, msPerPlace_ = 0;
  size_t lastNodes_ = 0, lastColumns_ = 0, lastPlaced_ = 0;
  std::vector<size_t> activePrefix_;
  double buildMs_ = 0;
  size_t bytes_ = 0;
  uint32_t status_ = 0;
};

}  // namespace narval
