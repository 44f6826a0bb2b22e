// kernel_features.h: every -D option a narval kernel is built with (kernelBuildOptions). Scene
// specialisation ("model only what a scene needs", DESIGN.md) fixes at build time what the scene does not
// vary, so the OpenCL compiler folds the runtime branches (the program cache keys on the options):
//
//   -DMEDIUM_HOMOGENEOUS                      no grid: density 1 in the box                          (grid.h)
//   -DPHASE_FIXED=<id, e.g. PHASE_HG>         the medium's phase function                            (phase.h)
//   -DMEDIUM_GREY / -DMEDIUM_CHROMATIC        σ grey or not: analogue walk or spectral tracking only (tracking.h)
//   -DLIGHT_FIXED=<id, e.g. LIGHT_RECTANGLE>  every light is of that kind                            (light.h)
//   -DCAMERA_PINHOLE                          lens_radius not positive                               (camera.h)
//   -DEMISSION                                the medium emits (else no emission code at all)        (emission.h)
//
// Each is derived from the values the kernel would test at run time (DeviceScene.params and .lights), so a specialised
// kernel takes the generic branch by construction: same pixels, bit for bit (tests/render/kernel_features_test.cpp).
// Phase and grey/chromatic need a medium; without the defines (as in host-compiled headers) the kernels keep the
// runtime branches. NARVAL_GENERIC=1 (measurement, debugging: bench/kernel_ab.py specialisation; read at every
// buildDeviceScene) turns specialisation off but for MEDIUM_HOMOGENEOUS, which is none (the grid argument is an int
// then); the generic kernel gets -DEMISSION, testing the emission kind at run time.
//
// The driver's choices, after those:
//   -DGRID_STORAGE_BUFFER / -DGRID_STORAGE_BRICKS  buffer or bricks, not the image (grid.h; render/device_grid.h)
//   -DMAJORANT_GLOBAL                         path tracer: one majorant (tracking.h)
//   -DCOUNTERS                                path tracer: collision counts (pathtrace.cl)
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

// All the -D options for `ds` built as `build`, space-separated, in the tables' order: the scene's
// (ds.buildOptions: homogeneous, then features), the storage (with a grid), the majorant, the counters.
std::string kernelBuildOptions(const DeviceScene& ds, const KernelBuild& build);

// ds.buildOptions: -DMEDIUM_HOMOGENEOUS without a grid, then sceneFeatureOptions unless NARVAL_GENERIC.
std::string sceneBuildOptions(const DeviceScene& ds);

// "" (the image, grid.h's default), "-DGRID_STORAGE_BUFFER" or "-DGRID_STORAGE_BRICKS"; not for Auto.
std::string gridStorageBuildOption(GridStorage storage);

// The feature options of `ds`, space-separated in the table's order ("" for none). Throws InputError
// ("the kernels know no light kind 5") for a phase function, light or emission kind the kernels lack.
std::string sceneFeatureOptions(const DeviceScene& ds);

// False when NARVAL_GENERIC is set to anything but "" or "0".
bool kernelSpecialisationEnabled();

}  // namespace narval
