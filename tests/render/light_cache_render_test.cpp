// The real-time kernels' economies on the device: the light-transmittance cache (host/render/device_light_cache.h,
// kernels/shared/light_cache.h), early termination of view marches, and the independence of their
// pixels from the path tracer's --majorant-resolution. Each image error is bounded by a derivation
// beside the test, per pixel; the cache's bookkeeping (what is rebuilt when) is counted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "analysis/image_compare.h"
#include "render/device_light_cache.h"
#include "render/device_scene.h"
#include "render/realtime_renderer.h"
#include "render_fixture.h"
#include "test_support.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The unit cube of homogeneous medium (σs = 1.5, σa = 0.5 per unit density, isotropic) lit by a
// point light of intensity 5 at (0, 0, 3), above its top face, seen from −z; `renderer` is the JSON
// renderer object.
std::string litBoxJson(const std::string& renderer, double density = 1, const std::string& background = "[0, 0, 0]") {
  return R"({
    "materials": [
      {"name": "bulb", "type": "emitter", "albedo": [5, 5, 5]},
      {"name": "fog", "type": "volume", "scattering": [1.5, 1.5, 1.5], "absorption": [0.5, 0.5, 0.5],
       "density": )" + std::to_string(density) + R"(}
    ],
    "primitives": [
      {"name": "point", "type": "point", "transform": {"position": [0, 0, 3]}, "materialName": "bulb"},
      {"name": "box", "type": "volume", "transform": {"scale": [1, 1, 1]}, "materialName": "fog"}
    ],
    "camera": {"position": [0.3, 0.4, -4], "lookAt": [0, 0, 0], "vfov": 22},
    "renderer": )" + renderer + R"(,
    "background": )" + background + R"(
  })";
}

RenderResult renderRt(const std::string& json, const DenseGrid* grid = nullptr, RenderOptions o = {}) {
  return renderRealtime(runtime(), sceneFromJson(json), grid, 1, o);
}

double maxAbsDiff(const ImageRGB& a, const ImageRGB& b, int* differing = nullptr) {
  double worst = 0;
  int n = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = std::fabs(double(a.rgb[i]) - b.rgb[i]);
    worst = std::max(worst, d);
    n += d > 0;
  }
  if (differing) *differing = n;
  return worst;
}

// Cache against exact marching on the lit box, both kernels, at 4, 8 and 16 cells. Bound per pixel:
// the shadow optical depths differ by |Δτ| ≤ σt·(h²/8)·0.4224 (tests/unit/light_cache_test.cpp:
// the chord's second derivatives for this light, h = 1/cells, σt = 2), and |e^{−a} − e^{−b}| ≤
// |a − b|, so each light term S/σt = albedo·p·(I/d²)·Tr moves by at most A·|Δτ| with A =
// albedo·p·I/d_min² = 0.75·(1/4π)·5/d_min². The ray marcher weighs those terms by
// Σ_k T_k(1 − e^{−σtΔ}) = 1 − T_end ≤ 1, the lobe by its mean over the points: |ΔL| ≤ A·|Δτ|.
// d_min: the light's distance from the box, 2.5 (ray marcher, samples inside the box); the lobe's
// points reach lobeRadius 0.2 outside it, so 2.3 there. Plus float rounding (1e-6).
TEST(LightCacheRender, ErrorAgainstExactMarchingFallsWithResolutionWithinTheDerivedBound) {
  const struct {
    const char* algorithm;
    const char* params;
    double dMin;
  } kernels[] = {
      {"raymarch", R"("raymarch": {"multipleScattering": "none", "steps": 40, "shadowSteps": 10, "minTransmittance": 0})", 2.5},
      {"lobe", R"("lobe": {"lobePoints": 8, "depthFactor": 0.5, "lobeRadius": 0.2, "shadowSteps": 10, "minTransmittance": 0})",
       2.3},
  };
  for (const auto& k : kernels) {
    SCOPED_TRACE(k.algorithm);
    auto renderer = [&](int cells) {
      return R"({"resolution": [24, 24], "algorithm": ")" + std::string(k.algorithm) + R"(", "lightCache": {"resolution": )" +
             std::to_string(cells) + "}, " + k.params + "}";
    };
    const RenderResult exact = renderRt(litBoxJson(renderer(0)));
    ASSERT_EQ(exact.stats.status, 0u);
    const double A = 0.75 / (4 * kPi) * 5 / (k.dMin * k.dMin);
    double previous = 1e9;
    for (int cells : {4, 8, 16}) {
      const RenderResult cached = renderRt(litBoxJson(renderer(cells)));
      ASSERT_EQ(cached.stats.status, 0u);
      EXPECT_EQ(cached.stats.lightCache.cells[0], cells);
      const double h = 1.0 / cells, bound = A * 2.0 * h * h / 8 * 0.4224 + 1e-6;
      int differing = 0;
      const double err = maxAbsDiff(exact.image, cached.image, &differing);
      std::printf("[ light cache ] %s, %d cells: max |dL| %.3g (bound %.3g), %d values differ\n", k.algorithm, cells,
                  err, bound, differing);
      EXPECT_LE(err, bound);
      EXPECT_GT(differing, 0);  // the cache was used
      EXPECT_LT(err, previous);
      previous = err;
    }
  }
}

