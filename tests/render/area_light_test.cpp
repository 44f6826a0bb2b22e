// Rectangle (area) lights in the path tracer (kernels/shared/pathtrace.h, light.h): single scattering
// of a homogeneous slab lit by a rectangle against host quadrature over the view ray AND the light's
// area, which checks that next-event estimation and phase sampling, combined by MIS, add up to the
// right answer; and the emitter seen directly, from its front (exactly Le) and from its back
// (exactly 0: one-sided and opaque).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "render/scene_upload.h"
#include "render_fixture.h"

namespace narval::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;

struct Vec {
  double x, y, z;
};
Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec operator*(double s, Vec a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double length(Vec a) { return std::sqrt(dot(a, a)); }

// The light shared by both tests: a 2.4 × 1.8 rectangle centred at C, rotated by `rotY` degrees
// about Y only (one axis, so no rotation-order convention enters the test). DESIGN.md: the unit quad
// lies in local XY and emits along local −Z. Ry(b) maps local X to (cos b, 0, −sin b), local Y to
// (0, 1, 0) and local −Z to (−sin b, 0, −cos b): for b = 170° the emission direction is
// n = (−0.174, 0, 0.985), towards +z (the slab) and slightly towards the axis.
constexpr double kRotY = 170.0, kSizeX = 2.4, kSizeY = 1.8;
const Vec kLightCentre = {0.6, 0.3, -3.0};
Vec lightAxisX() { return {std::cos(kRotY * kDegToRad), 0.0, -std::sin(kRotY * kDegToRad)}; }
Vec lightAxisY() { return {0.0, 1.0, 0.0}; }
Vec lightNormal() { return {-std::sin(kRotY * kDegToRad), 0.0, -std::cos(kRotY * kDegToRad)}; }

std::string lightJson() {
  return R"({"name": "panel", "type": "rectangle", "transform": {"position": [0.6, 0.3, -3.0],
             "rotation": [0, 170, 0], "scale": [2.4, 1.8, 1]}, "materialName": "panel"})";
}

