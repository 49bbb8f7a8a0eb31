// The 3D Shepp–Logan head phantom: ten ellipsoids in [-1, 1]^3 whose densities add up, with
// the higher-contrast "modified" densities (Toft): skull/skin shell 1.0, brain 0.2, ventricles
// 0.0, tumours 0.3.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace visopt::scenes {

struct PhantomEllipsoid {
  glm::vec3 center;
  glm::vec3 semiAxes;
  float angleDeg;  // rotation about +z
  float density;   // added inside the ellipsoid
};

const std::vector<PhantomEllipsoid>& sheppLoganEllipsoids();

// Exact (unsmoothed) phantom density at p in normalised coordinates: the sum of the densities
// of the ellipsoids containing p.
float sheppLoganDensity(glm::vec3 p);

}  // namespace visopt::scenes
