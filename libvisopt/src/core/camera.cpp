#include "visopt/camera.h"

#include <cmath>

namespace visopt {

namespace {
constexpr float kDegToRad = 3.14159265358979f / 180.f;
}

Camera Camera::orbit(glm::vec3 target, float azimuthDeg, float elevationDeg, float distance) {
  const float az = azimuthDeg * kDegToRad, el = elevationDeg * kDegToRad;
  glm::vec3 dir(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el));
  Camera c;
  c.target = target;
  c.eye = target + distance * dir;
  // Near the poles +z is (almost) parallel to the view direction; use the azimuth's forward.
  c.up = std::abs(elevationDeg) > 89.f
             ? glm::vec3(-std::sin(az), std::cos(az), 0.f) * (elevationDeg > 0 ? 1.f : -1.f)
             : glm::vec3(0.f, 0.f, 1.f);
  return c;
}

Camera Camera::orbitBounds(const Bounds& bounds, float azimuthDeg, float elevationDeg,
                           float distanceInRadii) {
  float radius = 0.5f * glm::length(bounds.size());
  return orbit(bounds.center(), azimuthDeg, elevationDeg, distanceInRadii * radius);
}

PointLight PointLight::keyLightFor(const Camera& camera, const Bounds& bounds) {
  glm::vec3 f = camera.forward();
  glm::vec3 r = glm::normalize(glm::cross(f, camera.up));
  glm::vec3 u = glm::cross(r, f);
  float dist = glm::length(camera.eye - bounds.center());
  PointLight light;
  light.position = bounds.center() + dist * glm::normalize(-f - 0.6f * r + 0.8f * u);
  return light;
}

}  // namespace visopt