// 8-point Gauss–Legendre on [−1, 1] (nodes ±x_i, weights w_i; exact for polynomials of degree 15).
const double kGlX[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
const double kGlW[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
// Nodes and weights of the composite rule with `panels` 8-point panels on [0, 1].
void gaussLegendre01(int panels, std::vector<double>* x, std::vector<double>* w) {
  x->clear();
  w->clear();
  for (int p = 0; p < panels; ++p) {
    const double a = double(p) / panels, half = 0.5 / panels;
    for (int i = 0; i < 8; ++i) {
      const double xi = i < 4 ? -kGlX[i] : kGlX[i - 4], wi = kGlW[i % 4];
      x->push_back(a + half * (1.0 + xi));
      w->push_back(half * wi);
    }
  }
}

// ---- single scattering from a rectangle light, with MIS ----
//
// Scene: homogeneous slab z ∈ [−h/2, h/2] (40 × 40 wide: infinite for every ray that matters),
// σs = 1, σa = 0.25 (normal optical depth τ = σt·h = 0.5, so ~40% of the camera paths scatter),
// HG g = −0.6; the light on the camera side (z = −3, centre off the view axis by (0.6, 0.3),
// tilted 10°), Le = 4; camera at z = −1.5 looking +z, between the light and the slab (a pinhole is
// not an occluder, and the light, behind it, is outside its view). Background 0, bounces = 1.
//
// With bounces = 1 the path tracer estimates the VRE (dissertation Eq. 3) truncated after one real
// scattering event:
//   L(pixel) = ∫_{t0}^{t1} T_v(t) σs ∫_A p(μ) Le T_l(x, y) cos θ_l / |x − y|² dA(y) dt,
// x = o + t·d, T_v(t) = e^{−σt (t − t0)} (camera → x inside the slab), T_l = e^{−σt ℓ} with
// ℓ = (x_z + h/2)/(−ω_z) the length inside the slab of x → y (ω = (y − x)/|y − x|; the light is
// on the −z side of the slab), cos θ_l = n·(−ω) (n the emission direction: the light is one-sided), and
// μ = ω·d: the light propagates along −ω, then scatters into −d (towards the camera), and the HG
// angle is between those two propagation directions, cos = (−ω)·(−d) (DESIGN.md convention).
// The camera ray direction is d and the light lies behind the camera, so μ ≈ −0.98 towards its
// centre: the light is seen in back-scattering. That is why g is negative: with g = −0.6, seen from
// the slab's centre, the light subtends 43° × 33° (Ω = 0.41 sr, so the light's solid-angle pdf is
// ≈ 1/Ω = 2.4 /sr) and the phase pdf averages 0.52 /sr over it: phase sampling hits the light in 21%
// of the scattered paths, and under the power heuristic the phase-sampling strategy carries 6.0% of
// the answer, NEE 94.0% (both measured with this quadrature, splitting each area point's
// contribution by its MIS weight). With g = +0.6 the phase pdf towards the light would be 0.013 and
// phase sampling would carry 3e-5 of the answer: the test could not see that term. Here a missing
// phase-sampling term (−6%), NEE without its MIS weight (+6%) or light hits without theirs (~+94%)
// are far outside the 1% tolerance (the standard error is ~0.1%).
//
// Reference quadrature: per pixel, 2 × 2 sub-pixel positions (the render jitters uniformly inside
// the pixel), 8-point Gauss–Legendre in t, 2 × 2 panels of 8 × 8 Gauss–Legendre nodes on the light.
// Measured: 4 × 4 sub-pixels move the image mean by 9e-6 relative; doubling the t or light nodes
// moves it by < 1e-12.
struct SlabParams {
  double sigmaS = 1.0, sigmaA = 0.25, g = -0.6, h = 0.4, Le = 4.0;
};

double hg(double g, double mu) { return (1 - g * g) / (4 * kPi * std::pow(1 + g * g - 2 * g * mu, 1.5)); }

std::vector<double> singleScatterReference(const SlabParams& P, const camera_params& c, int sub, int tPanels,
                                           int areaPanels) {
  const double sigmaT = P.sigmaS + P.sigmaA;
  const int W = c.width, H = c.height;
  const Vec o = {c.position.x, c.position.y, c.position.z};
  const Vec fwd = {c.forward.x, c.forward.y, c.forward.z}, right = {c.right.x, c.right.y, c.right.z},
            up = {c.up.x, c.up.y, c.up.z};
  std::vector<double> tx, tw, ax, aw;
  gaussLegendre01(tPanels, &tx, &tw);
  gaussLegendre01(areaPanels, &ax, &aw);
  const Vec ex = lightAxisX(), ey = lightAxisY(), n = lightNormal();
  const double area = kSizeX * kSizeY;
  // Light points and weights (dA = area · du dv on the unit square).
  std::vector<Vec> ys;
  std::vector<double> yw;
  for (size_t i = 0; i < ax.size(); ++i)
    for (size_t j = 0; j < ax.size(); ++j) {
      ys.push_back(kLightCentre + ((ax[i] - 0.5) * kSizeX) * ex + ((ax[j] - 0.5) * kSizeY) * ey);
      yw.push_back(aw[i] * aw[j] * area);
    }
  std::vector<double> ref(size_t(W) * H, 0.0);
  for (int py = 0; py < H; ++py)
    for (int px = 0; px < W; ++px) {
      double pixel = 0;
      for (int s = 0; s < sub * sub; ++s) {
        const double fx = px + (s % sub + 0.5) / sub, fy = py + (s / sub + 0.5) / sub;
        const double sx = (2 * fx / W - 1) * c.tan_half_vfov * c.aspect, sy = (1 - 2 * fy / H) * c.tan_half_vfov;
        Vec d = fwd + sx * right + sy * up;
        d = (1 / length(d)) * d;
        const double t0 = (-P.h / 2 - o.z) / d.z, t1 = (P.h / 2 - o.z) / d.z;
        double sum = 0;
        for (size_t k = 0; k < tx.size(); ++k) {
          const double t = t0 + tx[k] * (t1 - t0);
          const Vec x = o + t * d;
          double inscatter = 0;  // ∫_A p Le T_l cos θ_l / r² dA
          for (size_t m = 0; m < ys.size(); ++m) {
            const Vec toLight = ys[m] - x;
            const double r = length(toLight);
            const Vec w = (1 / r) * toLight;
            const double cosL = -dot(n, w);
            if (cosL <= 0) continue;
            const double ell = (x.z + P.h / 2) / (-w.z);
            inscatter += yw[m] * hg(P.g, dot(w, d)) * P.Le * std::exp(-sigmaT * ell) * cosL / (r * r);
          }
          sum += tw[k] * std::exp(-sigmaT * (t - t0)) * P.sigmaS * inscatter;
        }
        pixel += sum * (t1 - t0) / (sub * sub);
      }
      ref[size_t(py) * W + px] = pixel;
    }
  return ref;
}

// The slab and light of SlabParams seen from the camera of the reference, with `renderer` (a JSON
// object) as the scene's renderer block.
Scene lightSlabScene(const std::string& renderer) {
  return sceneFromJson(R"({
    "materials": [
      {"name": "panel", "type": "emitter", "albedo": [4, 4, 4]},
      {"name": "haze", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.25, 0.25, 0.25],
       "phaseFunction": "hg", "g": -0.6, "density": 1}
    ],
    "primitives": [
      )" + lightJson() + R"(,
      {"name": "slab", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [40, 40, 0.4]},
       "materialName": "haze"}
    ],
    "camera": {"position": [0, 0, -1.5], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 20},
    "renderer": )" + renderer + R"(
  })");
}

