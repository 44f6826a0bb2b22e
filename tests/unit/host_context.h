// host_context.h: the kernel context (kernels/shared/kernel_context.h) for one call of a shared
// kernel function in a host test: hostContext(scene, lights, medium, grids, &status) converts to the
// kernel_context* the function takes, starts from *status and ORs the call's status bits back into
// it (and its counts into *counters) when the call's full expression ends.
#pragma once

#include <cstdint>

#include "shared/kernel_context.h"

namespace narval::test {

class HostContext {
 public:
  HostContext(const scene_params* scene, const light_params* lights, const medium_params* medium,
              const grid_view* grids, uint32_t* status, track_counters* counters)
      : ctx_(kernel_context_host(scene, lights, medium, grids)), status_(status), counters_(counters) {
    if (status_) ctx_.status = *status_;
    if (counters_) ctx_.counters = *counters_;
  }
  HostContext(const HostContext&) = delete;
  HostContext& operator=(const HostContext&) = delete;
  ~HostContext() {
    if (status_) *status_ = ctx_.status;
    if (counters_) *counters_ = ctx_.counters;
  }
  operator kernel_context*() { return &ctx_; }  // NOLINT: converts at the call, by design

 private:
  kernel_context ctx_;
  uint32_t* status_;
  track_counters* counters_;
};

// A medium-level function's context (tracking, march, light cache, emission).
inline HostContext hostContext(const medium_params* medium, const grid_view* grids, uint32_t* status = nullptr,
                               track_counters* counters = nullptr) {
  return HostContext(nullptr, nullptr, medium, grids, status, counters);
}
// A scene-level function's context (pathtrace, raymarch, lobe).
inline HostContext sceneContext(const scene_params* scene, const light_params* lights, const grid_view* grids,
                                uint32_t* status = nullptr) {
  return HostContext(scene, lights, nullptr, grids, status, nullptr);
}

}  // namespace narval::test
