// Geometric hard cases (issue 5) for the path tracer, the ray marcher and the lobe renderer: the
// camera inside the medium, rays running along box faces, edges and through corners, rotated boxes,
// a point light inside the medium, degenerate and extreme image sizes, and a one-voxel grid. Each
// expectation is derived beside its test. Images are tiny so the file runs in a few seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "render/realtime_renderer.h"
#include "render/scene_upload.h"
#include "render_fixture.h"
#include "shared/grid.h"
#include "unit/host_context.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

const auto& kAlgorithms = kHardCaseRenderers;


// The ray mapped into index space by world_to_index (an affine map: the world parameter t is kept).
struct IndexRay {
  double o[3], d[3];
};
IndexRay toIndex(const nv_affine& m, const Ray& r) {
  const double A[3][4] = {{m.row[0].x, m.row[0].y, m.row[0].z, m.row[0].w},
                          {m.row[1].x, m.row[1].y, m.row[1].z, m.row[1].w},
                          {m.row[2].x, m.row[2].y, m.row[2].z, m.row[2].w}};
  IndexRay q{};
  for (int k = 0; k < 3; ++k) {
    q.o[k] = A[k][0] * r.o[0] + A[k][1] * r.o[1] + A[k][2] * r.o[2] + A[k][3];
    q.d[k] = A[k][0] * r.d[0] + A[k][1] * r.d[1] + A[k][2] * r.d[2];
  }
  return q;
}