// On a real (generated) cloud with two lights the automatic cache stays far below the JND against
// exact marching: mean ΔE76 ≤ 1 (measured here ~0.01-0.1). 120x90: a frame reads more shadows than the
// cache has nodes, so auto builds it (lightCacheLayout).
TEST(LightCacheRender, AutomaticCacheOnACloudStaysWithinOneDeltaEOfExactMarching) {
  const DenseGrid cloud = makeCloud(32, 7);
  for (const char* algorithm : {"raymarch", "lobe"}) {
    auto renderer = [&](const char* cache) {
      return R"({"resolution": [120, 90], "algorithm": ")" + std::string(algorithm) + R"(", "storage": "buffer",
                 "raymarch": {"multipleScattering": "none"}, "lightCache": {"resolution": )" + cache + "}}";
    };
    const RenderResult exact = renderAlgorithm(sceneFromJson(litCloudJson(renderer("0"))), &cloud);
    const RenderResult cached = renderAlgorithm(sceneFromJson(litCloudJson(renderer("\"auto\""))), &cloud);
    ASSERT_EQ(cached.stats.status, 0u);
    EXPECT_EQ(cached.stats.lightCache.builds, 2);  // one slab per light
    const ImageComparison c = compareImages(exact.image, cached.image, DisplaySettings{});
    std::printf("[ light cache ] %s on a cloud, auto: mean dE76 %.4f, max %.3f\n", algorithm, c.stats76.mean,
                c.stats76.max);
    EXPECT_LE(c.stats76.mean, 1.0) << algorithm;
    EXPECT_GT(maxAbsDiff(exact.image, cached.image), 0.0);
  }
}

// The device builds what the host's shared header computes (same quadrature and arithmetic; no
// contraction into FMA on either side, compat.h): within 1e-6 relative. Both weightings of a
// rectangle's shadow points (march_light_column): by area, and by the phase towards the camera.
TEST(LightCacheRender, DeviceBuildMatchesTheHost) {
  for (const char* weighting : {"area", "phase"}) {
    SCOPED_TRACE(weighting);
    const DenseGrid cloud = makeCloud(24, 5);
    const Scene scene = sceneFromJson(litCloudJson(R"({"resolution": [8, 8], "algorithm": "raymarch", "storage": "buffer",
                                                       "lightCache": {"resolution": 20},
                                                       "raymarch": {"multipleScattering": "none", "shadowWeighting": ")" + std::string(weighting) + R"("}})"));
    DeviceSceneBuffers dev(runtime(), scene, &cloud);
    const RealtimeParams params = realtimeParams(scene, dev.scene);
    EXPECT_EQ(params.march.shadow_weighting, std::string(weighting) == "phase" ? SHADOW_WEIGHTING_PHASE : SHADOW_WEIGHTING_AREA);
    DeviceLightCache cache;
    cache.update(runtime(), dev, params.march, params.lightCache, scene.sourcePath);
    const grid_view gv{cloud.data.data(), cloud.nx, cloud.ny, cloud.nz, dev.scene.majorants.data()};
    const std::vector<float> host = buildLightCacheOnHost(dev.scene, &gv, params.march, params.lightCache);
    std::vector<float> device(host.size());
    runtime().queue.enqueueReadBuffer(cache.buffer(), CL_TRUE, 0, device.size() * sizeof(float), device.data());
    int positive = 0;
    for (size_t i = 0; i < host.size(); ++i) {
      // A rectangle's column is −log1p(mean of expm1(−σ̄C_j))/σ̄ over its K×K points: OpenCL's expm1
      // and log1p may differ from libm's by a few ulps, which that quotient carries to ~1e-6 relative.
      ASSERT_NEAR(device[i], host[i], 1e-5 * host[i] + 1e-9) << "value " << i;
      positive += host[i] > 0;
    }
    EXPECT_GT(positive, int(host.size()) / 4);  // the cloud shadows a good part of the box
    EXPECT_EQ(cache.status(), 0u);
  }
}

