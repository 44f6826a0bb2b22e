// kernel_features.h: scene specialisation ("model only what a scene needs", DESIGN.md). The -D
// options that fix, at build time, what the scene does not vary, so the OpenCL compiler folds the
// runtime branches away (the program cache keys on the options, so each variant is built once):
//
//   -DPHASE_FIXED_ISOTROPIC / -DPHASE_FIXED_HG  the medium's phase function      (phase.h)
//   -DMEDIUM_GREY / -DMEDIUM_CHROMATIC           σ grey or not: analogue walk or
//                                                spectral tracking only             (tracking.h)
//   -DLIGHTS_POINT_ONLY / -DLIGHTS_RECT_ONLY     no rectangle light / only rectangles (intersect.h,
//                                                                                   light.h, march.h)
//   -DCAMERA_PINHOLE                             lens_radius not positive            (camera.h)
//
// Each is derived from the values the kernel would test at run time (DeviceScene.params and
// .lights), so a specialised kernel takes the generic kernel's branch by construction and computes
// the same arithmetic: same pixels, bit for bit (tests/render/kernel_features_test.cpp). Phase and
// grey/chromatic are set only with a medium. Without the defines the kernels keep the generic
// runtime branches (host-compiled headers always do).
//
// NARVAL_GENERIC=1 in the environment turns specialisation off (for measurement and debugging:
// bench/specialisation.sh); it is read at every buildDeviceScene.
#pragma once

#include <string>

#include "render/scene_upload.h"

namespace narval {

// The feature options of `ds`, space-separated in the order of the table above ("" for none).
std::string sceneFeatureOptions(const DeviceScene& ds);

// False when NARVAL_GENERIC is set to anything but "" or "0".
bool kernelSpecialisationEnabled();

}  // namespace narval