// [t0, t1] of the ray (t >= 0) inside the index box [0, n]³ (n = 1 for homogeneous boxes and for the
// one-voxel grid); t1 <= t0 when it misses. Slab test in double.
void boxSegment(const IndexRay& q, double n, double& t0, double& t1) {
  t0 = 0;
  t1 = INFINITY;
  for (int k = 0; k < 3; ++k) {
    if (q.d[k] == 0) {
      if (q.o[k] < 0 || q.o[k] > n) t1 = -1;
      continue;
    }
    const double ta = (0 - q.o[k]) / q.d[k], tb = (n - q.o[k]) / q.d[k];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
}
double boxLength(const nv_affine& m, const Ray& r) {
  double t0, t1;
  boxSegment(toIndex(m, r), 1.0, t0, t1);
  return std::max(0.0, t1 - t0);
}

// Every value finite and >= 0, the image the requested size, status 0 and no NaN pixels.
void expectSane(const RenderResult& r, int W, int H, const std::string& what) {
  EXPECT_EQ(r.image.width, W) << what;
  EXPECT_EQ(r.image.height, H) << what;
  ASSERT_EQ(r.image.rgb.size(), size_t(W) * size_t(H) * 3) << what;
  size_t bad = 0;
  for (float v : r.image.rgb) bad += !(std::isfinite(v) && v >= 0.0f);
  EXPECT_EQ(bad, 0u) << what << ": non-finite or negative values";
  EXPECT_EQ(r.stats.status, 0u) << what;
  EXPECT_EQ(r.stats.nanPixels, 0) << what;
}

float pixel(const ImageRGB& img, int x, int y, int c) { return img.rgb[(size_t(y) * img.width + x) * 3 + c]; }

// Statistical check of a path-traced absorption-only image against per-pixel transmittances T_p
// (background 1, no lights): every path is a Bernoulli trial (analogue tracking absorbs or escapes
// with weight 1), so the image mean has variance Σ_p T_p(1 − T_p)/spp / N² (any estimator in [0, 1]
// with mean T has variance <= T(1 − T), so this bounds it). Assert 4.5σ (false failure ~7e-6).
void expectPathtraceMean(const RenderResult& r, const std::vector<double>& T, int spp, const std::string& what) {
  double mean = 0, var = 0;
  for (double t : T) {
    mean += t;
    var += t * (1 - t) / spp;
  }
  const double N = double(T.size());
  mean /= N;
  const double se = std::sqrt(var) / N;
  for (int ch = 0; ch < 3; ++ch) {
    const ChannelStats s = channelStats(r.image, ch);
    EXPECT_NEAR(s.mean, mean, 4.5 * se) << what << " channel " << ch << " (σ " << se << ")";
  }
  // The same per 4x4 tile (an image mean lets a mirrored or shifted image pass), at 5σ per tile and
  // channel: false alarm 6e-7 each, below 1e-4 over the at most 64 tiles × 3 channels here.
  const int W = r.image.width, H = r.image.height;
  for (int ty = 0; ty < H; ty += 4)
    for (int tx = 0; tx < W; tx += 4) {
      double tileT = 0, tileVar = 0, tile[3] = {0, 0, 0}, n = 0;
      for (int y = ty; y < std::min(H, ty + 4); ++y)
        for (int x = tx; x < std::min(W, tx + 4); ++x) {
          const double t = T[size_t(y) * W + x];
          tileT += t, tileVar += t * (1 - t) / spp, n += 1;
          for (int ch = 0; ch < 3; ++ch) tile[ch] += pixel(r.image, x, y, ch);
        }
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(tile[ch] / n, tileT / n, 5 * std::sqrt(tileVar) / n + 1e-9)
            << what << " tile " << tx / 4 << "," << ty / 4 << " channel " << ch;
    }
}

// Reference per pixel averaged over the pixel (the path tracer jitters inside it) by 4 × 4 rays.
std::vector<double> pixelAreaTransmittance(const camera_params& c, const nv_affine& m, double sigma) {
  std::vector<double> T(size_t(c.width) * c.height, 0.0);
  for (int py = 0; py < c.height; ++py)
    for (int px = 0; px < c.width; ++px)
      for (int sub = 0; sub < 16; ++sub) {
        const Ray ray = pixelRay(c, px + (sub % 4 + 0.5) / 4, py + (sub / 4 + 0.5) / 4);
        T[size_t(py) * c.width + px] += std::exp(-sigma * boxLength(m, ray)) / 16;
      }
  return T;
}

// ---- 1. Camera inside the medium ------------------------------------------------------------------
// A homogeneous absorbing box (σa = 0.5, σs = 0) 4 units wide around the camera at (0.3, −0.2, 0.5),
// looking along +z, no lights, background 1. Every view ray starts inside, so the radiance is
// L = 1 · exp(−σa · d_exit), d_exit the distance from the camera to where the ray leaves the box (the
// slab test with t0 clamped to 0). Rays reach the far face z = 2 (d ≈ 1.5/cos θ) or a side face.
// Raymarch: the midpoint rule with constant σ is exact up to float rounding: 1e-5 relative.
// Lobe: σs = 0 leaves L_b · Tr(x0 → P) with lobeRadius 0 and depthFactor ≫ box putting P at the exit
// (lobe_test.cpp's AbsorptionOnlyIsBeerLambert): exact up to rounding as well.
// Pathtrace: Bernoulli per path, see expectPathtraceMean.
std::string insideScene(const std::string& renderer) {
  return R"({
    "materials": [
      {"name": "absorber", "type": "volume", "scattering": [0, 0, 0], "absorption": [0.5, 0.5, 0.5],
       "phaseFunction": "isotropic", "density": 1}
    ],
    "primitives": [
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [4, 4, 4]},
       "materialName": "absorber"}
    ],
    "camera": {"position": [0.3, -0.2, 0.5], "lookAt": [0.3, -0.2, 5], "up": [0, 1, 0], "vfov": 60},
    "renderer": )" + renderer + R"(,
    "background": [1, 1, 1]
  })";
}
constexpr double kInsideSigma = 0.5;

TEST(HardCasesGeometry, CameraInsideVolumeRaymarchAndLobeAreBeerLambertToExit) {
  const Scene scene = sceneFromJson(
      insideScene(R"({"resolution": [9, 7], "lobe": {"depthFactor": 1000, "lobeRadius": 0}})"));
  const scene_params sp = buildDeviceScene(scene, nullptr).params;
  for (const char* algo : {"raymarch", "lobe+eq7", "lobe+corrected"}) {
    const RenderResult r = renderWith(scene, algo);
    expectSane(r, 9, 7, algo);
    double worst = 0;
    for (int py = 0; py < 7; ++py)
      for (int px = 0; px < 9; ++px) {
        const double d = boxLength(sp.medium.world_to_index, pixelRay(sp.camera, px + 0.5, py + 0.5));
        ASSERT_GT(d, 1.4);  // starts inside: at least the 1.5 to the far face, less slant
        const double expected = std::exp(-kInsideSigma * d);
        for (int ch = 0; ch < 3; ++ch) {
          const double got = pixel(r.image, px, py, ch);
          worst = std::max(worst, std::fabs(got / expected - 1));
          EXPECT_NEAR(got, expected, 1e-5 * expected) << algo << " pixel " << px << "," << py << " d " << d;
        }
      }
    std::printf("[ hard cases ] camera inside, %s: worst relative error %.2e\n", algo, worst);
  }
}

