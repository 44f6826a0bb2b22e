// medium_mask.h: which pixels see the medium, for judging a render where the medium is rather than
// over an empty background (`narval compare --medium-only`). A pixel is in the mask when the ray
// through its centre from the lens's centre (the real-time kernels' ray, kernels/shared/camera.h)
// crosses a cell that holds density of a majorant grid of its own, 64 cells on the grid's longest
// axis (kernels/shared/majorant_dda.h): the medium's silhouette grown by at most a cell. It depends
// on the scene and the camera only, so every algorithm writes the same mask for the same scene and
// compare judges them on the same pixels.
#pragma once

#include <cstdint>
#include <vector>

#include "render/scene_upload.h"

namespace narval {

// The EXR channel the renders write it to (UINT, 1 in the mask, 0 outside), beside R, G and B.
constexpr const char* kMediumMaskChannel = "medium";

// The mask of one scene's medium for any of its cameras: the grid is bounded at the first call and
// kept (a renderer keeps one across snapshots and camera moves).
class MediumMask {
 public:
  // One value per pixel of ds.params.camera's image, row 0 at the top: 1 in the mask, else 0 (all 0
  // without a medium). `ds` must be the same scene at every call, its camera free to change.
  std::vector<uint32_t> pixels(const DeviceScene& ds);

 private:
  bool built_ = false;
  majorant_grid_params cells_{};
  std::vector<float> bounds_;  // per cell, as MajorantGrid::maxDensity; one cell of 1: homogeneous
};

}  // namespace narval
