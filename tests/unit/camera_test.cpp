// camera_test.cpp: primary rays of kernels/shared/camera.h on the host (the very code the device
// compiles). A camera_params is built by hand; expectations come from the projection the header
// documents: for continuous pixel coordinates (px, py),
//   sx = (2px/W − 1)·tan(vfov/2)·aspect along `right`,  sy = (1 − 2py/H)·tan(vfov/2) along `up`,
//   dir = normalize(forward + sx·right + sy·up),
// whose inverse (the hand projection of a world point P seen from the camera at `position`) is
//   x_c = (P−pos)·right / (P−pos)·forward,  y_c = (P−pos)·up / (P−pos)·forward,
//   px = (x_c/(tan·aspect) + 1)·W/2,        py = (1 − y_c/tan)·H/2.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "shared/camera.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

struct D3 {
  double x, y, z;
};
D3 d3(vec3 v) { return {v.x, v.y, v.z}; }
D3 d3(nv_float4 v) { return {v.x, v.y, v.z}; }
D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 add(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 scale(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
D3 normalize(D3 a) { return scale(a, 1.0 / std::sqrt(dot(a, a))); }
nv_float4 f4(D3 a) { return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z), 0.0f}; }

// Distance from P to the ray's line (origin o, unit direction d).
double distanceToRay(D3 p, const ray3& r) {
  const D3 q = sub(p, d3(r.origin)), d = d3(r.dir);
  const D3 perp = sub(q, scale(d, dot(q, d)));
  return std::sqrt(dot(perp, perp));
}

// A camera at (1, 2, 3) looking along normalize(1, −0.5, 0.2) — no axis-aligned shortcut — with
// right = normalize(forward × ŷ) and up = right × forward (orthonormal, up has a +y component),
// 64 × 48 pixels (aspect 4/3), vfov 40°.
camera_params makeCamera(float lensRadius = 0.0f, float focusDistance = 1.0f) {
  const D3 fwd = normalize({1.0, -0.5, 0.2});
  const D3 right = normalize(cross(fwd, {0.0, 1.0, 0.0}));
  const D3 up = cross(right, fwd);
  camera_params c{};
  c.position = {1.0f, 2.0f, 3.0f, 0.0f};
  c.forward = f4(fwd);
  c.right = f4(right);
  c.up = f4(up);
  c.width = 64;
  c.height = 48;
  c.aspect = 64.0f / 48.0f;
  c.tan_half_vfov = static_cast<float>(std::tan(20.0 * kPi / 180.0));
  c.lens_radius = lensRadius;
  c.focus_distance = focusDistance;
  return c;
}

// The pixel (px, py) where world point P appears (the hand projection above), in double.
void project(const camera_params& c, D3 p, double* px, double* py) {
  const D3 q = sub(p, d3(c.position));
  const double z = dot(q, d3(c.forward));
  const double xc = dot(q, d3(c.right)) / z, yc = dot(q, d3(c.up)) / z;
  *px = (xc / (double(c.tan_half_vfov) * c.aspect) + 1.0) * 0.5 * c.width;
  *py = (1.0 - yc / c.tan_half_vfov) * 0.5 * c.height;
}

// The image centre (px, py) = (W/2, H/2) gives sx = sy = 0: the ray is `forward` from `position`.
TEST(CameraPinhole, CentreLooksForward) {
  const camera_params c = makeCamera();
  const ray3 r = camera_ray(&c, 32.0f, 24.0f, 0.5f, 0.5f);
  EXPECT_NEAR(r.dir.x, c.forward.x, 1e-6f);
  EXPECT_NEAR(r.dir.y, c.forward.y, 1e-6f);
  EXPECT_NEAR(r.dir.z, c.forward.z, 1e-6f);
  EXPECT_EQ(r.origin.x, c.position.x);
  EXPECT_EQ(r.origin.y, c.position.y);
  EXPECT_EQ(r.origin.z, c.position.z);
}