TEST(HardCasesGeometry, CameraInsideVolumePathtraceIsBeerLambertToExit) {
  const int spp = 2048;
  const Scene scene =
      sceneFromJson(insideScene(R"({"resolution": [8, 8], "spp": 2048, "bounces": 3})"));
  const scene_params sp = buildDeviceScene(scene, nullptr).params;
  const RenderResult r = render(scene);
  expectSane(r, 8, 8, "pathtrace");
  expectPathtraceMean(r, pixelAreaTransmittance(sp.camera, sp.medium.world_to_index, kInsideSigma), spp,
                      "camera inside");
}

// ---- 2. Rays along faces, edges and through corners --------------------------------------------------
// A unit box at the origin (faces x, y, z = ±0.5), scattering and absorbing, lit by a point light and
// seen against a rectangle light and background. A nearly orthographic camera (vfov 0.01° from 1000
// units away, odd resolution so the centre pixel's ray is exactly the forward axis) is placed so its
// centre ray runs exactly in the face plane x = 0.5, or along the edge x = y = 0.5, or (from (2,2,2))
// through the corners (0.5, 0.5, 0.5) and (−0.5, −0.5, −0.5). Whether the float slab test counts
// such a ray as inside or outside, the result must be finite with status 0. For the absorption-only
// version the marcher's value must further lie between L_b·e^{−σ·√3} (the longest chord of the
// cube) and L_b.
std::string grazingScene(const std::string& camera, const std::string& medium, const std::string& renderer) {
  return R"({
    "materials": [
      {"name": "light", "type": "emitter", "albedo": [2, 3, 4]},
      {"name": "bulb", "type": "emitter", "albedo": [20, 20, 20]},
      {"name": "fog", "type": "volume", )" + medium + R"(, "phaseFunction": "hg", "g": 0.3, "density": 1}
    ],
    "primitives": [
      {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 30], "scale": [400, 400, 1]},
       "materialName": "light"},
      {"name": "bulb", "type": "point", "transform": {"position": [1.5, 2, -1]}, "materialName": "bulb"},
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [1, 1, 1]},
       "materialName": "fog"}
    ],
    "camera": )" + camera + R"(,
    "renderer": )" + renderer + R"(,
    "background": [0.5, 0.5, 0.5]
  })";
}

const char* const kGrazingCameras[] = {
    // centre ray in the face plane x = 0.5
    R"({"position": [0.5, 0, -1000], "lookAt": [0.5, 0, 0], "up": [0, 1, 0], "vfov": 0.01})",
    // centre ray along the edge x = y = 0.5
    R"({"position": [0.5, 0.5, -1000], "lookAt": [0.5, 0.5, 0], "up": [0, 1, 0], "vfov": 0.01})",
    // centre ray in the face plane y = −0.5, camera close (wider spread of grazing directions)
    R"({"position": [0, -0.5, -3], "lookAt": [0, -0.5, 0], "up": [0, 1, 0], "vfov": 20})",
    // centre ray along the body diagonal through two corners
    R"({"position": [2, 2, 2], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 0.01})",
    // centre ray through the single corner (0.5, 0.5, −0.5) only, then away from the box
    R"({"position": [2.5, 2.5, -2.5], "lookAt": [0.5, 0.5, -0.5], "up": [0, 1, 0], "vfov": 0.01})",
};

