#include "render/kernel_features.h"

#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "core/input_error.h"

namespace narval {
namespace {

// `base` and `extra` joined by a space (either may be empty).
std::string joinBuildOptions(const std::string& base, const std::string& extra) {
  if (base.empty()) return extra;
  if (extra.empty()) return base;
  return base + " " + extra;
}

// A kind the kernels do not know (structs.h): a scene this build cannot render, refused as bad
// input (one line, exit 2) before anything is built. The loader produces only known kinds, so it
// means a host and kernels out of step.
InputError unknownKind(const std::string& what, int kind) {
  return InputError("the kernels know no " + what + " kind " + std::to_string(kind));
}

// The id's own name (phase_kinds.h, light_kinds.h), as -DPHASE_FIXED and -DLIGHT_FIXED take it.
std::string phaseKindId(int kind) {
  switch (kind) {
#define PHASE_KIND_NAME(id, value, name, prefix, key, lo, hi, fallback) \
  case id: return #id;
    PHASE_KINDS(PHASE_KIND_NAME)
#undef PHASE_KIND_NAME
  }
  throw unknownKind("phase function", kind);
}
std::string lightKindId(int kind) {
  switch (kind) {
#define LIGHT_KIND_NAME(id, value, name, prefix, scaled, area, vkey, key, lo, hi, fallback) \
  case id: return #id;
    LIGHT_KINDS(LIGHT_KIND_NAME)
#undef LIGHT_KIND_NAME
  }
  throw unknownKind("light", kind);
}

}  // namespace

std::string sceneFeatureOptions(const DeviceScene& ds) {
  const scene_params& sp = ds.params;
  std::string o;
  auto add = [&o](const char* d) {
    if (!o.empty()) o += ' ';
    o += d;
  };
  if (sp.has_medium) {
    add(("-DPHASE_FIXED=" + phaseKindId(sp.medium.phase.kind)).c_str());
    add(sp.medium.grey ? "-DMEDIUM_GREY" : "-DMEDIUM_CHROMATIC");
    const int emits = emission_emits(sp.medium.emission.kind);
    if (emits < 0) throw unknownKind("emission", sp.medium.emission.kind);
    if (emits > 0) add("-DEMISSION");
  }
  // One kind for every light: fixed at build time (no light at all: nothing to fix).
  std::string lightKind;
  for (int i = 0; i < sp.num_lights && size_t(i) < ds.lights.size(); ++i) {
    const std::string id = lightKindId(ds.lights[size_t(i)].type);
    lightKind = i == 0 || id == lightKind ? id : "mixed";
  }
  if (!lightKind.empty() && lightKind != "mixed") add(("-DLIGHT_FIXED=" + lightKind).c_str());
  if (!(sp.camera.lens_radius > 0.0f)) add("-DCAMERA_PINHOLE");
  return o;
}

std::string sceneBuildOptions(const DeviceScene& ds) {
  const scene_params& sp = ds.params;
  std::string o = (!sp.has_medium || !ds.grid) ? "-DMEDIUM_HOMOGENEOUS" : "";
  // Derived either way, so an unknown kind is an error on the host before anything is built.
  const std::string features = sceneFeatureOptions(ds);
  if (kernelSpecialisationEnabled()) return joinBuildOptions(o, features);
  // The generic kernel carries every branch, emission's included (its kind then decides at run time).
  return joinBuildOptions(o, "-DEMISSION");
}

std::string gridStorageBuildOption(GridStorage storage) {
#define GRID_STORAGE_FLAG(name, cxx, define) \
  case GridStorage::cxx: return define;
  switch (storage) {
    GRID_STORAGE_KINDS(GRID_STORAGE_FLAG)
    case GridStorage::Auto: break;
  }
#undef GRID_STORAGE_FLAG
  throw std::invalid_argument("gridStorageBuildOption: the storage must be resolved (not auto)");
}

std::string kernelBuildOptions(const DeviceScene& ds, const KernelBuild& build) {
  std::string o = ds.buildOptions;
  if (ds.grid) o = joinBuildOptions(o, gridStorageBuildOption(build.storage));
  if (build.majorant == "global")
    o = joinBuildOptions(o, "-DMAJORANT_GLOBAL");
  else if (!build.majorant.empty() && build.majorant != "grid")
    throw std::invalid_argument("kernelBuildOptions: unknown majorant '" + build.majorant + "'");
  if (build.counters) o = joinBuildOptions(o, "-DCOUNTERS");
  return o;
}

bool kernelSpecialisationEnabled() {
  const char* v = std::getenv("NARVAL_GENERIC");
  return v == nullptr || v[0] == '\0' || std::strcmp(v, "0") == 0;
}

}  // namespace narval
