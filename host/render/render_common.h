// render_common.h: pieces every render driver shares (launch geometry, stats, read-back).
#pragma once

#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "render/device_scene.h"
#include "render/render_types.h"
#include "render/scene_upload.h"
#include "scene/scene.h"

namespace narval {

// Statistics with the fields every algorithm fills the same way.
RenderStats initialStats(const std::string& algorithm, const ClRuntime& rt, const Scene& scene);

// The grid storage `dev` chose (auto may fall back to bricks for a large grid) and its size on the
// device, into `st` (storage, gridBytes, bricks, bricksOccupied).
void recordGridStorage(RenderStats& st, const DeviceSceneBuffers& dev);

// OpenCL 1.2 wants the global size to be a multiple of the local size: pad; kernels guard.
cl::NDRange paddedGlobalRange(int width, int height, const RenderOptions& options);
cl::NDRange localRange(const RenderOptions& options);

// RGBA floats (as the kernels write them) divided by `divisor` into an RGB image; counts the
// pixels with a non-finite channel into *nanPixels.
ImageRGB imageFromRgba(const std::vector<float>& rgba, int width, int height, float divisor, long long* nanPixels);

// Frame statistics from per-frame kernel (profiling) and wall-clock milliseconds.
FrameTimings frameTimings(const std::vector<double>& kernelMs, const std::vector<double>& wallMs);

// Seconds between an event's start and end (profiling queue).
double eventSeconds(const cl::Event& e);

// Device memory a scene holds once uploaded (scene, lights, majorant cells, grid), in bytes.
size_t deviceSceneBytes(const DeviceScene& scene);

// One launch of `kernel`, waited for; a resource error names `what` and the `deviceBytes` this render
// holds (rethrowLaunchError). Returns the launch's profiling event.
cl::Event launchAndWait(ClRuntime& rt, const cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local,
                        const std::string& what, size_t deviceBytes);

// One warning line per STATUS_* bit set in `status` (what the kernels met; DESIGN.md).
std::vector<std::string> statusWarnings(uint32_t status);

// The bytes of a plain struct, as a string: a key for "has this input changed" (the real-time
// caches compare what they were built from).
template <typename T>
std::string rawBytes(const T& v) {
  return std::string(reinterpret_cast<const char*>(&v), sizeof v);
}

// A read-only device copy of a plain struct (a kernel's __constant parameters).
template <typename T>
cl::Buffer constantBuffer(ClRuntime& rt, const T& v) {
  return cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof v, const_cast<T*>(&v));
}

// True once options.cancel is set (Ctrl-C): the render loops stop before their next pass.
bool cancelled(const RenderOptions& options);

}  // namespace narval