TEST(HardCasesGeometry, RaysAlongFacesEdgesAndCornersAreFinite) {
  const std::string scattering = R"("scattering": [0.8, 0.8, 0.8], "absorption": [0.2, 0.2, 0.2])";
  for (const char* cam : kGrazingCameras)
    for (const char* algo : kAlgorithms) {
      const Scene scene =
          sceneFromJson(grazingScene(cam, scattering, R"({"resolution": [5, 5], "spp": 64, "bounces": 8})"));
      expectSane(renderWith(scene, algo), 5, 5, std::string(algo) + " camera " + cam);
    }
}

TEST(HardCasesGeometry, RaysAlongFacesEdgesAndCornersAbsorptionIsBounded) {
  const std::string absorbing = R"("scattering": [0, 0, 0], "absorption": [0.9, 0.9, 0.9])";
  const double lo = 0.5 * std::exp(-0.9 * std::sqrt(3.0)) * (1 - 1e-5);
  for (const char* cam : kGrazingCameras) {
    Scene scene = sceneFromJson(grazingScene(cam, absorbing, R"({"resolution": [5, 5]})"));
    scene.primitives.erase(scene.primitives.begin(), scene.primitives.begin() + 2);  // background only
    const RenderResult r = renderWith(scene, "raymarch");
    expectSane(r, 5, 5, std::string("raymarch camera ") + cam);
    for (float v : r.image.rgb) {
      EXPECT_GE(v, lo) << cam;
      EXPECT_LE(v, 0.5f) << cam;
    }
  }
}

// ---- 3. Rotated boxes -----------------------------------------------------------------------------
// An absorbing box (σa = 0.9) with half extents (0.4 across the rotation, 1 along the axis, 0.3 in z)
// rotated by θ about y (rotation [0, θ, 0], scale [0.8, 2, 0.6]) or about x (rotation [θ, 0, 0],
// scale [2, 0.8, 0.6]), seen along +z through its centre. In the box frame the centre ray's direction
// is (∓sin θ, 0, cos θ) (resp. (0, ±sin θ, cos θ)): a ray through the centre of a box leaves it after
// min_k(h_k/|u_k|), and enters as far behind, so the chord is d(θ) = 2·min(0.4/sin θ, 0.3/cos θ):
//   θ = 30°: min(0.8, 0.3464) → 0.6928 (through the z faces); 45°: min(0.5657, 0.4243) → 0.8485;
//   θ = 60°: min(0.4619, 0.6) → 0.9238 (through the rotated x faces).
// L = 1·exp(−σa·d) against background 1. Raymarch/lobe: the centre pixel of an odd-sized image is
// the forward axis exactly; exact to rounding (1e-5). Pathtrace: 8 × 8 pixels at vfov 0.05° from
// 10 units (a 0.009-unit footprint: path lengths differ by < 1e-4 across it), each pixel's reference
// from the slab test, which is itself checked against d(θ) at the centre.
std::string rotatedScene(const std::string& rotation, const std::string& scale, const std::string& renderer,
                         double vfov) {
  return R"({
    "materials": [
      {"name": "absorber", "type": "volume", "scattering": [0, 0, 0], "absorption": [0.9, 0.9, 0.9],
       "phaseFunction": "isotropic", "density": 1}
    ],
    "primitives": [
      {"name": "box", "type": "volume",
       "transform": {"position": [0, 0, 0], "scale": )" + scale + R"(, "rotation": )" + rotation + R"(},
       "materialName": "absorber"}
    ],
    "camera": {"position": [0, 0, -10], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": )" + std::to_string(vfov) + R"(},
    "renderer": )" + renderer + R"(,
    "background": [1, 1, 1]
  })";
}
constexpr double kRotSigma = 0.9;

struct RotCase {
  std::string rotation, scale;
  double theta;
};
std::vector<RotCase> rotCases() {
  std::vector<RotCase> v;
  for (int deg : {30, 45, 60}) {
    const std::string a = std::to_string(deg);
    v.push_back({"[0, " + a + ", 0]", "[0.8, 2, 0.6]", deg * kPi / 180});
    v.push_back({"[" + a + ", 0, 0]", "[2, 0.8, 0.6]", deg * kPi / 180});
  }
  return v;
}
double rotatedChord(double theta) { return 2 * std::min(0.4 / std::sin(theta), 0.3 / std::cos(theta)); }

