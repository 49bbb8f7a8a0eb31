// Perspective camera and point light. World units are the volume's (usually mm); z is "up"
// for orbiting, the convention of patient coordinates (superior = +z).
#pragma once

#include <glm/glm.hpp>

#include "visopt/grid.h"

namespace visopt {

struct Camera {
  glm::vec3 eye{0.f, -3.f, 0.f};
  glm::vec3 target{0.f};
  glm::vec3 up{0.f, 0.f, 1.f};
  float fovYDegrees = 30.f;

  // Orbit around `target`: azimuth about +z from the -y axis (0° looks along +y, i.e. at a
  // patient's face), elevation above the xy-plane, distance in world units.
  static Camera orbit(glm::vec3 target, float azimuthDeg, float elevationDeg, float distance);
  // Orbit framing `bounds`: distance is in multiples of the bounding-sphere radius.
  static Camera orbitBounds(const Bounds& bounds, float azimuthDeg, float elevationDeg,
                            float distanceInRadii);
  glm::vec3 forward() const { return glm::normalize(target - eye); }
};

struct PointLight {
  glm::vec3 position{0.f, -3.f, 3.f};
  float intensity = 1.f;  // L_e of paper 000 Eq. 9 (no quadratic fall-off, as in the paper)
  glm::vec3 color{1.f};

  // A light above-left of the camera, a photographer's key light: the default for scenes.
  static PointLight keyLightFor(const Camera& camera, const Bounds& bounds);
};

}  // namespace visopt
