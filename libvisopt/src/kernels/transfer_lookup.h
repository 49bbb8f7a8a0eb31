// Post-classification: the transfer function is applied to the interpolated scalar (paper 000
// Eq. 3: albedo a(x) and base extinction mu_bar(x) from the scalar s(x)).
#pragma once

#include <glm/glm.hpp>

#include "core/hd.h"

namespace visopt {

struct TransferLookup {
  const glm::vec4* table = nullptr;  // rgb albedo, extinction; entries at t = i / (size - 1)
  int size = 0;

  // Linear interpolation in the baked table at normalised value t.
  VISOPT_HD glm::vec4 at(float t) const {
    float x = glm::clamp(t, 0.f, 1.f) * float(size - 1);
    int i0 = int(x);
    int i1 = i0 + 1 < size ? i0 + 1 : size - 1;
    float f = x - float(i0);
    return table[i0] + f * (table[i1] - table[i0]);
  }
};

}  // namespace visopt
