#include "camera_navigation.h"

#include <algorithm>
#include <cmath>

namespace visopt::ws {

namespace {
constexpr float kDegree = 3.14159265358979f / 180.f;
}

Camera orbitCamera(const Camera& camera, float azimuthDeg, float elevationDeg) {
  const glm::vec3 offset = camera.eye - camera.target;
  const float r = glm::length(offset);
  if (r <= 0.f) return camera;
  float az = std::atan2(offset.x, -offset.y);  // 0 when the eye is on -y (Camera::orbit)
  float el = std::asin(std::clamp(offset.z / r, -1.f, 1.f));
  az -= azimuthDeg * kDegree;
  el = std::clamp(el + elevationDeg * kDegree, -89.f * kDegree, 89.f * kDegree);
  Camera out = camera;
  out.eye = camera.target +
            r * glm::vec3(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el));
  out.up = glm::vec3(0.f, 0.f, 1.f);
  return out;
}

Camera panCamera(const Camera& camera, glm::vec2 delta) {
  const glm::vec3 forward = camera.forward();
  glm::vec3 right = glm::cross(forward, camera.up);
  if (glm::length(right) < 1e-6f) return camera;
  right = glm::normalize(right);
  const glm::vec3 up = glm::cross(right, forward);
  const float distance = glm::length(camera.target - camera.eye);
  const float viewHeight = 2.f * distance * std::tan(0.5f * camera.fovYDegrees * kDegree);
  const glm::vec3 shift = viewHeight * (-delta.x * right + delta.y * up);
  Camera out = camera;
  out.eye += shift;
  out.target += shift;
  return out;
}

Camera zoomCamera(const Camera& camera, float factor, float minDistance, float maxDistance) {
  if (!(factor > 0.f)) return camera;
  const glm::vec3 offset = camera.eye - camera.target;
  const float r = glm::length(offset);
  if (r <= 0.f) return camera;
  const float next = std::clamp(r / factor, minDistance, maxDistance);
  Camera out = camera;
  out.eye = camera.target + offset * (next / r);
  return out;
}

}  // namespace visopt::ws
