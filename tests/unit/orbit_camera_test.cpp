// The viewer's camera controls: each move checked against its geometry.
#include "viewer/orbit_camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

namespace narval {
namespace {

Camera sceneCamera() {
  Camera c;
  c.position = {0, 0, -20};
  c.lookAt = {0, 0, 0};
  c.up = {0, 1, 0};
  c.vfov = 45;
  c.speed = 3;
  return c;
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(OrbitCamera, YawTurnsAroundTheLookAtPointKeepingTheDistance) {
  OrbitCamera cam(sceneCamera());
  // Yaw +90 about +y, applied as a rotation of -90 degrees to the offset (0, 0, -20):
  // x' = x cos(-90) + z sin(-90) = 20, z' = -x sin(-90) + z cos(-90) = 0. The camera goes to the
  // image's left (image +x is world -x here: right = forward x up = (-1, 0, 0)), so the medium
  // turns with a mouse dragged to the right.
  cam.orbit(90, 0);
  expectNear(cam.position(), {20, 0, 0}, 1e-4f);
  expectNear(cam.lookAt(), {0, 0, 0}, 0);
  cam.orbit(37, -12);
  EXPECT_NEAR(cam.distance(), 20.0f, 1e-4f);
  expectNear(cam.lookAt(), {0, 0, 0}, 0);
}

TEST(OrbitCamera, PitchStopsOneDegreeFromThePoles) {
  OrbitCamera cam(sceneCamera());
  cam.orbit(0, 500);  // down past the pole: stops at a polar angle of 179 degrees from +y
  const glm::vec3 offset = glm::normalize(cam.position() - cam.lookAt());
  EXPECT_NEAR(std::acos(offset.y) * 180.0 / M_PI, 179.0, 1e-3);
  cam.orbit(0, -500);  // and up: 1 degree
  const glm::vec3 up = glm::normalize(cam.position() - cam.lookAt());
  EXPECT_NEAR(std::acos(up.y) * 180.0 / M_PI, 1.0, 1e-3);
  EXPECT_NEAR(cam.distance(), 20.0f, 1e-3f);
  cam.orbit(0, 30);  // a pitch of +30 from the upper limit lands at 31 degrees
  const glm::vec3 after = glm::normalize(cam.position() - cam.lookAt());
  EXPECT_NEAR(std::acos(after.y) * 180.0 / M_PI, 31.0, 1e-3);
}

TEST(OrbitCamera, PanMovesCameraAndLookAtByImageHeights) {
  OrbitCamera cam(sceneCamera());
  // One image height at distance 20 with vfov 45: 2 · 20 · tan(22.5°) = 16.5685.
  const float height = 2.0f * 20.0f * std::tan(22.5f * float(M_PI) / 180.0f);
  cam.pan(0.5f, 0.25f);  // image right is world -x, image up world +y
  expectNear(cam.lookAt(), {-0.5f * height, 0.25f * height, 0}, 1e-4f);
  expectNear(cam.position(), {-0.5f * height, 0.25f * height, -20}, 1e-4f);
}

TEST(OrbitCamera, ZoomScalesTheDistanceWithAFloor) {
  OrbitCamera cam(sceneCamera());
  cam.zoom(0.5f);
  expectNear(cam.position(), {0, 0, -10}, 1e-5f);
  cam.zoom(1e-9f);  // never closer than 1e-3 of the first distance: 0.02
  EXPECT_NEAR(cam.distance(), 0.02f, 1e-6f);
  expectNear(cam.lookAt(), {0, 0, 0}, 0);
}

TEST(OrbitCamera, FlyMovesAtTheCameraSpeed) {
  OrbitCamera cam(sceneCamera());
  cam.fly({0, 0, 1}, 2.0f);  // W for 2 s at speed 3: 6 units forward (+z)
  expectNear(cam.position(), {0, 0, -14}, 1e-5f);
  expectNear(cam.lookAt(), {0, 0, 6}, 1e-5f);
  cam.fly({1, 1, 0}, 1.0f);  // D and E for 1 s: 3 to the image's right (world -x) and 3 up
  expectNear(cam.position(), {-3, 3, -14}, 1e-5f);
}

TEST(OrbitCamera, FrameFitsTheBoxBoundingSphere) {
  OrbitCamera cam(sceneCamera());
  cam.orbit(30, 0);
  const glm::vec3 direction = glm::normalize(cam.lookAt() - cam.position());
  cam.frame({1, 1, 1}, {3, 5, 3}, 2.0f);
  // Centre (2, 3, 2); radius |(2, 4, 2)| / 2 = sqrt(6); the vertical half-angle (22.5°) is the
  // narrower at aspect 2, so the distance is sqrt(6) / sin(22.5°) = 6.4007.
  expectNear(cam.lookAt(), {2, 3, 2}, 1e-5f);
  EXPECT_NEAR(cam.distance(), std::sqrt(6.0f) / std::sin(22.5f * float(M_PI) / 180.0f), 1e-4f);
  expectNear(glm::normalize(cam.lookAt() - cam.position()), direction, 1e-5f);
  // A tall image (aspect 0.5): the horizontal half-angle atan(tan(22.5°) · 0.5) = 11.701° limits.
  cam.frame({1, 1, 1}, {3, 5, 3}, 0.5f);
  EXPECT_NEAR(cam.distance(), std::sqrt(6.0f) / std::sin(std::atan(std::tan(22.5f * float(M_PI) / 180.0f) * 0.5f)),
              1e-3f);
}

TEST(OrbitCamera, ToCameraKeepsTheLensAndSpeed) {
  Camera c = sceneCamera();
  c.aperture = 0.3f;
  c.focus = 7;
  OrbitCamera cam(c);
  cam.orbit(10, 5);
  const Camera out = cam.toCamera();
  EXPECT_EQ(out.vfov, 45.0f);
  EXPECT_EQ(out.aperture, 0.3f);
  EXPECT_EQ(out.focus, 7.0f);
  EXPECT_EQ(out.speed, 3.0f);
  EXPECT_EQ(out.position[0], cam.position().x);
  EXPECT_EQ(out.lookAt[2], cam.lookAt().z);
}

}  // namespace
}  // namespace narval