TEST(RenderAreaLight, SingleScatteringWithMisMatchesQuadrature) {
  const SlabParams P;
  Scene scene = lightSlabScene(R"({"resolution": [16, 16], "spp": 8192, "bounces": 1})");
  const DeviceScene ds = buildDeviceScene(scene, nullptr);
  // The uploaded light is the one the reference integrates (independent derivation above).
  ASSERT_EQ(ds.params.num_lights, 1);
  const light_params& l = ds.lights[0];
  const Vec n = lightNormal();
  EXPECT_NEAR(l.normal.x, n.x, 1e-6);
  EXPECT_NEAR(l.normal.y, n.y, 1e-6);
  EXPECT_NEAR(l.normal.z, n.z, 1e-6);
  EXPECT_NEAR(l.normal.w, kSizeX * kSizeY, 1e-5);

  const RenderResult r = render(scene);
  const camera_params& c = ds.params.camera;
  const std::vector<double> ref = singleScatterReference(P, c, 2, 1, 2);
  const size_t np = ref.size();

  // Image means, and the standard error of the rendered mean from the per-pixel deviations from the
  // reference (the pixels' expectations differ, their noise is independent). The 1% tolerance must
  // be at least 4 standard errors, else the test would be too noisy to mean anything: asserted too.
  double meanRender = 0, meanRef = 0;
  for (size_t i = 0; i < np; ++i) {
    meanRender += r.image.rgb[i * 3] / double(np);
    meanRef += ref[i] / double(np);
  }
  MeanAccumulator dev;
  for (size_t i = 0; i < np; ++i) dev.add(r.image.rgb[i * 3] - ref[i]);
  const double stderrMean = dev.result().se;
  EXPECT_LT(4 * stderrMean, 0.01 * meanRef) << "too noisy for a 1% test";
  EXPECT_NEAR(meanRender, meanRef, 0.01 * meanRef) << "standard error " << stderrMean;
  RecordProperty("relative_error", std::to_string((meanRender - meanRef) / meanRef));
  RecordProperty("relative_standard_error", std::to_string(stderrMean / meanRef));
  // Grey light and medium: the three channels carry the same estimate.
  EXPECT_EQ(r.image.rgb[0], r.image.rgb[1]);
  EXPECT_EQ(r.stats.status, 0u);
  EXPECT_EQ(r.stats.nanPixels, 0);
}

