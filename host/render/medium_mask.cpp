#include "render/medium_mask.h"

#include <array>

#include "shared/camera.h"
#include "shared/majorant_dda.h"
#include "shared/medium.h"
#include "volume/majorant_grid.h"

namespace narval {
namespace {

// Cells along the grid's longest axis: the mask's silhouette is the medium's to within one.
constexpr int kMaskCells = 64;

}  // namespace

std::vector<uint32_t> MediumMask::pixels(const DeviceScene& ds) {
  const camera_params& cam = ds.params.camera;
  const medium_params& medium = ds.params.medium;
  std::vector<uint32_t> mask(size_t(cam.width) * size_t(cam.height), 0u);
  if (!ds.params.has_medium) return mask;
  if (!built_) {  // its own majorant grid, not the renderer's: each algorithm picks its resolution
    cells_ = medium.majorant_grid;
    bounds_.assign(1, 1.0f);
    if (ds.grid) {
      const std::array<int, 3> n = chooseMajorantResolution(ds.grid->nx, ds.grid->ny, ds.grid->nz, kMaskCells);
      const MajorantGrid g = buildMajorantGrid(*ds.grid, n[0], n[1], n[2]);
      cells_ = g.params();
      bounds_ = g.maxDensity;
    }
    built_ = true;
  }
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const ray3 ray = camera_pixel_centre_ray(&cam, x, y);
      medium_segment seg;
      if (!medium_intersect(&medium, ray.origin, ray.dir, 0.0f, NV_INFINITY, &seg)) continue;
      majorant_iter it = majorant_iter_begin(cells_, seg.o, seg.d, seg.t0, seg.t1);
      float a, b, cellMax;
      while (majorant_iter_next(&it, bounds_.data(), &a, &b, &cellMax))
        if (cellMax > 0.0f) {
          mask[size_t(y) * size_t(cam.width) + size_t(x)] = 1u;
          break;
        }
    }
  return mask;
}

}  // namespace narval