TEST(HardCasesGeometry, RotatedBoxRaymarchAndLobeMatchAnalyticChord) {
  for (const RotCase& rc : rotCases()) {
    const Scene scene = sceneFromJson(rotatedScene(
        rc.rotation, rc.scale, R"({"resolution": [5, 5], "lobe": {"depthFactor": 1000, "lobeRadius": 0}})", 2));
    const scene_params sp = buildDeviceScene(scene, nullptr).params;
    const double d = rotatedChord(rc.theta);
    // The host slab test agrees with the closed form (checks the chord derivation and convention).
    EXPECT_NEAR(boxLength(sp.medium.world_to_index, pixelRay(sp.camera, 2.5, 2.5)), d, 1e-5) << rc.rotation;
    const double expected = std::exp(-kRotSigma * d);
    for (const char* algo : {"raymarch", "lobe+eq7", "lobe+corrected"}) {
      const RenderResult r = renderWith(scene, algo);
      expectSane(r, 5, 5, std::string(algo) + " rotation " + rc.rotation);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(pixel(r.image, 2, 2, ch), expected, 1e-5 * expected)
            << algo << " rotation " << rc.rotation << " chord " << d;
    }
  }
}

TEST(HardCasesGeometry, RotatedBoxPathtraceMatchesAnalyticChord) {
  const int spp = 2048;
  for (const RotCase& rc : rotCases()) {
    const Scene scene =
        sceneFromJson(rotatedScene(rc.rotation, rc.scale, R"({"resolution": [8, 8], "spp": 2048, "bounces": 3})", 0.05));
    const scene_params sp = buildDeviceScene(scene, nullptr).params;
    const std::vector<double> T = pixelAreaTransmittance(sp.camera, sp.medium.world_to_index, kRotSigma);
    for (double t : T) EXPECT_NEAR(t, std::exp(-kRotSigma * rotatedChord(rc.theta)), 2e-4) << rc.rotation;
    const RenderResult r = render(scene);
    expectSane(r, 8, 8, "pathtrace rotation " + rc.rotation);
    expectPathtraceMean(r, T, spp, "pathtrace rotation " + rc.rotation);
  }
}

// ---- 4. A point light inside the medium ----------------------------------------------------------
// A scattering box 3 units wide with a point light inside it: off-centre, and exactly at the box
// centre with the centre pixel's view ray passing through the light (r → 0 in the 1/r² term on that
// ray). Also the camera inside the same box. Finite, status 0, and the medium is lit (some pixel > 0).
std::string lightInsideScene(const std::string& light, const std::string& camera) {
  return R"({
    "materials": [
      {"name": "bulb", "type": "emitter", "albedo": [10, 10, 10]},
      {"name": "fog", "type": "volume", "scattering": [0.5, 0.5, 0.5], "absorption": [0.1, 0.1, 0.1],
       "phaseFunction": "hg", "g": 0.4, "density": 1}
    ],
    "primitives": [
      {"name": "bulb", "type": "point", "transform": {"position": )" + light + R"(}, "materialName": "bulb"},
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [3, 3, 3]},
       "materialName": "fog"}
    ],
    "camera": )" + camera + R"(,
    "renderer": {"resolution": [7, 5], "spp": 32, "bounces": 6}
  })";
}

void checkLightInside(const std::string& light, const std::string& camera) {
  for (const char* algo : kAlgorithms) {
    const RenderResult r = renderWith(sceneFromJson(lightInsideScene(light, camera)), algo);
    const std::string what = std::string(algo) + " light " + light + " camera " + camera;
    expectSane(r, 7, 5, what);
    EXPECT_GT(*std::max_element(r.image.rgb.begin(), r.image.rgb.end()), 0.0f) << what;
  }
}

TEST(HardCasesGeometry, PointLightInsideVolumeOffCentreIsFinite) {
  checkLightInside("[0.2, 0.1, 0.3]", R"({"position": [0, 0, -6], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 40})");
}

TEST(HardCasesGeometry, PointLightInsideVolumeWithCameraInsideIsFinite) {
  checkLightInside("[0.2, 0.1, 0.3]", R"({"position": [-0.4, 0, -0.5], "lookAt": [0, 0, 1], "up": [0, 1, 0], "vfov": 60})");
}

