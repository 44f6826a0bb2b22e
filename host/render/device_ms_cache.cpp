#include "render/device_ms_cache.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cl/device_allocation.h"
#include "core/input_error.h"
#include "render/majorant_options.h"
#include "render/node_grid_layout.h"
#include "render/render_common.h"
#include "shared/ms_cache.h"
#include "shared/ms_cache_view.h"

namespace narval {

void DeviceMsCache::refine(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params,
                           int targetPaths, int pathsPerLaunch, const std::string& sceneFile, double budgetMs) {
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
  scene_params restScene = pathScene;  // the key less the camera and nodes: a move alone is told apart
  restScene.camera = camera_params{};
  std::string key = rawBytes(restScene) + rawBytes(dev.scene.grid) + dev.buildOptions() +
                    (towardsCamera ? "camera" : "uniform") + std::to_string(params.layout) + "/" +
                    std::to_string(params.tile) + (params.direct ? "/direct" : "");
  const bool view = params.layout == MS_CACHE_LAYOUT_VIEW;
  filterOn_ = view && params.filter > 0;
  twicingOn_ = filterOn_ && params.filter_twicing;
  for (int l = 0; l < pathScene.num_lights; ++l) key += rawBytes(dev.scene.lights[size_t(l)]);
  budgeted_ = budgetMs > 0;
  budgetLeftMs_ = budgetMs;
  const std::string rest = key;
  key += rawBytes(c) + rawBytes(pathScene.camera);
  if (key != key_) {
    // Started over with as many nodes as before (a light or the medium changed; a view cache's camera
    // without a budget), the old nodes are drawn until each takes its first new path, which replaces
    // all that a lookup reads (the running mean's first step sets it; ms_cache_build.h): the picture is refreshed
    // progressively, not thrown away, and the cache ends as one built from nothing, bit for bit.
    const bool keep = buffer_() && nodes * MS_CACHE_STRIDE * sizeof(float) == bytes_;
    // A view cache's camera or image size alone changed in a budgeted refine (a viewer's frame): what
    // was drawn is reprojected to the new nodes once they are placed, and drawn while their paths come
    // in (blend()). The running means start from zeros (the blend reads their counts).
    const bool moved = view && budgeted_ && rest == restKey_ && (paths_ > 0 || priorOn_) && !restore_;
    if (moved) {  // the buffers of one move kept for the next (a viewer moves frame after frame)
      if (!previous_() || previous_.getInfo<CL_MEM_SIZE>() != bytes_)
        previous_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
      rt.queue.enqueueCopyBuffer(buffer(), previous_, 0, 0, bytes_);
      previousCamera_ = camera_;
      previousParams_ = placedParams_;
      reprojectPending_ = true;
      frontReady_ = false;
    }
    priorOn_ = blended_ = false;
    if (!keep || !moved) prior_ = drawn_ = cl::Buffer();
    if (!moved) previous_ = cl::Buffer();
    bytes_ = nodes * MS_CACHE_STRIDE * sizeof(float);
    site_ = AllocationSite{sceneFile, view ? "renderer.raymarch.msCache.tile" : "renderer.raymarch.msCache.resolution",
                              "a multiple-scattering cache of " + std::to_string(c.nx) + "x" + std::to_string(c.ny) +
                                  "x" + std::to_string(c.nz) + " nodes"};
    if (moved && keep) rt.queue.enqueueFillBuffer(buffer_, cl_float(0), 0, bytes_);
    if (!keep) {
      buffer_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
      rt.queue.enqueueFillBuffer(buffer_, cl_float(0), 0, bytes_);
      front_ = back_ = mid_ = cl::Buffer();  // allocated by the filter when it is on
      frontReady_ = false;                   // (a kept front is the old filtered copy, drawn meanwhile)
    }
    filteredKey_.clear();
    filteredPaths_ = -1;
    filterPass_ = 0;
    activePrefix_.clear();
    if (dev.buildOptions() != programOptions_) {  // kept across start-overs (a view cache's camera moves)
      programOptions_ = dev.buildOptions();
      program_ = buildProgram(rt, "ms_cache.cl", programOptions_);
      kernel_ = NamedKernel(program_, "ms_cache_build");
      placeKernel_ = NamedKernel(program_, "ms_cache_place_view");
      filterKernel_ = NamedKernel(program_, "ms_cache_filter_view");
      reprojectKernel_ = NamedKernel(program_, "ms_cache_reproject_view");
      blendKernel_ = NamedKernel(program_, "ms_cache_blend_view");
    }
    walkMajorants(rt, dev, pathScene);
    sceneBuf_ = constantBuffer(rt, pathScene);
    statusBuf_ = cl::Buffer(rt.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
    rt.queue.enqueueFillBuffer(statusBuf_, cl_uint(0), 0, sizeof(cl_uint));
    paths_ = sweepPaths_ = 0;
    sweepNode_ = 0;
    ++rebuilds_;
    key_ = key;
    restKey_ = rest;
    camera_ = pathScene.camera;
    placedParams_ = params;
    placed_ = view ? 0 : size_t(-1);  // the view nodes' places, first (place())
    if (restore_) restore(rt, params);
  }
  if (filterOn_ && filterPass_ > 0) filter(rt, params);  // a filtered copy under way first
  if (!place(rt, dev, params)) return;                   // budget spent before every column is placed
  if (reprojectPending_) reproject(rt, params);
  if (paths_ < targetPaths) addPaths(rt, dev, params, targetPaths, pathsPerLaunch);
  if (filterOn_) filter(rt, params);
  if (priorOn_) blend(rt, params, targetPaths, paths_ >= targetPaths && !filterPending());
}

MsCacheSnapshot DeviceMsCache::snapshot(ClRuntime& rt) const {
  MsCacheSnapshot s;
  s.nodes.resize(bytes_ / sizeof(float));
  if (!s.nodes.empty()) rt.queue.enqueueReadBuffer(buffer_, CL_TRUE, 0, bytes_, s.nodes.data());
  s.paths = paths_;
  s.sweepPaths = sweepPaths_;
  s.sweepNode = sweepNode_;
  s.placed = placed_ == size_t(-1) ? UINT64_MAX : uint64_t(placed_);
  s.camera = camera_;
  return s;
}

// The pending snapshot into the cache just started (refine's start-over); a view layout's placed for
// another camera becomes a camera move's prior (filtered first, as it would have been drawn), the
// paths starting from none; without a budget it is let go, since the build runs to its paths before
// anything is drawn.
void DeviceMsCache::restore(ClRuntime& rt, const ms_cache_params& params) {
  const MsCacheSnapshot s = std::move(*restore_);
  restore_.reset();
  if (s.nodes.size() * sizeof(float) != bytes_)
    throw InputError("the multiple-scattering cache to restore holds " + std::to_string(s.nodes.size() / MS_CACHE_STRIDE) +
                     " nodes; this scene's has " + std::to_string(bytes_ / (MS_CACHE_STRIDE * sizeof(float))));
  if (params.layout == MS_CACHE_LAYOUT_VIEW && rawBytes(s.camera) != rawBytes(camera_)) {
    if (!budgeted_) return;
    previous_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
    rt.queue.enqueueWriteBuffer(previous_, CL_TRUE, 0, bytes_, s.nodes.data());
    if (filterOn_) {
      const cl::Buffer means = previous_;
      previous_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
      filterAll(rt, params, means, previous_);
    }
    previousCamera_ = s.camera;
    previousParams_ = params;
    reprojectPending_ = true;
    return;
  }
  rt.queue.enqueueWriteBuffer(buffer_, CL_TRUE, 0, bytes_, s.nodes.data());
  paths_ = s.paths;
  sweepPaths_ = s.sweepPaths;
  sweepNode_ = size_t(s.sweepNode);
  placed_ = s.placed == UINT64_MAX ? size_t(-1) : size_t(s.placed);
}

double DeviceMsCache::pathsDone() const {
  const size_t nodes = bytes_ / (MS_CACHE_STRIDE * sizeof(float));
  return paths() + (nodes > 0 ? double(sweepPaths_) * double(sweepNode_) / double(nodes) : 0.0);
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

// The view layout's nodes' places along their columns, once per cache (ms_cache_view.h, "Layout"), in
// budgeted column slices; true once every column is placed (the grid layout's nodes always are).
bool DeviceMsCache::place(ClRuntime& rt, const DeviceSceneBuffers& dev, const ms_cache_params& params) {
  const size_t columns = size_t(params.grid.nx) * size_t(params.grid.ny);
  if (placed_ >= columns) return true;
  NamedKernel& place = placeKernel_;
  dev.bind(place);
  place.set("scene", sceneBuf_);
  place.set("grid_majorants", majorantBuf_);
  place.set("ms_cache", params);
  place.set("cache", buffer_);
  place.set("status_word", statusBuf_);
  while (placed_ < columns) {
    if (budgeted_ && budgetLeftMs_ <= 0) return false;
    // Budgeted in slices, but all at once under a camera move's prior, which needs every node placed.
    const bool sliced = budgeted_ && !reprojectPending_;
    const size_t end =
        sliced ? std::min(columns, placed_ + std::max<size_t>(64, size_t(unitsThatFit(msPerPlace_, 1024, lastPlaced_))))
               : columns;
    place.set("column_first", cl_uint(placed_));
    place.set("column_count", cl_uint(end - placed_));
    const double ms = launchOverNodes(rt, place.get(), end - placed_, "the multiple-scattering cache",
                                      deviceSceneBytes(dev.scene) + bytes_);
    buildMs_ += ms;
    if (budgeted_) {
      lastPlaced_ = end - placed_;
      msPerPlace_ = std::max(1e-9, ms / double(lastPlaced_));
      budgetLeftMs_ -= ms;
    }
    placed_ = end;
  }
  return true;
}

// Active units before node n: nodes of columns that hold medium in the view layout (the others take
// no paths), every node in the grid layout; for n below the column count, columns with medium.
size_t DeviceMsCache::activeBefore(size_t n) const {
  if (activePrefix_.empty()) return n;
  const size_t columns = activePrefix_.size() - 1;
  return (n / columns) * activePrefix_.back() + activePrefix_[n % columns];
}

// The end of a budgeted slice from `first` (at most `end`): the nodes or columns holding `units` active
// ones, at least one (a slice across empty space takes it all up to the next active unit).
size_t DeviceMsCache::sliceEnd(size_t first, size_t end, double units) const {
  const size_t want = activeBefore(first) + size_t(std::max(1.0, std::min(units, 1e15)));
  size_t lo = first + 1, hi = end;  // the least n in [lo, hi] with activeBefore(n) >= want, else end
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (activeBefore(mid) >= want) hi = mid; else lo = mid + 1;
  }
  return lo;
}

// In the view layout, which columns hold medium (a node's cost is its column's): read once per cache,
// from slice 0's placement, when a budget first needs it.
void DeviceMsCache::countActive(ClRuntime& rt, const ms_cache_params& params) {
  if (!activePrefix_.empty() || params.layout != MS_CACHE_LAYOUT_VIEW) return;
  const size_t columns = size_t(params.grid.nx) * size_t(params.grid.ny);
  std::vector<float> slice0(columns * MS_CACHE_STRIDE);
  rt.queue.enqueueReadBuffer(buffer_, CL_TRUE, 0, slice0.size() * sizeof(float), slice0.data());
  activePrefix_.assign(columns + 1, 0);
  for (size_t c = 0; c < columns; ++c)
    activePrefix_[c + 1] = activePrefix_[c] + (slice0[c * MS_CACHE_STRIDE + MS_VIEW_TAU] >= 0.0f ? 1 : 0);
}

// The units a budgeted slice of cost `msPerUnit` each can take with the budget left (`pilot` before
// anything was measured), growing at most twofold from the last (costs vary across the medium).
double DeviceMsCache::unitsThatFit(double msPerUnit, double pilot, size_t lastUnits) const {
  double units = msPerUnit > 0 ? budgetLeftMs_ / msPerUnit : pilot;
  if (lastUnits > 0) units = std::min(units, 2.0 * double(lastUnits));
  return units;
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
  if (budgeted_) countActive(rt, params);
  while (paths_ < targetPaths) {
    if (sweepPaths_ == 0)  // a new sweep: budgeted, as many paths as the nodes hold (the noise halves)
      sweepPaths_ = std::min({std::max(1, pathsPerLaunch), targetPaths - paths_, budgeted_ ? std::max(1, paths_) : 1 << 30});
    size_t end = nodes;
    if (budgeted_) {
      if (budgetLeftMs_ <= 0) break;  // spent: the next slice waits for the next call
      end = sliceEnd(sweepNode_, nodes, unitsThatFit(msPerNodePath_ * sweepPaths_, 512, lastNodes_));
    }
    kernel_.set("node_first", cl_uint(sweepNode_));
    kernel_.set("node_count", cl_uint(end - sweepNode_));
    kernel_.set("first", cl_uint(paths_));
    kernel_.set("count", cl_uint(sweepPaths_));
    const double ms = launchOverNodes(rt, kernel_.get(), end - sweepNode_, "the multiple-scattering cache",
                                      deviceSceneBytes(dev.scene) + bytes_);
    ++launches_;
    buildMs_ += ms;
    if (budgeted_) {
      lastNodes_ = std::max<size_t>(1, activeBefore(end) - activeBefore(sweepNode_));
      msPerNodePath_ = std::max(1e-9, ms / (double(lastNodes_) * sweepPaths_));
      budgetLeftMs_ -= ms;
    }
    sweepNode_ = end;
    if (sweepNode_ == nodes) {
      paths_ += sweepPaths_;
      sweepNode_ = 0;
      sweepPaths_ = 0;
    }
  }
  status_ |= readStatusWord(rt, statusBuf_);
}

// The filtered copy of the paths so far, made into back_ (twicing: its first pass into mid_) column
// slice by column slice, then swapped to the front that the march reads: a budgeted refine never
// shows a half-filtered copy, and until the first is done the march reads the running means.
void DeviceMsCache::filter(ClRuntime& rt, const ms_cache_params& params) {
  const std::string key = std::to_string(paths_) + "/" + rawBytes(params.filter) + (twicingOn_ ? "/twiced" : "");
  if (filterPass_ == 0) {
    if (key == filteredKey_ || paths_ == 0) return;  // nothing to filter before the first sweep
    filterPass_ = 1;
    filterColumn_ = 0;
    filteringKey_ = key;
    filteringPaths_ = paths_;
  }
  for (cl::Buffer* b : {&front_, &back_, &mid_})
    if (!(*b)() && (b != &mid_ || twicingOn_)) *b = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
  if (budgeted_) countActive(rt, params);
  const size_t columns = size_t(params.grid.nx) * size_t(params.grid.ny);
  while (filterPass_ > 0) {
    const bool second = filterPass_ == 2;
    size_t end = columns;
    if (budgeted_) {
      if (budgetLeftMs_ <= 0) return;
      end = sliceEnd(filterColumn_, columns, unitsThatFit(msPerColumn_, 512, lastColumns_));
    }
    const double ms = filterSlice(rt, params, buffer_, second, mid_, back_, filterColumn_, end);
    if (budgeted_) {
      lastColumns_ = std::max<size_t>(1, activeBefore(end) - activeBefore(filterColumn_));
      msPerColumn_ = std::max(1e-9, ms / double(lastColumns_));
      budgetLeftMs_ -= ms;
    }
    filterColumn_ = end;
    if (filterColumn_ < columns) continue;
    filterColumn_ = 0;
    if (twicingOn_ && !second) {
      filterPass_ = 2;
      continue;
    }
    std::swap(front_, back_);
    frontReady_ = true;
    filterPass_ = 0;
    filteredKey_ = filteringKey_;
    filteredPaths_ = filteringPaths_;
  }
}

// Columns [first, end) of one filter pass over the running means `means` into `out`: S(J), or with
// `second` twicing's 2·S(J) − S(S(J)) from the first pass's `mid` (the weights both times the means':
// ms_cache_filter.h, "Twicing"); with twicing the first pass goes into `mid`. Its milliseconds.
double DeviceMsCache::filterSlice(ClRuntime& rt, const ms_cache_params& params, const cl::Buffer& means, bool second,
                                  const cl::Buffer& mid, const cl::Buffer& out, size_t first, size_t end) {
  NamedKernel& filter = filterKernel_;
  filter.set("ms_cache", params);
  filter.set("cache", means);
  filter.set("column_first", cl_uint(first));
  filter.set("column_count", cl_uint(end - first));
  filter.set("values", second ? mid : means);
  filter.set("residual", cl_int(second ? 1 : 0));
  filter.set("filtered", twicingOn_ && !second ? mid : out);
  const double ms = launchOverNodes(rt, filter.get(), end - first, "the multiple-scattering cache",
                                    (second ? 3 : 2) * bytes_);
  buildMs_ += ms;
  return ms;
}

// The filtered copy of `means` into `out` in one go (both passes with twicing).
void DeviceMsCache::filterAll(ClRuntime& rt, const ms_cache_params& params, const cl::Buffer& means, cl::Buffer& out) {
  const size_t columns = size_t(params.grid.nx) * size_t(params.grid.ny);
  const cl::Buffer mid = twicingOn_ ? allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_) : cl::Buffer();
  filterSlice(rt, params, means, false, mid, out, 0, columns);
  if (twicingOn_) filterSlice(rt, params, means, true, mid, out, 0, columns);
}

// One launch of `k` over every node (the reprojection's, the blend's), its time counted in the build and
// the budget.
void DeviceMsCache::launchEveryNode(ClRuntime& rt, const NamedKernel& k, const ms_cache_params& params) {
  const double ms = launchOverNodes(rt, k.get(), nodeGridCount(params.grid), "the multiple-scattering cache", 3 * bytes_);
  buildMs_ += ms;
  budgetLeftMs_ -= ms;
}

// The camera move's prior: the cache drawn before it (previous_) read at the new nodes' points
// (ms_cache_reproject.h, "Reprojection"), once every column is placed.
void DeviceMsCache::reproject(ClRuntime& rt, const ms_cache_params& params) {
  if (!prior_()) prior_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
  NamedKernel& k = reprojectKernel_;
  k.set("scene", sceneBuf_);
  k.set("ms_cache", params);
  k.set("previous_cache", previousParams_);
  k.set("previous_camera", previousCamera_);
  k.set("previous", previous_);
  k.set("placed", buffer_);
  k.set("prior", prior_);
  launchEveryNode(rt, k, params);
  reprojectPending_ = false;
  priorOn_ = true;
  blended_ = false;
}

// What is drawn while the new paths come in: the prior alone until the first are (the filtered copy's,
// with the filter), then blended with them whenever they changed ("Blend"); dropped once `done`.
void DeviceMsCache::blend(ClRuntime& rt, const ms_cache_params& params, int target, bool done) {
  if (done) {  // the buffers go with the prior (the cache is whole: a viewer has stopped moving)
    priorOn_ = blended_ = false;
    prior_ = drawn_ = previous_ = cl::Buffer();
    return;
  }
  if (filterOn_ && !frontReady_) return;
  const std::string key = filterOn_ ? std::to_string(filteredPaths_)
                                    : std::to_string(paths_) + "/" + std::to_string(sweepNode_);
  if (blended_ && key == blendedKey_) return;
  if (!drawn_()) drawn_ = allocateBuffer(rt, CL_MEM_READ_WRITE, bytes_, site_);
  NamedKernel& k = blendKernel_;
  k.set("ms_cache", params);
  k.set("target", cl_int(std::max(1, target)));
  k.set("prior", prior_);
  k.set("fresh", filterOn_ ? front_ : buffer_);
  k.set("drawn", drawn_);
  launchEveryNode(rt, k, params);
  blended_ = true;
  blendedKey_ = key;
}

}  // namespace narval
