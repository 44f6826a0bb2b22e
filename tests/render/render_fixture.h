// render_fixture.h: helpers for rendering small analytic scenes on the default OpenCL device.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "cl/cl_runtime.h"
#include "render/pathtrace_renderer.h"
#include "render/realtime_renderer.h"
#include "shared/structs.h"
#include "scene/scene.h"
#include "volume/dense_grid.h"
#include "unit/stat_util.h"

namespace narval::test {

// One runtime for the whole test binary: building contexts is slow on PoCL.
inline ClRuntime& runtime() {
  static std::unique_ptr<ClRuntime> rt = std::make_unique<ClRuntime>("");
  return *rt;
}

inline Scene sceneFromJson(const std::string& json) { return parseScene(json, "test_scene.json"); }

// A lit isotropic box (a point light above it, background 0.2), drawn by the ray marcher with its
// multiple-scattering cache at 4 cells: the cache's tests' scene.
inline Scene litBox() {
  return sceneFromJson(R"({
    "materials": [
      {"name": "bulb", "type": "emitter", "albedo": [5, 5, 5]},
      {"name": "fog", "type": "volume", "scattering": [1.5, 1.5, 1.5], "absorption": [0.5, 0.5, 0.5], "density": 1}
    ],
    "primitives": [
      {"name": "point", "type": "point", "transform": {"position": [0, 0, 3]}, "materialName": "bulb"},
      {"name": "box", "type": "volume", "transform": {"scale": [1, 1, 1]}, "materialName": "fog"}
    ],
    "camera": {"position": [0, 0, -4], "lookAt": [0, 0, 0], "vfov": 30},
    "renderer": {"resolution": [8, 8], "algorithm": "raymarch", "bounces": 20,
                 "raymarch": {"multipleScattering": "cache", "msCache": {"layout": "grid", "resolution": 4}}},
    "background": [0.2, 0.2, 0.2]
  })");
}

// An n³ grid of density 1 in the voxels x0 <= x < x1 (every y and z), 0 elsewhere.
inline DenseGrid xSlabGrid(int n, int x0, int x1) {
  DenseGrid g;
  g.nx = g.ny = g.nz = n;
  g.data.assign(g.voxelCount(), 0.0f);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = x0; x < x1; ++x) g.data[size_t(x) + size_t(n) * (size_t(y) + size_t(n) * size_t(z))] = 1.0f;
  g.maxValue = 1.0f;
  return g;
}

// The path tracer. Every render helper takes the grid storage from the scene (renderer.storage;
// auto: the buffer on PoCL), as the CLI does.
inline RenderResult render(const Scene& scene, SceneGrids grid = {}, int lx = 8, int ly = 8) {
  RenderOptions o;
  o.localSizeX = lx;
  o.localSizeY = ly;
  return renderPathtrace(runtime(), scene, grid, o);
}

// The scene's own renderer.algorithm (one frame for the real-time ones).
inline RenderResult renderAlgorithm(const Scene& scene, SceneGrids grid = {}) {
  if (scene.renderer.algorithm == Algorithm::Pathtrace) return render(scene, grid);
  return renderRealtime(runtime(), scene, grid, 1, RenderOptions{});
}

// What the hard-case suites render: every algorithm and every real-time option: the ray marcher
// as the dissertation's single-scattering march ("raymarch"), with octaves (and 2x2 phase points per rectangle light), with its multiple-scattering cache
// ("raymarch+ms-cache": a small one, 4 cells and 8 paths per node, so the suites stay fast; every
// code path of the cache's build and lookup runs; with the phase integrated exactly over rectangle
// lights and the HG closure; "raymarch+ms-cache-camera" the same cache with its paths aimed at the
// camera; "raymarch+ms-cache-view" the view layout, columns of 2x2 pixels, 4 slices, with the
// rectangles' shadows weighted by the phase; "raymarch+ms-cache-direct" the same holding the
// lights' unscattered light too, no light loop)
// and the Lobe Estimator as Eq. 7 ("lobe+eq7") and corrected (its phase exact as well).
inline const char* const kHardCaseRenderers[] = {"pathtrace",         "raymarch",
                                                 "raymarch+octaves",  "raymarch+ms-cache",
                                                 "raymarch+ms-cache-camera", "raymarch+ms-cache-view",
                                                 "raymarch+ms-cache-direct", "lobe+eq7",
                                                 "lobe+corrected"};

