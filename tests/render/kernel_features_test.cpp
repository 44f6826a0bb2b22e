// Scene specialisation (host/render/kernel_features.h): the -D features derived from a scene (exact
// strings), and for each feature the specialised kernel against the generic one (NARVAL_GENERIC=1).
// Every feature fixes a branch to the value the runtime test would take for that scene and leaves
// the arithmetic as it is, so the pixels must be the same bit for bit — path tracer, ray marcher and
// Lobe Estimator alike. (If a compiler ever contracted or reordered float operations differently
// once a branch folds, that would show here as a mismatch: the message gives the largest difference.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/input_error.h"
#include "render/kernel_features.h"
#include "render_fixture.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

struct SceneSpec {
  const char* phase;  // "isotropic" or "hg"
  bool grey;
  bool rect, point;   // which lights
  bool lens;          // thin lens (aperture > 0)
  bool medium = true;
  bool emits = false; // the medium emits (a constant colour: emission.h)
};

std::string sceneJson(const SceneSpec& s) {
  const std::string scattering = s.grey ? "[1.2, 1.2, 1.2]" : "[1.0, 1.3, 1.7]";
  const std::string absorption = s.grey ? "[0.05, 0.05, 0.05]" : "[0.02, 0.05, 0.03]";
  std::string prims;
  auto add = [&prims](const std::string& p) { prims += (prims.empty() ? "" : ",\n") + p; };
  if (s.rect)
    add(R"({"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 5], "scale": [6, 4, 1]}, "materialName": "light"})");
  if (s.point)
    add(R"({"name": "bulb", "type": "point", "transform": {"position": [-2, 2, -1]}, "materialName": "bulb"})");
  if (s.medium)
    add(R"({"name": "box", "type": "volume", "transform": {"scale": [3, 3, 3], "rotation": [0, 15, 0]}, "materialName": "cloud"})");
  return std::string(R"({
  "materials": [
    {"name": "light", "type": "emitter", "albedo": [6, 6, 6]},
    {"name": "bulb", "type": "emitter", "albedo": [4, 3, 2]},
    {"name": "cloud", "type": "volume", "scattering": )") +
         scattering + R"(, "absorption": )" + absorption + R"(, "phaseFunction": ")" + s.phase +
         R"(", "g": 0.6, "density": 3)" +
         (s.emits ? R"(, "emission": {"color": [0.5, 0.3, 0.1], "scale": 2})" : "") + R"(}
  ],
  "primitives": [
)" + prims + R"(
  ],
  "camera": {"position": [0, 0, -7], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 35)" +
         (s.lens ? R"(, "aperture": 0.1, "focus": 7)" : "") + R"(},
  "renderer": {"resolution": [24, 16], "spp": 4, "bounces": 4, "seed": 5},
  "background": [0.1, 0.1, 0.2]
})";
}

// NARVAL_GENERIC set for the lifetime of the object.
struct GenericKernels {
  GenericKernels() { setenv("NARVAL_GENERIC", "1", 1); }
  ~GenericKernels() { unsetenv("NARVAL_GENERIC"); }
};

TEST(KernelFeatures, OptionsDerivedFromTheScene) {
  unsetenv("NARVAL_GENERIC");
  ASSERT_TRUE(kernelSpecialisationEnabled());
  const DenseGrid cloud = makeCloud(16, 3);
  struct Case {
    SceneSpec spec;
    bool grid;
    std::string features, buildOptions;
  };
  const Case cases[] = {
      {{"hg", false, true, true, true}, true, "-DPHASE_FIXED=PHASE_HG -DMEDIUM_CHROMATIC",
       "-DPHASE_FIXED=PHASE_HG -DMEDIUM_CHROMATIC"},
      {{"isotropic", true, true, false, false}, true,
       "-DPHASE_FIXED=PHASE_ISOTROPIC -DMEDIUM_GREY -DLIGHT_FIXED=LIGHT_RECTANGLE -DCAMERA_PINHOLE",
       "-DPHASE_FIXED=PHASE_ISOTROPIC -DMEDIUM_GREY -DLIGHT_FIXED=LIGHT_RECTANGLE -DCAMERA_PINHOLE"},
      {{"hg", true, false, true, false}, false, "-DPHASE_FIXED=PHASE_HG -DMEDIUM_GREY -DLIGHT_FIXED=LIGHT_POINT -DCAMERA_PINHOLE",
       "-DMEDIUM_HOMOGENEOUS -DPHASE_FIXED=PHASE_HG -DMEDIUM_GREY -DLIGHT_FIXED=LIGHT_POINT -DCAMERA_PINHOLE"},
      // No medium: no phase or σ feature.
      {{"hg", false, true, false, true, false}, false, "-DLIGHT_FIXED=LIGHT_RECTANGLE", "-DMEDIUM_HOMOGENEOUS -DLIGHT_FIXED=LIGHT_RECTANGLE"},
      // An emitting medium: its kernels carry emission (emission.h).
      {{"hg", true, true, false, false, true, true}, false,
       "-DPHASE_FIXED=PHASE_HG -DMEDIUM_GREY -DEMISSION -DLIGHT_FIXED=LIGHT_RECTANGLE -DCAMERA_PINHOLE",
       "-DMEDIUM_HOMOGENEOUS -DPHASE_FIXED=PHASE_HG -DMEDIUM_GREY -DEMISSION -DLIGHT_FIXED=LIGHT_RECTANGLE -DCAMERA_PINHOLE"},
      // No light at all: no kind to fix.
      {{"isotropic", true, false, false, false}, true, "-DPHASE_FIXED=PHASE_ISOTROPIC -DMEDIUM_GREY -DCAMERA_PINHOLE",
       "-DPHASE_FIXED=PHASE_ISOTROPIC -DMEDIUM_GREY -DCAMERA_PINHOLE"},
  };
  for (const Case& c : cases) {
    const std::string json = sceneJson(c.spec);
    const DeviceScene ds = buildDeviceScene(sceneFromJson(json), c.grid ? &cloud : nullptr);
    EXPECT_EQ(sceneFeatureOptions(ds), c.features) << json;
    EXPECT_EQ(ds.buildOptions, c.buildOptions) << json;
    GenericKernels generic;
    EXPECT_FALSE(kernelSpecialisationEnabled());
    const DeviceScene g = buildDeviceScene(sceneFromJson(json), c.grid ? &cloud : nullptr);
    // The generic kernel carries every branch, emission's too.
    EXPECT_EQ(g.buildOptions, c.grid && c.spec.medium ? "-DEMISSION" : "-DMEDIUM_HOMOGENEOUS -DEMISSION") << json;
    EXPECT_EQ(sceneFeatureOptions(g), c.features);  // the derivation itself ignores the switch
  }
  setenv("NARVAL_GENERIC", "0", 1);
  EXPECT_TRUE(kernelSpecialisationEnabled());
  unsetenv("NARVAL_GENERIC");
}

