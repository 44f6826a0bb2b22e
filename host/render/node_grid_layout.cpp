#include "render/node_grid_layout.h"

#include <algorithm>
#include <cmath>

#include "render/render_common.h"

namespace narval {

node_grid_params nodeGridLayout(const DeviceScene& ds, int cells) {
  node_grid_params c{};
  const scene_params& sp = ds.params;
  if (cells <= 0 || !sp.has_medium) return c;
  const medium_params& m = sp.medium;
  c.index_to_world = affineInverse(m.world_to_index);
  // World length of each box edge: the index-to-world map's column times the box's index extent.
  const float dims[3] = {m.dims.x, m.dims.y, m.dims.z};
  float len[3];
  for (int a = 0; a < 3; ++a) {
    const float col[3] = {(&c.index_to_world.row[0].x)[a], (&c.index_to_world.row[1].x)[a],
                          (&c.index_to_world.row[2].x)[a]};
    len[a] = dims[a] * std::sqrt(col[0] * col[0] + col[1] * col[1] + col[2] * col[2]);
  }
  const float longest = std::max({len[0], len[1], len[2]});
  int* nodes[3] = {&c.nx, &c.ny, &c.nz};
  for (int a = 0; a < 3; ++a) *nodes[a] = 1 + std::max(1, int(std::lround(double(cells) * len[a] / longest)));
  return c;
}

size_t nodeGridCount(const node_grid_params& c) { return size_t(c.nx) * size_t(c.ny) * size_t(c.nz); }

double launchOverNodes(ClRuntime& rt, const cl::Kernel& kernel, size_t nodes, const std::string& what,
                       size_t deviceBytes) {
  const size_t local = 64, global = (nodes + local - 1) / local * local;
  const cl::Event ev = launchAndWait(rt, kernel, cl::NDRange(global), cl::NDRange(local), what, deviceBytes);
  return eventSeconds(ev) * 1e3;
}

uint32_t readStatusWord(ClRuntime& rt, const cl::Buffer& statusBuf) {
  cl_uint st = 0;
  rt.queue.enqueueReadBuffer(statusBuf, CL_TRUE, 0, sizeof st, &st);
  return st;
}

void nodeGridCells(const node_grid_params& c, int cells[3]) {
  cells[0] = std::max(0, c.nx - 1);
  cells[1] = std::max(0, c.ny - 1);
  cells[2] = std::max(0, c.nz - 1);
}

}  // namespace narval