// ---- the ray marcher's phase over the same light ----
//
// The same slab and light, rendered by the ray marcher (single scattering, one ray through each
// pixel centre) against the quadrature at pixel centres (sub = 1). With areaLightPhase "exact" the
// phase is integrated over the light's solid angle in closed form (kernels/shared/phase_polygon.h);
// what separates the march from the quadrature is then only its shadow, one transmittance for the
// whole light (the effective column over K×K points, march_light_column) instead of one per point,
// and its step rule. Here the shadow rays' lengths in the slab, (x_z + h/2)/(−ω_z), differ by < 7%
// across the light (ω within 22° of −z), so the transmittance by < 3.5% (σt·ℓ ≤ 0.5) and the error
// of replacing each point's by their weighted mean is second order in that spread (with the step
// rule's error, 128 steps): measured 0.32% a pixel at most, asserted at 0.5%. The light's centre
// alone (areaLightSamples 1, the dissertation's point light, intensity Le·A·cos θ) misses how the
// phase and 1/d² change across the light's 43° × 33° seen from 1.5–2 units: measured 23% off or more
// in every pixel, asserted > 10% so that the test tells the two apart.
TEST(RenderAreaLight, RaymarchExactPhaseMatchesQuadrature) {
  const SlabParams P;
  auto scene = [](const std::string& phase) {
    return lightSlabScene(R"({"resolution": [16, 16], "algorithm": "raymarch", "bounces": 1, "lightCache": {"resolution": 0},
                         "raymarch": {"multipleScattering": "none", "steps": 128, "shadowSteps": 16, "shadowAreaSamples": 8, "minTransmittance": 0, )" +
                     phase + "}}");
  };
  const Scene exact = scene(R"("areaLightPhase": "exact")");
  const Scene centre = scene(R"("areaLightSamples": 1)");
  const camera_params c = buildDeviceScene(exact, nullptr).params.camera;
  const std::vector<double> ref = singleScatterReference(P, c, 1, 2, 2);
  const RenderResult re = renderAlgorithm(exact), rc = renderAlgorithm(centre);
  ASSERT_EQ(re.stats.status, 0u);
  ASSERT_EQ(rc.stats.status, 0u);
  double worstExact = 0, bestCentre = 1e30;
  for (size_t i = 0; i < ref.size(); ++i) {
    const double e = std::fabs(re.image.rgb[i * 3] / ref[i] - 1), k = std::fabs(rc.image.rgb[i * 3] / ref[i] - 1);
    EXPECT_LT(e, 0.005) << "exact phase, pixel " << i % 16 << "," << i / 16;
    EXPECT_GT(k, 0.10) << "light centre, pixel " << i % 16 << "," << i / 16;
    worstExact = std::max(worstExact, e);
    bestCentre = std::min(bestCentre, k);
  }
  std::printf("[ area light ] ray marcher against the quadrature: exact phase within %.3f%% a pixel, "
              "the centre off by at least %.2f%%\n",
              100 * worstExact, 100 * bestCentre);
}