// Largest |a − b| / max(1, |b|) over the image, for the failure message.
double maxRelativeDifference(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    m = std::max(m, std::fabs(double(a[i]) - b[i]) / std::max(1.0, std::fabs(double(b[i]))));
  return m;
}

void expectSpecialisedEqualsGeneric(const SceneSpec& spec, const DenseGrid* grid) {
  unsetenv("NARVAL_GENERIC");
  for (const char* algorithm : {"pathtrace", "raymarch", "lobe"}) {
    Scene scene = sceneFromJson(sceneJson(spec));
    ASSERT_TRUE(algorithmFromName(algorithm, &scene.renderer.algorithm));
    const RenderResult specialised = renderAlgorithm(scene, grid);
    RenderResult generic;
    {
      GenericKernels g;
      generic = renderAlgorithm(scene, grid);
    }
    ASSERT_EQ(specialised.image.rgb.size(), generic.image.rgb.size());
    double sum = 0;
    for (float v : generic.image.rgb) sum += v;
    EXPECT_GT(sum, 0.0) << algorithm << ": a black image proves nothing";
    EXPECT_TRUE(specialised.image.rgb == generic.image.rgb)
        << algorithm << " on " << sceneJson(spec) << "\nlargest relative difference "
        << maxRelativeDifference(specialised.image.rgb, generic.image.rgb);
  }
}

// A kind the kernels do not know is refused on the host before any build, with or without
// specialisation, as bad input (InputError: one line, exit 2 in the CLI; buildDeviceScene prefixes
// the scene's file). The loader never produces one: it means a host and kernels out of step.
TEST(KernelFeatures, UnknownKindsAreAnErrorOnTheHost) {
  DeviceScene ds = buildDeviceScene(sceneFromJson(sceneJson({"hg", true, true, true, false})), nullptr);
  ds.params.medium.phase.kind = 7;
  try {
    sceneBuildOptions(ds);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "the kernels know no phase function kind 7");
  }
  ds.params.medium.phase.kind = PHASE_HG;
  ds.lights[0].type = 5;
  GenericKernels generic;
  try {
    sceneBuildOptions(ds);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "the kernels know no light kind 5");
  }
  ds.lights[0].type = LIGHT_RECTANGLE;
  ds.params.medium.emission.kind = 9;
  try {
    sceneBuildOptions(ds);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "the kernels know no emission kind 9");
  }
}

// Each scene switches on a different set of features (see OptionsDerivedFromTheScene).
TEST(KernelFeatures, HgChromaticBothLightsThinLensSameAsGeneric) {
  const DenseGrid cloud = makeCloud(16, 3);
  expectSpecialisedEqualsGeneric({"hg", false, true, true, true}, &cloud);
}

TEST(KernelFeatures, IsotropicGreyRectOnlyPinholeSameAsGeneric) {
  const DenseGrid cloud = makeCloud(16, 3);
  expectSpecialisedEqualsGeneric({"isotropic", true, true, false, false}, &cloud);
}

TEST(KernelFeatures, HgGreyPointOnlyHomogeneousSameAsGeneric) {
  expectSpecialisedEqualsGeneric({"hg", true, false, true, false}, nullptr);
}

// Emission: the generic kernel (-DEMISSION, the kind tested at run time) gives an emitting scene the
// same bits as its specialised kernel; the non-emitting scenes above check that emission code built
// in but switched off (EMISSION_NONE) changes no pixel either.
TEST(KernelFeatures, EmittingChromaticGridSameAsGeneric) {
  const DenseGrid cloud = makeCloud(16, 3);
  expectSpecialisedEqualsGeneric({"hg", false, true, false, false, true, true}, &cloud);
}

TEST(KernelFeatures, IsotropicChromaticPointOnlyGridSameAsGeneric) {
  const DenseGrid cloud = makeCloud(16, 3);
  expectSpecialisedEqualsGeneric({"isotropic", false, false, true, false}, &cloud);
}

}  // namespace
}  // namespace narval::test
