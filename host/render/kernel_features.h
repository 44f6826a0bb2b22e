// kernel_features.h: every -D option a narval kernel is built with comes from here
// (kernelBuildOptions): what the scene needs and the choices of the driver.
//
// Scene specialisation ("model only what a scene needs", DESIGN.md): the options that fix, at
// build time, what the scene does not vary, so the OpenCL compiler folds the runtime branches away
// (the program cache keys on the options, so each variant is built once):
//
//   -DMEDIUM_HOMOGENEOUS                         no grid: density 1 in the box      (grid.h)
//   -DPHASE_FIXED=<id, e.g. PHASE_HG>            the medium's phase function      (phase.h)
//   -DMEDIUM_GREY / -DMEDIUM_CHROMATIC           σ grey or not: analogue walk or
//                                                spectral tracking only             (tracking.h)
//   -DLIGHT_FIXED=<id, e.g. LIGHT_RECTANGLE>     every light is of that kind      (light.h)
//   -DCAMERA_PINHOLE                             lens_radius not positive            (camera.h)
//   -DEMISSION                                   the medium emits; without it no kernel
//                                                function carries emission code      (emission.h)
//
// Each is derived from the values the kernel would test at run time (DeviceScene.params and
// .lights), so a specialised kernel takes the generic kernel's branch by construction and computes
// the same arithmetic: same pixels, bit for bit (tests/render/kernel_features_test.cpp). Phase and
// grey/chromatic are set only with a medium. Without the defines the kernels keep the generic
// runtime branches (host-compiled headers always do).
//
// NARVAL_GENERIC=1 in the environment turns specialisation off (for measurement and debugging:
// bench/specialisation.sh); it is read at every buildDeviceScene. MEDIUM_HOMOGENEOUS is not a
// specialisation (the kernel's grid argument is an int then) and stays; the generic kernel is built
// with -DEMISSION, whose code then tests the emission kind at run time.
//
// The driver's choices, after those:
//   -DGRID_STORAGE_BUFFER / -DGRID_STORAGE_BRICKS  the grid as a buffer or bricks (image: none)
//                                                  (grid.h; render/device_grid.h chooses)
//   -DMAJORANT_GLOBAL                            path tracer: one majorant   (tracking.h)
//   -DCOUNTERS                                   path tracer: collision counts (pathtrace.cl)
#pragma once

#include <string>

#include "render/scene_upload.h"

namespace narval {

// What a driver builds a kernel for, beyond the scene.
struct KernelBuild {
  GridStorage storage = GridStorage::Image;  // resolved (not Auto); ignored without a grid
  std::string majorant;                      // the path tracer's: "grid", "global"; "" otherwise
  bool counters = false;                     // the path tracer's -DCOUNTERS
};

// All the -D options for a kernel on `ds` built as `build`, space-separated, in the order of the
// tables above: the scene's (ds.buildOptions: homogeneous, then its features), then the storage
// (with a grid), the majorant and the counters.
std::string kernelBuildOptions(const DeviceScene& ds, const KernelBuild& build);

// The scene's part: -DMEDIUM_HOMOGENEOUS without a grid, then sceneFeatureOptions unless
// NARVAL_GENERIC turns specialisation off (what buildDeviceScene stores in ds.buildOptions).
std::string sceneBuildOptions(const DeviceScene& ds);

// The -D option that builds a kernel for `storage`: "" for the image (the default in grid.h),
// "-DGRID_STORAGE_BUFFER", "-DGRID_STORAGE_BRICKS". `storage` must be resolved (not Auto).
std::string gridStorageBuildOption(GridStorage storage);

// The feature options of `ds`, space-separated in the order of the table above ("" for none).
// Throws InputError ("the kernels know no light kind 5") for a phase function, light or emission
// kind the kernels do not know.
std::string sceneFeatureOptions(const DeviceScene& ds);

// False when NARVAL_GENERIC is set to anything but "" or "0".
bool kernelSpecialisationEnabled();

}  // namespace narval