// World points in front of the camera, projected by hand to (px, py): the ray through (px, py)
// passes through the point. Float rounding of the direction (~1e-7 rad) over distances ≤ 20 keeps
// the miss distance below 1e-5. Then the reverse: the point at depth 7 on the centre of pixel
// (i, j) projects to (i + 0.5, j + 0.5) and is hit by the ray through it.
TEST(CameraPinhole, RayThroughProjectedPixelHitsThePoint) {
  const camera_params c = makeCamera();
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  int inside = 0;
  for (int k = 0; k < 500; ++k) {
    const double depth = 2.0 + 8.0 * (uni(gen) + 1.0);
    const D3 p = add(d3(c.position), add(scale(d3(c.forward), depth),
                                         add(scale(d3(c.right), uni(gen) * 0.5 * depth),
                                             scale(d3(c.up), uni(gen) * 0.35 * depth))));
    double px, py;
    project(c, p, &px, &py);
    if (px >= 0 && px < c.width && py >= 0 && py < c.height) ++inside;
    const ray3 r = camera_ray(&c, static_cast<float>(px), static_cast<float>(py), 0.5f, 0.5f);
    EXPECT_NEAR(vec3_length(r.dir), 1.0f, 1e-6f);
    EXPECT_LT(distanceToRay(p, r), 1e-5) << "px = " << px << ", py = " << py;
  }
  // right·0.5·depth at tan 20°·4/3 = 0.485 per unit depth: most points fall in the image.
  EXPECT_GT(inside, 400);

  const double t = std::tan(20.0 * kPi / 180.0), aspect = 4.0 / 3.0;
  for (int i : {0, 5, 31, 32, 63}) {
    for (int j : {0, 7, 23, 47}) {
      const double sx = (2.0 * (i + 0.5) / 64.0 - 1.0) * t * aspect, sy = (1.0 - 2.0 * (j + 0.5) / 48.0) * t;
      const D3 p = add(d3(c.position),
                       scale(add(d3(c.forward), add(scale(d3(c.right), sx), scale(d3(c.up), sy))), 7.0));
      double px, py;
      project(c, p, &px, &py);
      EXPECT_NEAR(px, i + 0.5, 1e-4);
      EXPECT_NEAR(py, j + 0.5, 1e-4);
      const ray3 r = camera_ray(&c, i + 0.5f, j + 0.5f, 0.5f, 0.5f);
      EXPECT_LT(distanceToRay(p, r), 1e-5) << "pixel (" << i << ", " << j << ")";
    }
  }
}

// Pixel (0,0) is the top left: its centre (0.5, 0.5) has sx = (1/64 − 1)·tan·aspect < 0 (towards
// −right) and sy = (1 − 1/48)·tan > 0 (towards +up); the bottom-right pixel the opposite. The exact
// corner (0, 0) is forward − tan·aspect·right + tan·up, normalised.
TEST(CameraPinhole, PixelZeroIsTopLeft) {
  const camera_params c = makeCamera();
  const D3 right = d3(c.right), up = d3(c.up), fwd = d3(c.forward);
  const ray3 tl = camera_ray(&c, 0.5f, 0.5f, 0.5f, 0.5f);
  EXPECT_LT(dot(d3(tl.dir), right), 0.0);
  EXPECT_GT(dot(d3(tl.dir), up), 0.0);
  const ray3 br = camera_ray(&c, 63.5f, 47.5f, 0.5f, 0.5f);
  EXPECT_GT(dot(d3(br.dir), right), 0.0);
  EXPECT_LT(dot(d3(br.dir), up), 0.0);

  const double t = c.tan_half_vfov, a = c.aspect;
  const D3 corner = normalize(add(fwd, add(scale(right, -t * a), scale(up, t))));
  const ray3 r = camera_ray(&c, 0.0f, 0.0f, 0.5f, 0.5f);
  EXPECT_NEAR(r.dir.x, corner.x, 1e-6);
  EXPECT_NEAR(r.dir.y, corner.y, 1e-6);
  EXPECT_NEAR(r.dir.z, corner.z, 1e-6);
}

// tan_half_vfov is the vertical half angle: the rays through the middle of the top edge (W/2, 0)
// and of the bottom edge (W/2, H) are 40° apart, and each is 20° from forward. Horizontally the
// half angle is atan(tan 20° · 4/3) = 25.88°.
TEST(CameraPinhole, FieldOfViewIsVertical) {
  const camera_params c = makeCamera();
  const ray3 top = camera_ray(&c, 32.0f, 0.0f, 0.5f, 0.5f), bottom = camera_ray(&c, 32.0f, 48.0f, 0.5f, 0.5f);
  const double deg = 180.0 / kPi;
  EXPECT_NEAR(std::acos(dot(d3(top.dir), d3(bottom.dir))) * deg, 40.0, 1e-3);
  EXPECT_NEAR(std::acos(dot(d3(top.dir), d3(c.forward))) * deg, 20.0, 1e-3);
  const ray3 left = camera_ray(&c, 0.0f, 24.0f, 0.5f, 0.5f);
  EXPECT_NEAR(std::acos(dot(d3(left.dir), d3(c.forward))) * deg,
              std::atan(std::tan(20.0 / deg) * 4.0 / 3.0) * deg, 1e-3);
}

