#include "render/kernel_features.h"

#include <cstdlib>
#include <cstring>

namespace narval {

std::string sceneFeatureOptions(const DeviceScene& ds) {
  const scene_params& sp = ds.params;
  std::string o;
  auto add = [&o](const char* d) {
    if (!o.empty()) o += ' ';
    o += d;
  };
  if (sp.has_medium) {
    add(sp.medium.phase == PHASE_HG ? "-DPHASE_FIXED_HG" : "-DPHASE_FIXED_ISOTROPIC");
    add(sp.medium.grey ? "-DMEDIUM_GREY" : "-DMEDIUM_CHROMATIC");
  }
  int rects = 0, points = 0;
  for (int i = 0; i < sp.num_lights && size_t(i) < ds.lights.size(); ++i)
    (ds.lights[size_t(i)].type == LIGHT_RECTANGLE ? rects : points) += 1;
  if (rects == 0)
    add("-DLIGHTS_POINT_ONLY");  // also with no light at all: nothing to intersect
  else if (points == 0)
    add("-DLIGHTS_RECT_ONLY");
  if (!(sp.camera.lens_radius > 0.0f)) add("-DCAMERA_PINHOLE");
  return o;
}

bool kernelSpecialisationEnabled() {
  const char* v = std::getenv("NARVAL_GENERIC");
  return v == nullptr || v[0] == '\0' || std::strcmp(v, "0") == 0;
}

}  // namespace narval
