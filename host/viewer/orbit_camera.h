// orbit_camera.h: the viewer's camera controls (GLM): orbit, pan and zoom around the look-at point,
// flying at camera.speed, and framing the medium's box. Everything is in the scene's world units
// and degrees; the result goes back into the scene's Camera, so `narval render` of a scene written
// from it draws the same view.
#pragma once

#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace narval {

class OrbitCamera {
 public:
  explicit OrbitCamera(const Camera& camera);
  // The scene's camera with this position, look-at point and up vector (vfov, lens, speed kept).
  Camera toCamera() const;

  // Turns the camera around the look-at point: `yawDegrees` about the up vector, `pitchDegrees`
  // about the camera's right axis; the view direction stays at least 1 degree away from ±up, where
  // the look-at frame would be undefined. The distance to the look-at point is kept.
  void orbit(float yawDegrees, float pitchDegrees);
  // Moves camera and look-at point together within the image plane: `right` and `up` are fractions
  // of the image height at the look-at distance (a drag of the full window height moves the view by
  // one image height at that distance).
  void pan(float right, float up);
  // Multiplies the distance to the look-at point by `factor` (> 0); it stays at least 1e-3 of its
  // original value and at least 1e-4 world units.
  void zoom(float factor);
  // Flies camera and look-at point by `seconds` · camera.speed along the camera's right, up and
  // forward axes weighted by `axes` (e.g. (0, 0, 1) for W, (-1, 0, 0) for A).
  void fly(const glm::vec3& axes, float seconds);
  // Looks at the centre of the box [lo, hi] from the current direction, at the distance where the
  // box's bounding sphere fits the vertical field of view and the image's `aspect` (width/height).
  void frame(const glm::vec3& lo, const glm::vec3& hi, float aspect);

  const glm::vec3& position() const { return position_; }
  const glm::vec3& lookAt() const { return lookAt_; }
  const glm::vec3& up() const { return up_; }
  float distance() const;

 private:
  glm::vec3 forward() const;
  glm::vec3 right() const;
  Camera base_;
  glm::vec3 position_, lookAt_, up_;
  float minDistance_;
};

}  // namespace narval
