// Ray / box intersection in a volume's index space (the box spans the voxel centres).
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/hd.h"

namespace visopt {

// Parametric interval [t0, t1] (t0 >= 0) where o + t d lies in [0, hi]^3; empty when t1 <= t0.
struct RayInterval {
  float t0 = 0.f, t1 = -1.f;
  VISOPT_HD bool empty() const { return !(t1 > t0); }
};

VISOPT_HD inline RayInterval intersectBox(glm::vec3 o, glm::vec3 d, glm::vec3 hi) {
  RayInterval r{0.f, 3.0e38f};
  for (int a = 0; a < 3; ++a) {
    if (fabsf(d[a]) < 1e-20f) {
      if (o[a] < 0.f || o[a] > hi[a]) r.t1 = -1.f;
      continue;
    }
    float ta = (0.f - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    r.t0 = fmaxf(r.t0, fminf(ta, tb));
    r.t1 = fminf(r.t1, fmaxf(ta, tb));
  }
  return r;
}

}  // namespace visopt