// ---- the emitter seen directly ----
//
// The same light alone (no medium), background b = (0.25, 0.5, 0.75), Le = (3, 2, 1). A camera at
// C ± 4n looking at the centre C, up = +y, sees the light face-on: n is perpendicular to y, so the
// camera axes are ±(light X axis), y and ∓n, and a point C + X·ex + Y·ey maps to the image-plane
// coordinates (|sx|, sy) = (|X|, Y)/4. The light is |X| ≤ 1.2, |Y| ≤ 0.9, i.e. |sx| ≤ 0.3,
// |sy| ≤ 0.225; with tan(vfov/2) = 0.5 (vfov = 2·atan(0.5)) on 16 × 16 pixels, sx = (2fx/16 − 1)·0.5,
// so the light covers fx ∈ [3.2, 12.8] and fy ∈ [4.4, 11.6]: pixels 4..11 × 5..10 lie wholly on it,
// columns 3 and 12 and rows 4 and 11 are partly on it, the rest wholly off it.
// From the front (C + 4n, on the emitting side): every sample of a wholly covered pixel hits the
// front of the rectangle with throughput 1 and no MIS (the ray left the camera), so it is exactly
// Le; a pixel wholly off sees the background exactly. From behind (C − 4n): the rectangle is
// opaque and emits only along n, so the covered pixels are exactly 0 (the background behind the
// light is hidden), the others exactly b. Partly covered pixels lie between (per channel).
enum class Cover { Full, None, Partial };
Cover coverage(int px, int py) {
  auto range = [](int p, double lo, double hi) {
    return (p >= lo && p + 1 <= hi) ? Cover::Full : (p + 1 <= lo || p >= hi) ? Cover::None : Cover::Partial;
  };
  const Cover cx = range(px, 3.2, 12.8), cy = range(py, 4.4, 11.6);
  if (cx == Cover::None || cy == Cover::None) return Cover::None;
  return cx == Cover::Full && cy == Cover::Full ? Cover::Full : Cover::Partial;
}

void checkDirectView(bool front) {
  const Vec n = lightNormal(), cam = kLightCentre + (front ? 4.0 : -4.0) * n;
  const std::string json = R"({
    "materials": [{"name": "panel", "type": "emitter", "albedo": [3, 2, 1]}],
    "primitives": [)" + lightJson() + R"(],
    "camera": {"position": [)" + std::to_string(cam.x) + ", " + std::to_string(cam.y) + ", " +
                           std::to_string(cam.z) + R"(], "lookAt": [0.6, 0.3, -3.0], "up": [0, 1, 0],
               "vfov": )" + std::to_string(2 * std::atan(0.5) / kDegToRad) + R"(},
    "renderer": {"resolution": [16, 16], "spp": 64, "bounces": 4},
    "background": [0.25, 0.5, 0.75]
  })";
  const RenderResult r = render(sceneFromJson(json));
  const float le[3] = {3, 2, 1}, bg[3] = {0.25f, 0.5f, 0.75f};
  int counts[3] = {0, 0, 0};
  for (int py = 0; py < 16; ++py)
    for (int px = 0; px < 16; ++px) {
      const Cover cover = coverage(px, py);
      ++counts[int(cover)];
      for (int ch = 0; ch < 3; ++ch) {
        const float v = r.image.rgb[size_t(py * 16 + px) * 3 + ch];
        const float on = front ? le[ch] : 0.0f;
        if (cover == Cover::Full) EXPECT_EQ(v, on) << "pixel " << px << "," << py << " channel " << ch;
        if (cover == Cover::None) EXPECT_EQ(v, bg[ch]) << "pixel " << px << "," << py << " channel " << ch;
        if (cover == Cover::Partial) {
          EXPECT_GT(v, std::min(on, bg[ch])) << "pixel " << px << "," << py << " channel " << ch;
          EXPECT_LT(v, std::max(on, bg[ch])) << "pixel " << px << "," << py << " channel " << ch;
        }
      }
    }
  EXPECT_EQ(counts[int(Cover::Full)], 8 * 6);
  EXPECT_EQ(counts[int(Cover::Partial)], 2 * 8 + 2 * 10 - 4);
  EXPECT_EQ(r.stats.status, 0u);
}

TEST(RenderAreaLight, SeenFromTheFrontIsExactlyLe) { checkDirectView(true); }
TEST(RenderAreaLight, SeenFromBehindIsBlackAndOpaque) { checkDirectView(false); }

}  // namespace
}  // namespace narval::test