// Thin lens (radius 0.2, focus 5): rays from different lens samples through the same pixel start
// on the lens disk (in the plane through `position` spanned by right and up, within the radius) and
// meet at the focus distance, on the plane (x − pos)·forward = 5, exactly where the pinhole ray
// through that pixel crosses it. They do not meet elsewhere: at depth 4 the spread is
// ≈ radius · (1 − 4/5) = 0.04 across the lens, far above the 1e-5 meeting tolerance.
TEST(CameraThinLens, RaysMeetAtTheFocusDistance) {
  const float radius = 0.2f, focus = 5.0f;
  const camera_params lens = makeCamera(radius, focus), pinhole = makeCamera();
  const D3 pos = d3(lens.position), fwd = d3(lens.forward);
  auto pointAtDepth = [&](const ray3& r, double depth) {
    const double s = (depth - dot(sub(d3(r.origin), pos), fwd)) / dot(d3(r.dir), fwd);
    return add(d3(r.origin), scale(d3(r.dir), s));
  };
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const std::vector<std::array<float, 2>> pixels = {{10.25f, 40.5f}, {32.0f, 24.0f}, {63.0f, 1.0f}};
  for (const std::array<float, 2>& pixel : pixels) {
    const D3 target = pointAtDepth(camera_ray(&pinhole, pixel[0], pixel[1], 0.0f, 0.0f), focus);
    double maxSpreadAt4 = 0.0;
    D3 first4{};
    for (int k = 0; k < 200; ++k) {
      const ray3 r = camera_ray(&lens, pixel[0], pixel[1], uni(gen), uni(gen));
      const D3 o = sub(d3(r.origin), pos);
      EXPECT_NEAR(dot(o, fwd), 0.0, 1e-6);
      EXPECT_LE(std::sqrt(dot(o, o)), radius * (1.0 + 1e-5));
      EXPECT_NEAR(vec3_length(r.dir), 1.0f, 1e-6f);
      const D3 p = pointAtDepth(r, focus), miss = sub(p, target);
      EXPECT_LT(std::sqrt(dot(miss, miss)), 1e-5) << "lens sample " << k;
      const D3 p4 = pointAtDepth(r, 4.0);
      if (k == 0) first4 = p4;
      const D3 spread = sub(p4, first4);
      maxSpreadAt4 = std::max(maxSpreadAt4, std::sqrt(dot(spread, spread)));
    }
    EXPECT_GT(maxSpreadAt4, 0.02);
  }
  // The lens centre (u, v) = (1/2, 1/2) maps to the disk centre: the pinhole ray itself.
  const ray3 centre = camera_ray(&lens, 20.0f, 20.0f, 0.5f, 0.5f), pin = camera_ray(&pinhole, 20.0f, 20.0f, 0.f, 0.f);
  EXPECT_EQ(centre.origin.x, pin.origin.x);
  EXPECT_NEAR(centre.dir.x, pin.dir.x, 1e-6f);
  EXPECT_NEAR(centre.dir.y, pin.dir.y, 1e-6f);
  EXPECT_NEAR(centre.dir.z, pin.dir.z, 1e-6f);
}

// camera_project is the hand projection above: world points in front of the camera land at the pixel
// the double-precision projection gives (within 1e-3 pixels in float), and the camera ray through that
// pixel passes through them; a point behind the camera or in its plane is refused.
TEST(CameraProject, InvertsTheRayThroughAPixel) {
  const camera_params c = makeCamera();
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> pixel(-8.0, 72.0), depth(0.5, 30.0);
  for (int k = 0; k < 200; ++k) {
    const double px = pixel(gen), py = pixel(gen) * 0.75;
    const ray3 r = camera_ray(&c, float(px), float(py), 0.5f, 0.5f);
    const D3 p = add(d3(r.origin), scale(d3(r.dir), depth(gen)));
    double ex, ey;
    project(c, p, &ex, &ey);
    float fx = -1, fy = -1;
    ASSERT_EQ(camera_project(&c, vec3_make(float(p.x), float(p.y), float(p.z)), &fx, &fy), 1);
    EXPECT_NEAR(fx, ex, 1e-3);
    EXPECT_NEAR(fy, ey, 1e-3);
    EXPECT_NEAR(fx, px, 1e-3);
    EXPECT_NEAR(fy, py, 1e-3);
  }
  const D3 behind = sub(d3(c.position), d3(c.forward)), beside = add(d3(c.position), d3(c.right));
  float fx, fy;
  EXPECT_EQ(camera_project(&c, vec3_make(float(behind.x), float(behind.y), float(behind.z)), &fx, &fy), 0);
  EXPECT_EQ(camera_project(&c, vec3_make(float(beside.x), float(beside.y), float(beside.z)), &fx, &fy), 0);
}

}  // namespace