TEST(HardCasesGeometry, PointLightAtCentreOnAPixelRayIsFinite) {
  // 7 × 5 is odd both ways: the centre pixel's ray is the forward axis and passes through (0, 0, 0).
  checkLightInside("[0, 0, 0]", R"({"position": [0, 0, -6], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 40})");
}

// ---- 5. Extreme image sizes -----------------------------------------------------------------------
// 1 × 1 and 4096 × 16 (aspect 256, 65536 pixels) of a trivial scene: a small scattering box against
// background 1, 1 spp. The image has the requested size and every value is finite.
std::string trivialScene(int w, int h) {
  return R"({
    "materials": [
      {"name": "fog", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.2, 0.2, 0.2],
       "phaseFunction": "isotropic", "density": 1}
    ],
    "primitives": [
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [1, 1, 1]},
       "materialName": "fog"}
    ],
    "camera": {"position": [0, 0, -3], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 30},
    "renderer": {"resolution": [)" + std::to_string(w) + ", " + std::to_string(h) + R"(], "spp": 1, "bounces": 4},
    "background": [1, 1, 1]
  })";
}

TEST(HardCasesGeometry, ExtremeResolutionsRender) {
  for (const auto& wh : {std::pair<int, int>{1, 1}, std::pair<int, int>{4096, 16}})
    for (const char* algo : kAlgorithms) {
      const Scene scene = sceneFromJson(trivialScene(wh.first, wh.second));
      const RenderResult r = renderWith(scene, algo);
      expectSane(r, wh.first, wh.second, std::string(algo) + " " + std::to_string(wh.first) + "x" + std::to_string(wh.second));
      EXPECT_EQ(r.stats.width, wh.first);
      EXPECT_EQ(r.stats.height, wh.second);
    }
}

// ---- 6. A one-voxel grid ----------------------------------------------------------------------------
// DenseGrid 1 × 1 × 1 holding 1, filling the box (gridSpace "unit": index space [0, 1]³). Trilinear
// reconstruction with the voxel centre at 0.5 and 0 outside gives ρ(p) = Π_k (1 − |p_k − 0.5|) inside
// the box: 1 at the centre, falling linearly to ½ per axis at the faces (it would reach 0 only one
// voxel out, beyond the box). Along the centre ray (p_x = p_y = 0.5, p_z from 0 to 1):
// ∫ρ dp_z = ∫(1 − |z − ½|) dz = ¾, so with the box 2 units long in z the optical depth is
// σa·2·¾ = 0.9 (σa = 0.6) and T = e^{−0.9}. The host reference integrates grid_density (the host
// copy of the kernels' lookup, kernels/shared/grid.h) along each pixel ray in index space by the
// midpoint rule with 20000 steps (exact on each linear piece; the one kink costs < 1e-9).
// Raymarch: 64 steps (even), so the kink at the box middle falls on a step boundary along the centre
// ray and the midpoint rule is exact there up to rounding (1e-5); other pixels' rays are within
// 0.02° of it, assert 1e-4. Lobe (σs = 0, lobeRadius 0, depth ≫ box: Tr to the exit with 100 even
// shadow steps): the same, 1e-4. Pathtrace: 8 × 8 at vfov 0.05°, Bernoulli bound as above.
std::string voxelScene(const std::string& renderer, double vfov) {
  return R"({
    "materials": [
      {"name": "absorber", "type": "volume", "scattering": [0, 0, 0], "absorption": [0.6, 0.6, 0.6],
       "phaseFunction": "isotropic", "density": 1}
    ],
    "primitives": [
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [1.2, 0.8, 2]},
       "materialName": "absorber"}
    ],
    "camera": {"position": [0, 0, -10], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": )" + std::to_string(vfov) + R"(},
    "renderer": )" + renderer + R"(,
    "background": [1, 1, 1]
  })";
}
constexpr double kVoxelSigma = 0.6;

DenseGrid oneVoxel() {
  DenseGrid g;
  g.nx = g.ny = g.nz = 1;
  g.data = {1.0f};
  g.maxValue = 1.0f;
  return g;
}