// `scene` rendered by one of kHardCaseRenderers (or any algorithm name), one frame for the
// real-time ones.
inline RenderResult renderWith(Scene scene, const std::string& renderer, SceneGrids grid = {}) {
  if (renderer == "raymarch+ms-cache" || renderer == "raymarch+ms-cache-camera" || renderer == "raymarch+ms-cache-view" ||
      renderer == "raymarch+ms-cache-direct") {
    scene.renderer.algorithm = Algorithm::Raymarch;
    scene.renderer.raymarch.multipleScattering = MultipleScattering::Cache;
    scene.renderer.raymarch.msCache.layout = MsCacheLayout::Grid;
    scene.renderer.raymarch.msCache.direct = false;
    scene.renderer.raymarch.msCache.resolution = 4;
    scene.renderer.raymarch.msCache.paths = 8;
    scene.renderer.raymarch.areaLightPhase = AreaLightPhase::Exact;  // the phase over a rectangle's solid angle
    scene.renderer.raymarch.msCache.closure = renderer == "raymarch+ms-cache"
                                                  ? MsCacheClosure::Linear   // the moments' linear closure
                                                  : MsCacheClosure::Camera;  // the paths aimed at the camera
    if (renderer == "raymarch+ms-cache-view" || renderer == "raymarch+ms-cache-direct") {
      scene.renderer.raymarch.msCache.layout = MsCacheLayout::View;
      scene.renderer.raymarch.msCache.tile = 2;
      scene.renderer.raymarch.msCache.slices = 4;
      scene.renderer.raymarch.shadowWeighting = ShadowWeighting::Phase;
      scene.renderer.raymarch.msCache.direct = renderer == "raymarch+ms-cache-direct";
    }
  } else if (renderer == "raymarch") {  // the dissertation's march: single scattering
    scene.renderer.algorithm = Algorithm::Raymarch;
    scene.renderer.raymarch.multipleScattering = MultipleScattering::None;
  } else if (renderer == "raymarch+octaves") {
    scene.renderer.algorithm = Algorithm::Raymarch;
    scene.renderer.raymarch.multipleScattering = MultipleScattering::Octaves;
    scene.renderer.raymarch.octaves = 3;
    scene.renderer.raymarch.areaLightSamples = 2;  // and the phase at 2x2 points of a rectangle
  } else if (renderer == "lobe+eq7") {
    scene.renderer.algorithm = Algorithm::Lobe;
    scene.renderer.lobe.variant = LobeVariant::Eq7;
  } else if (renderer == "lobe+corrected") {
    scene.renderer.algorithm = Algorithm::Lobe;
    scene.renderer.lobe.variant = LobeVariant::Corrected;
    scene.renderer.lobe.areaLightPhase = AreaLightPhase::Exact;
  } else if (!algorithmFromName(renderer, &scene.renderer.algorithm)) {
    throw std::invalid_argument("renderWith: no renderer called '" + renderer + "'");
  }
  if (scene.renderer.algorithm == Algorithm::Pathtrace) return render(scene, grid);
  return renderRealtime(runtime(), scene, grid, 1, RenderOptions{});
}

// A ray in double precision.
struct Ray {
  double o[3], d[3];
};

// The ray through image position (fx, fy) (pixel units, (0,0) the top-left corner) of the scene's
// pinhole camera, in double (camera.h's formula); the centre of pixel (px, py) is (px + ½, py + ½).
inline Ray pixelRay(const camera_params& c, double fx, double fy) {
  const double sx = (2 * fx / c.width - 1) * c.tan_half_vfov * c.aspect;
  const double sy = (1 - 2 * fy / c.height) * c.tan_half_vfov;
  Ray r{{c.position.x, c.position.y, c.position.z}, {}};
  const double f[3] = {c.forward.x, c.forward.y, c.forward.z}, rt[3] = {c.right.x, c.right.y, c.right.z},
               up[3] = {c.up.x, c.up.y, c.up.z};
  double n = 0;
  for (int k = 0; k < 3; ++k) {
    r.d[k] = f[k] + sx * rt[k] + sy * up[k];
    n += r.d[k] * r.d[k];
  }
  for (double& v : r.d) v /= std::sqrt(n);
  return r;
}
inline Ray pixelCentreRay(const camera_params& c, int px, int py) { return pixelRay(c, px + 0.5, py + 0.5); }

// An absorption-only homogeneous box (σa = 0.7, 1 unit thick along z) between the camera and a
// large rectangle light (Le = (2, 3, 4)) facing it, seen through a 2° field of view so every camera
// ray crosses the box face to face and then hits the light. `renderer` is the JSON renderer object.
inline std::string absorptionBoxJson(const std::string& renderer) {
  return R"({
    "materials": [
      {"name": "light", "type": "emitter", "albedo": [2, 3, 4]},
      {"name": "absorber", "type": "volume", "scattering": [0, 0, 0], "absorption": [0.7, 0.7, 0.7],
       "phaseFunction": "isotropic", "density": 1}
    ],
    "primitives": [
      {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 5], "scale": [40, 40, 1]},
       "materialName": "light"},
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [2, 2, 1]},
       "materialName": "absorber"}
    ],
    "camera": {"position": [0, 0, -10], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 2},
    "renderer": )" + renderer + "}";
}
constexpr double kAbsorptionBoxSigma = 0.7;
constexpr double kAbsorptionBoxLe[3] = {2, 3, 4};

// exp(−σ/cos θ) for the ray through the centre of pixel (x, y): the transmittance of the unit-thick
// absorption box along it (forward = +z, so 1/cos θ = |(sx, sy, 1)|).
inline double absorptionBoxTransmittance(const camera_params& c, int x, int y) {
  const double sx = (2.0 * (x + 0.5) / c.width - 1) * c.tan_half_vfov * c.aspect;
  const double sy = (1 - 2.0 * (y + 0.5) / c.height) * c.tan_half_vfov;
  return std::exp(-kAbsorptionBoxSigma * std::sqrt(1.0 + sx * sx + sy * sy));
}

// Mean and standard error of the image mean for channel c (pixels as independent samples).
struct ChannelStats {
  double mean = 0, stderrOfMean = 0;
};
inline ChannelStats channelStats(const ImageRGB& img, int c) {
  MeanAccumulator acc;
  for (size_t i = 0, n = size_t(img.width) * img.height; i < n; ++i) acc.add(img.rgb[i * 3 + c]);
  const MeanSe r = acc.result();
  ChannelStats st;
  st.mean = r.mean;
  st.stderrOfMean = r.se;
  return st;
}

}  // namespace narval::test
