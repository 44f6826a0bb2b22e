#include "viewer/orbit_camera.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/trigonometric.hpp>

namespace narval {
namespace {

glm::vec3 toGlm(const Vec3f& v) { return {v[0], v[1], v[2]}; }
Vec3f toVec3f(const glm::vec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

OrbitCamera::OrbitCamera(const Camera& camera)
    : base_(camera), position_(toGlm(camera.position)), lookAt_(toGlm(camera.lookAt)), up_(toGlm(camera.up)) {
  minDistance_ = std::max(1e-4f, 1e-3f * distance());
}

Camera OrbitCamera::toCamera() const {
  Camera c = base_;
  c.position = toVec3f(position_);
  c.lookAt = toVec3f(lookAt_);
  c.up = toVec3f(up_);
  return c;
}

float OrbitCamera::distance() const { return glm::length(lookAt_ - position_); }
glm::vec3 OrbitCamera::forward() const { return glm::normalize(lookAt_ - position_); }
glm::vec3 OrbitCamera::right() const { return glm::normalize(glm::cross(forward(), up_)); }

void OrbitCamera::orbit(float yawDegrees, float pitchDegrees) {
  const glm::vec3 upAxis = glm::normalize(up_);
  glm::vec3 offset = position_ - lookAt_;  // from the look-at point to the camera
  const float d = glm::length(offset);
  // Pitch first (positive: the camera goes down, its polar angle from `up` grows), limited so that
  // the polar angle stays within [1, 179] degrees; a camera already beyond that may only go back.
  const float polar = glm::degrees(std::acos(std::clamp(glm::dot(offset / d, upAxis), -1.0f, 1.0f)));
  const float pitch = std::clamp(pitchDegrees, std::min(0.0f, 1.0f - polar), std::max(0.0f, 179.0f - polar));
  offset = glm::angleAxis(glm::radians(pitch), right()) * offset;
  offset = glm::angleAxis(glm::radians(-yawDegrees), upAxis) * offset;
  position_ = lookAt_ + glm::normalize(offset) * d;
}

void OrbitCamera::pan(float rightAmount, float upAmount) {
  const float height = 2.0f * distance() * std::tan(glm::radians(0.5f * base_.vfov));
  const glm::vec3 r = right(), u = glm::cross(r, forward());
  const glm::vec3 move = (rightAmount * r + upAmount * u) * height;
  position_ += move;
  lookAt_ += move;
}

void OrbitCamera::zoom(float factor) {
  const float d = std::max(minDistance_, distance() * factor);
  position_ = lookAt_ - forward() * d;
}

void OrbitCamera::fly(const glm::vec3& axes, float seconds) {
  const glm::vec3 f = forward(), r = right(), u = glm::cross(r, f);
  const glm::vec3 move = (axes.x * r + axes.y * u + axes.z * f) * (base_.speed * seconds);
  position_ += move;
  lookAt_ += move;
}

void OrbitCamera::frame(const glm::vec3& lo, const glm::vec3& hi, float aspect) {
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = 0.5f * glm::length(hi - lo);
  // The sphere fits when its radius subtends at most half the narrower field of view.
  const float halfV = glm::radians(0.5f * base_.vfov);
  const float halfH = std::atan(std::tan(halfV) * aspect);
  const float d = radius / std::sin(std::min(halfV, halfH));
  const glm::vec3 f = forward();
  lookAt_ = centre;
  position_ = centre - f * d;
  minDistance_ = std::max(1e-4f, 1e-3f * d);
}

}  // namespace narval