// The build kernel's status word is live: a NaN voxel (the loaders refuse them; a grid handed over
// directly is not checked) poisons the columns through it, and the build says so.
TEST(LightCacheRender, ANanVoxelRaisesTheBuildsStatus) {
  DenseGrid g = makeCloud(16, 2);
  const Scene scene = sceneFromJson(litCloudJson(R"({"resolution": [8, 8], "algorithm": "raymarch", "storage": "buffer",
                                                     "lightCache": {"resolution": 8},
                                                     "raymarch": {"multipleScattering": "none"}})"));
  DeviceLightCache clean, poisoned;
  DeviceSceneBuffers devClean(runtime(), scene, &g);
  const RealtimeParams params = realtimeParams(scene, devClean.scene);
  clean.update(runtime(), devClean, params.march, params.lightCache, "clean");
  EXPECT_EQ(clean.status(), 0u);
  g.data[size_t(8 + 16 * (8 + 16 * 8))] = NAN;  // the centre voxel
  DeviceSceneBuffers devNan(runtime(), scene, &g);
  poisoned.update(runtime(), devNan, params.march, params.lightCache, "nan");
  EXPECT_TRUE(poisoned.status() & STATUS_NAN);
  const RenderResult r = renderRealtime(runtime(), scene, &g, 1, RenderOptions{});
  EXPECT_TRUE(r.stats.status & STATUS_NAN);
  EXPECT_EQ(r.stats.nanPixels, 0);  // written as 0, never NaN
}

// Rebuilt only when the medium, that light or the shadow quadrature changes: update() on the same
// scene or after a camera move builds nothing; moving one light rebuilds its slab alone; another
// density or step count rebuilds every slab. Weighted by the phase towards the camera, the shadow
// depends on the camera: the weighting itself, and then a camera move, rebuild every slab.
TEST(LightCacheRender, RebuildsOnlyTheSlabsWhoseInputsChanged) {
  const DenseGrid cloud = makeCloud(16, 2);
  auto scene = [](const std::string& renderer, double density = 4) {
    std::string json = litCloudJson(renderer);
    json.replace(json.find("\"density\": 4}"), 13, "\"density\": " + std::to_string(density) + "}");
    return sceneFromJson(json);
  };
  const std::string r = R"({"resolution": [8, 8], "algorithm": "raymarch", "storage": "buffer", "lightCache": {"resolution": 8},
                               "raymarch": {"multipleScattering": "none"}})";
  const Scene a = scene(r);
  DeviceLightCache cache;
  auto update = [&](const DeviceSceneBuffers& dev, const RealtimeParams& p, const std::string& file) {
    cache.update(runtime(), dev, p.march, p.lightCache, file);
  };
  DeviceSceneBuffers devA(runtime(), a, &cloud);
  const RealtimeParams pa = realtimeParams(a, devA.scene);
  cache.update(runtime(), devA, pa.march, pa.lightCache, "a");
  EXPECT_EQ(cache.slabsBuilt(), 2);
  cache.update(runtime(), devA, pa.march, pa.lightCache, "a");
  EXPECT_EQ(cache.slabsBuilt(), 2);  // nothing changed: nothing built

  Scene camera = a;
  camera.camera.position = {1.0f, 0.5f, -6.0f};  // a camera move
  DeviceSceneBuffers devCamera(runtime(), camera, &cloud);
  update(devCamera, realtimeParams(camera, devCamera.scene), "camera");
  EXPECT_EQ(cache.slabsBuilt(), 2);  // the cache does not depend on the camera

  Scene moved = a;
  moved.primitives[1].transform.position = {-1.5f, 2.5f, -1.0f};  // the point light
  DeviceSceneBuffers devMoved(runtime(), moved, &cloud);
  update(devMoved, realtimeParams(moved, devMoved.scene), "moved");
  EXPECT_EQ(cache.slabsBuilt(), 3);  // that light's slab alone

  const Scene denser = scene(r, 5);
  DeviceSceneBuffers devDenser(runtime(), denser, &cloud);
  update(devDenser, realtimeParams(denser, devDenser.scene), "denser");
  EXPECT_EQ(cache.slabsBuilt(), 5);  // the medium changed: every slab

  RealtimeParams moreSteps = realtimeParams(denser, devDenser.scene);
  moreSteps.march.shadow_steps += 1;
  update(devDenser, moreSteps, "denser");
  EXPECT_EQ(cache.slabsBuilt(), 7);

  RealtimeParams phase = moreSteps;
  phase.march.shadow_weighting = SHADOW_WEIGHTING_PHASE;
  update(devDenser, phase, "denser");
  EXPECT_EQ(cache.slabsBuilt(), 9);
  update(devDenser, phase, "denser");
  EXPECT_EQ(cache.slabsBuilt(), 9);
  Scene denserMoved = denser;
  denserMoved.camera.position = {1.0f, 0.5f, -6.0f};
  DeviceSceneBuffers devDenserMoved(runtime(), denserMoved, &cloud);
  update(devDenserMoved, phase, "denser");
  EXPECT_EQ(cache.slabsBuilt(), 11);
}

