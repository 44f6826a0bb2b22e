#include "render/majorant_options.h"

#include <stdexcept>

namespace narval {

void checkMajorantOptions(const RenderOptions& options) {
  if (options.majorant != "grid" && options.majorant != "global")
    throw std::invalid_argument("majorant must be \"grid\" or \"global\", got \"" + options.majorant + "\"");
  if (options.majorantResolution < 0)
    throw std::invalid_argument("majorant resolution must be >= 0 (0: automatic), got " +
                                std::to_string(options.majorantResolution));
}

void applyMajorantResolution(ClRuntime& rt, DeviceSceneBuffers& dev, const RenderOptions& options,
                             RenderStats& stats) {
  DeviceScene& ds = dev.scene;
  if (setMajorantResolution(ds, options.majorantResolution)) {
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
  }
}

std::string pathtraceMajorantBuildOptions(const RenderOptions& options) {
  std::string o = options.majorant == "global" ? "-DMAJORANT_GLOBAL" : "";
  if (options.counters) o = joinBuildOptions(o, "-DCOUNTERS");
  return o;
}

std::string joinBuildOptions(const std::string& base, const std::string& extra) {
  if (base.empty()) return extra;
  if (extra.empty()) return base;
  return base + " " + extra;
}

}  // namespace narval
