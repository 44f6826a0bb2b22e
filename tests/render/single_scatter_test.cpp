// Single scattering (bounces = 1) of a thin homogeneous slab lit by a point light, against the
// single-scattering integral evaluated by quadrature on the host:
//   L(pixel) = ∫_{t0}^{t1} e^{-σt (t - t0)} σs p(μ) I e^{-σt ℓ(x)} / |x - y|² dt,   x = o + t d,
// with y the light, ℓ(x) the path length of x→y inside the slab, and μ = cos of the angle between
// the light's propagation direction (y→x) and the scattered one (x→camera, -d) (DESIGN.md, HG
// convention). That is the VRE (dissertation Eq. 3) truncated after one scattering event, which is
// what the path tracer estimates with bounces = 1 and no background: NEE at the first real collision.
#include <gtest/gtest.h>

#include <cmath>

#include "render/scene_upload.h"
#include "render_fixture.h"
#include "shared/phase.h"

namespace narval::test {
namespace {

TEST(RenderAnalytic, SingleScatteringSlabMatchesQuadrature) {
  const double sigmaS = 0.5, sigmaA = 0.1, sigmaT = sigmaS + sigmaA, g = 0.3, I = 40.0, h = 0.2;
  const double light[3] = {1.0, 0.5, -2.0};
  Scene scene = sceneFromJson(R"({
    "materials": [
      {"name": "bulb", "type": "emitter", "albedo": [40, 40, 40]},
      {"name": "haze", "type": "volume", "scattering": [0.5, 0.5, 0.5], "absorption": [0.1, 0.1, 0.1],
       "phaseFunction": "hg", "g": 0.3, "density": 1}
    ],
    "primitives": [
      {"name": "bulb", "type": "point", "transform": {"position": [1.0, 0.5, -2.0]}, "materialName": "bulb"},
      {"name": "slab", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [40, 40, 0.2]},
       "materialName": "haze"}
    ],
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 30},
    "renderer": {"resolution": [8, 8], "spp": 40000, "bounces": 1}
  })");
  const RenderResult r = render(scene);
  const camera_params c = buildDeviceScene(scene, nullptr).params.camera;

  // Reference: 4x4 sub-pixel positions (the render jitters uniformly in the pixel), 2000-step
  // midpoint rule in t (the integrand is smooth; error far below 0.1%).
  std::vector<double> ref(64, 0.0);
  for (int py = 0; py < 8; ++py)
    for (int px = 0; px < 8; ++px)
      for (int sub = 0; sub < 16; ++sub) {
        const double fx = px + (sub % 4 + 0.5) / 4, fy = py + (sub / 4 + 0.5) / 4;
        const double sx = (2 * fx / 8 - 1) * c.tan_half_vfov * c.aspect, sy = (1 - 2 * fy / 8) * c.tan_half_vfov;
        // right = (-1, 0, 0), up = (0, 1, 0), forward = (0, 0, 1) for this camera.
        double d[3] = {-sx, sy, 1.0};
        const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double& v : d) v /= n;
        const double o[3] = {0, 0, -5};
        const double t0 = (-h / 2 - o[2]) / d[2], t1 = (h / 2 - o[2]) / d[2];
        const int steps = 2000;
        double sum = 0;
        for (int k = 0; k < steps; ++k) {
          const double t = t0 + (k + 0.5) * (t1 - t0) / steps;
          const double x[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
          double toLight[3] = {light[0] - x[0], light[1] - x[1], light[2] - x[2]};
          const double r2 = toLight[0] * toLight[0] + toLight[1] * toLight[1] + toLight[2] * toLight[2];
          const double rl = std::sqrt(r2);
          // Inside the slab the light path runs from x to the face z = -h/2 (the light is below it).
          const double ell = (x[2] + h / 2) / (-toLight[2] / rl);
          // μ = dot(y→x, -d) = dot(x→y, d)
          const double mu = (toLight[0] * d[0] + toLight[1] * d[1] + toLight[2] * d[2]) / rl;
          const double phase = (1 - g * g) / (4 * M_PI * std::pow(1 + g * g - 2 * g * mu, 1.5));
          sum += std::exp(-sigmaT * (t - t0)) * sigmaS * phase * I * std::exp(-sigmaT * ell) / r2;
        }
        ref[size_t(py * 8 + px)] += sum * (t1 - t0) / steps / 16;
      }

  // Compare the image means; the standard error comes from the per-pixel deviations from the
  // reference (64 pixels x 40000 spp: only ~11% of the paths scatter in so thin a slab). The 1% tolerance must be at least 4 standard errors, else
  // the test would be too noisy to mean anything: assert that too.
  double meanRender = 0, meanRef = 0, dev2 = 0;
  for (int i = 0; i < 64; ++i) {
    meanRender += r.image.rgb[size_t(i) * 3] / 64;
    meanRef += ref[size_t(i)] / 64;
  }
  for (int i = 0; i < 64; ++i) {
    const double dv = r.image.rgb[size_t(i) * 3] - ref[size_t(i)] - (meanRender - meanRef);
    dev2 += dv * dv / 63;
  }
  const double stderrMean = std::sqrt(dev2 / 64);
  EXPECT_LT(4 * stderrMean, 0.01 * meanRef) << "too noisy for a 1% test";
  EXPECT_NEAR(meanRender, meanRef, 0.01 * meanRef) << "standard error " << stderrMean;
  // Grey light and medium: the three channels carry the same estimate.
  EXPECT_EQ(r.image.rgb[0], r.image.rgb[1]);
  EXPECT_EQ(r.stats.status, 0u);
}

}  // namespace
}  // namespace narval::test