double voxelTransmittance(const DenseGrid& g, const nv_affine& m, const Ray& r) {
  const grid_view view{g.data.data(), g.nx, g.ny, g.nz, nullptr};
  const IndexRay q = toIndex(m, r);
  double t0, t1;
  boxSegment(q, 1.0, t0, t1);
  if (t1 <= t0) return 1.0;
  const int steps = 20000;
  const double dt = (t1 - t0) / steps;
  double tau = 0;
  for (int k = 0; k < steps; ++k) {
    const double t = t0 + (k + 0.5) * dt;
    vec3 p;
    p.x = float(q.o[0] + t * q.d[0]);
    p.y = float(q.o[1] + t * q.d[1]);
    p.z = float(q.o[2] + t * q.d[2]);
    tau += grid_view_density(&view, p) * dt;
  }
  return std::exp(-kVoxelSigma * tau);
}

TEST(HardCasesGeometry, OneVoxelGridRaymarchAndLobeMatchQuadrature) {
  const DenseGrid g = oneVoxel();
  // Buffer storage: the shared float filter on every device. A GPU's image sampler quantises the
  // trilinear weights to 8 bits (grid_storage_test.cpp bounds that), which moved these pixels by up
  // to 0.3% on an H100, beyond the 1e-4 asked here.
  const Scene scene = sceneFromJson(voxelScene(
      R"({"resolution": [5, 5], "storage": "buffer", "raymarch": {"steps": 64, "shadowSteps": 10},
          "lobe": {"depthFactor": 1000, "lobeRadius": 0}})", 0.05));
  const scene_params sp = buildDeviceScene(scene, &g).params;
  const double centre = voxelTransmittance(g, sp.medium.world_to_index, pixelRay(sp.camera, 2.5, 2.5));
  EXPECT_NEAR(centre, std::exp(-kVoxelSigma * 2 * 0.75), 1e-6);  // the closed form above
  for (const char* algo : {"raymarch", "lobe+eq7", "lobe+corrected"}) {
    const RenderResult r = renderWith(scene, algo, &g);
    expectSane(r, 5, 5, algo);
    for (int py = 0; py < 5; ++py)
      for (int px = 0; px < 5; ++px) {
        const double expected =
            voxelTransmittance(g, sp.medium.world_to_index, pixelRay(sp.camera, px + 0.5, py + 0.5));
        const double tol = (px == 2 && py == 2 ? 1e-5 : 1e-4) * expected;
        for (int ch = 0; ch < 3; ++ch)
          EXPECT_NEAR(pixel(r.image, px, py, ch), expected, tol) << algo << " pixel " << px << "," << py;
      }
  }
}

TEST(HardCasesGeometry, OneVoxelGridPathtraceMatchesQuadrature) {
  const DenseGrid g = oneVoxel();
  const int spp = 2048;
  const Scene scene = sceneFromJson(voxelScene(R"({"resolution": [8, 8], "spp": 2048, "bounces": 3})", 0.05));
  const scene_params sp = buildDeviceScene(scene, &g).params;
  std::vector<double> T;
  for (int py = 0; py < 8; ++py)
    for (int px = 0; px < 8; ++px)
      T.push_back(voxelTransmittance(g, sp.medium.world_to_index, pixelRay(sp.camera, px + 0.5, py + 0.5)));
  const RenderResult r = render(scene, &g);
  expectSane(r, 8, 8, "pathtrace one voxel");
  expectPathtraceMean(r, T, spp, "pathtrace one voxel");
}

// A one-voxel grid with scattering and a light: every renderer finite with status 0.
TEST(HardCasesGeometry, OneVoxelGridScatteringIsFinite) {
  const DenseGrid g = oneVoxel();
  Scene scene = sceneFromJson(lightInsideScene(
      "[0.2, 0.1, 0.3]", R"({"position": [0, 0, -6], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 40})"));
  for (const char* algo : kAlgorithms) {
    const RenderResult r = renderWith(scene, algo, &g);
    expectSane(r, 7, 5, std::string(algo) + " one voxel, light inside");
    EXPECT_GT(*std::max_element(r.image.rgb.begin(), r.image.rgb.end()), 0.0f) << algo;
  }
}

}  // namespace
}  // namespace narval::test
