#include "visopt/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "visopt/error.h"

namespace visopt {

namespace {
constexpr float kDegToRad = 3.14159265358979f / 180.f;

bool finite(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
[[noreturn]] void refuse(const char* what, const std::string& problem) {
  throw Error(ErrorKind::Usage, std::string(what) + ": " + problem);
}
float radiusOf(const Bounds& bounds) {
  return std::max(0.5f * glm::length(bounds.size()), 1e-30f);
}
std::string rangeText() {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g..%g bounding radii", double(kMinOrbitRadii),
                double(kMaxOrbitRadii));
  return buf;
}
std::string farText() {
  char buf[96];
  std::snprintf(buf, sizeof buf, "more than %g bounding radii from the volume",
                double(kMaxOrbitRadii));
  return buf;
}
}  // namespace

void checkOrbit(float azimuthDeg, float elevationDeg, float distanceInRadii, const char* what) {
  if (!std::isfinite(azimuthDeg) || !std::isfinite(elevationDeg))
    refuse(what, "the azimuth and elevation must be finite numbers of degrees");
  if (!(distanceInRadii >= kMinOrbitRadii && distanceInRadii <= kMaxOrbitRadii))
    refuse(what, "the distance must be " + rangeText());
}

void checkCamera(const Camera& camera, const Bounds& bounds, const char* what) {
  if (!finite(camera.eye) || !finite(camera.target) || !finite(camera.up))
    refuse(what, "the eye, target and up vector must be finite");
  if (!(camera.fovYDegrees >= 1.f && camera.fovYDegrees <= 170.f))
    refuse(what, "the vertical field of view must be 1..170 degrees");
  const float radius = radiusOf(bounds);
  const float distance = glm::length(camera.eye - camera.target);
  if (!(distance >= kMinOrbitRadii * radius && distance <= kMaxOrbitRadii * radius))
    refuse(what, "the eye must be " + rangeText() + " from the target");
  if (!(glm::length(camera.eye - bounds.center()) <= kMaxOrbitRadii * radius))
    refuse(what, "the eye lies " + farText());
  const glm::vec3 forward = (camera.target - camera.eye) / distance;
  const float upLength = glm::length(camera.up);
  if (!(upLength > 0.f) || glm::length(glm::cross(forward, camera.up / upLength)) < 1e-4f)
    refuse(what, "the up vector must not point along the view direction");
}

void checkLight(const PointLight& light, const Bounds& bounds, const char* what) {
  if (!finite(light.position)) refuse(what, "the position must be finite");
  if (!(glm::length(light.position - bounds.center()) <= kMaxOrbitRadii * radiusOf(bounds)))
    refuse(what, "the position lies " + farText());
  if (!(light.intensity >= 0.f) || !std::isfinite(light.intensity))
    refuse(what, "the intensity must be a finite number >= 0");
  if (!finite(light.color) || light.color.x < 0.f || light.color.y < 0.f || light.color.z < 0.f)
    refuse(what, "the colour must be finite and >= 0");
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
