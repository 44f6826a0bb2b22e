#include "render/majorant_options.h"

#include <stdexcept>

#include "volume/majorant_grid.h"

namespace narval {

namespace {
// Measured (majorant_options.h): cells along the longest axis for the path tracer on CPUs.
constexpr int kPathtraceMajorantResolutionCpu = 32;
}  // namespace

void checkMajorantOptions(const RenderOptions& options) {
  if (options.majorant != "auto" && options.majorant != "grid" && options.majorant != "global")
    throw std::invalid_argument("majorant must be \"auto\", \"grid\" or \"global\", got \"" + options.majorant + "\"");
  if (options.majorantResolution < 0)
    throw std::invalid_argument("majorant resolution must be >= 0 (0: automatic), got " +
                                std::to_string(options.majorantResolution));
}

std::string resolveMajorant(const std::string& requested, const DeviceInfo& device) {
  if (requested != "auto") return requested;
  return device.type == "GPU" ? "global" : "grid";
}

int pathtraceMajorantResolution(const DeviceInfo& device) {
  return device.type == "CPU" ? kPathtraceMajorantResolutionCpu : kDefaultMajorantResolution;
}

void applyMajorantResolution(ClRuntime& rt, DeviceSceneBuffers& dev, int target, RenderStats& stats) {
  DeviceScene& ds = dev.scene;
  if (setMajorantResolution(ds, target)) {
    // The scene struct carries the cell counts and sizes; both buffers are read-only copies.
    dev.sceneBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(scene_params), &ds.params);
    dev.majorantBuf = cl::Buffer(rt.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                 sizeof(float) * ds.majorants.size(), ds.majorants.data());
  }
  if (ds.grid && ds.params.has_medium) {
    const majorant_grid_params& g = ds.params.medium.majorant_grid;
    stats.majorantCells[0] = g.cells_x;
    stats.majorantCells[1] = g.cells_y;
    stats.majorantCells[2] = g.cells_z;
    stats.majorantResolution = target > 0 ? target : kDefaultMajorantResolution;
  }
}

}  // namespace narval
