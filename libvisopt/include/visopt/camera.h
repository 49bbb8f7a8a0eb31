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
  bool operator==(const Camera&) const = default;
};

// The orbit distances a view may use, in bounding-sphere radii: nearer than kMinOrbitRadii the
// camera sits on the volume's centre (no view direction in float), farther than kMaxOrbitRadii
// the volume is below a pixel and float products of world positions overflow.
inline constexpr float kMinOrbitRadii = 1e-3f;
inline constexpr float kMaxOrbitRadii = 1e4f;

// The orbit a volume file opens with (a scene has its own): from the front, slightly above.
struct OrbitView {
  float azimuthDeg, elevationDeg, distanceInRadii;
};
inline constexpr OrbitView kDefaultVolumeView{0.f, 10.f, 2.6f};

// Throws Error(Usage) naming `what` unless the camera can render `bounds`: finite eye, target
// and up, a field of view of 1..170 degrees, the eye kMinOrbitRadii..kMaxOrbitRadii bounding
// radii from the target and within kMaxOrbitRadii of the bounds' centre, up not along the view.
void checkCamera(const Camera& camera, const Bounds& bounds, const char* what = "camera");
// The same for orbit angles and distance (finite angles, distance in radii within the range).
void checkOrbit(float azimuthDeg, float elevationDeg, float distanceInRadii,
                const char* what = "camera");

struct PointLight {
  glm::vec3 position{0.f, -3.f, 3.f};
  float intensity =
      1.f;  // L_e of Himmler & Günther 2026, Eq. 9 (no quadratic fall-off, as in the paper)
  glm::vec3 color{1.f};

  // A light above-left of the camera, a photographer's key light: the default for scenes.
  static PointLight keyLightFor(const Camera& camera, const Bounds& bounds);
  bool operator==(const PointLight&) const = default;
};

// Throws Error(Usage) unless the light is usable with `bounds`: a finite position within
// kMaxOrbitRadii bounding radii of the centre, finite non-negative intensity and colour.
void checkLight(const PointLight& light, const Bounds& bounds, const char* what = "light");

}  // namespace visopt
