// The context surfaces as seen by kernels: up to kMaxContextSurfaces SDFs phi on the volume grid
// (inside negative). Their union (the minimum) is opaque: volume behind it is not visible and
// not lit, which is how surfaces enter T_V and T_L.
#pragma once

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"

namespace visopt {

constexpr int kMaxContextSurfaces = 4;

struct SurfaceSet {
  int count = 0;
  FieldView phi[kMaxContextSurfaces];

  VISOPT_HD bool empty() const { return count == 0; }
  // min_i phi_i at a continuous index position; +inf-like when there is no surface.
  VISOPT_HD VISOPT_INLINE float unionAt(glm::vec3 idx) const {
    float m = 3.0e38f;
    for (int s = 0; s < count; ++s) m = fminf(m, phi[s].sample(idx));
    return m;
  }
};

}  // namespace visopt