// Early termination (minTransmittance ε): the ray marcher stops once every channel of T is below
// ε' = ε / max(1, L_b) and changes no pixel by more than ε'·max(A, L_b) (raymarch.h), A =
// albedo·p·Σ I/d_min² with the shadow transmittance taken as 1: 0.75·(1/4π)·5/2.5². The lobe's
// Tr(x0 → P_i) stop below ε' and move a pixel by less than ε'·L_b (lobe.h). A dense box (σt = 32
// per unit) makes both stop early; the exact shadow marches (cache off) isolate the termination.
// Backgrounds 0.3 and 3: below and above 1, where ε' is ε scaled down.
TEST(LightCacheRender, EarlyTerminationChangesNoPixelBeyondItsBound) {
  const double eps = 0.01, A = 0.75 / (4 * kPi) * 5 / (2.5 * 2.5);
  for (double Lb : {0.3, 3.0}) {
    const double epsPixel = eps / std::max(1.0, Lb);
    const struct {
      const char* algorithm;
      const char* params;
      double bound;
    } kernels[] = {
        {"raymarch", R"("raymarch": {"multipleScattering": "none", "steps": 60, "shadowSteps": 10, "minTransmittance": %g})", epsPixel * std::max(A, Lb)},
        {"lobe",
         R"("lobe": {"lobePoints": 8, "depthFactor": 4, "lobeRadius": 0.2, "viewSteps": 40, "minTransmittance": %g})",
         epsPixel * Lb},
    };
    const std::string background = "[" + std::to_string(Lb) + ", " + std::to_string(Lb) + ", " + std::to_string(Lb) + "]";
    for (const auto& k : kernels) {
      SCOPED_TRACE(std::string(k.algorithm) + " in front of " + background);
      auto renderer = [&](double e) {
        char params[256];
        std::snprintf(params, sizeof params, k.params, e);
        return R"({"resolution": [24, 24], "algorithm": ")" + std::string(k.algorithm) +
               R"(", "lightCache": {"resolution": 0}, )" + params + "}";
      };
      const RenderResult full = renderRt(litBoxJson(renderer(0), 16, background));
      const RenderResult cut = renderRt(litBoxJson(renderer(eps), 16, background));
      ASSERT_EQ(cut.stats.status, 0u);
      int differing = 0;
      const double err = maxAbsDiff(full.image, cut.image, &differing);
      std::printf("[ early termination ] %s, eps %g, background %g: max |dL| %.3g (bound %.3g), %d values differ\n",
                  k.algorithm, eps, Lb, err, k.bound, differing);
      EXPECT_LE(err, k.bound * (1 + 1e-5) + 1e-7);
      EXPECT_GT(differing, 0);  // the marches did stop early
    }
  }
}

// The marches place their samples by the default majorant grid, whatever the path tracer's
// --majorant-resolution: no real-time pixel moves (it moved lobe pixels by ΔE up to 100 when it
// reached the marches), and the render says the flag does not apply.
TEST(LightCacheRender, MajorantResolutionChangesNoRealtimePixel) {
  const DenseGrid cloud = makeCloud(32, 7);
  for (const char* algorithm : {"raymarch", "lobe"}) {
    const Scene s = sceneFromJson(
        litCloudJson(R"({"resolution": [32, 24], "storage": "buffer", "algorithm": ")" + std::string(algorithm) + "\"}"));
    const RenderResult base = renderRealtime(runtime(), s, &cloud, 1, RenderOptions{});
    for (int resolution : {1, 4, 64}) {
      RenderOptions o;
      o.majorantResolution = resolution;
      const RenderResult r = renderRealtime(runtime(), s, &cloud, 1, o);
      EXPECT_EQ(r.image.rgb, base.image.rgb) << algorithm << " at " << resolution;
      ASSERT_EQ(r.warnings.size(), 1u);
      EXPECT_EQ(r.warnings[0], std::string("--majorant-resolution applies to the path tracer; ") + algorithm +
                                   " samples over the occupied cells of the default 16-cell grid");
    }
  }
}

}  // namespace
}  // namespace narval::test
