// Post-classification: the transfer function is applied to the interpolated scalar (Himmler &
// Günther 2026 Eq. 3: albedo a(x) and base extinction mu_bar(x) from the scalar s(x)).
#pragma once

#include <glm/glm.hpp>

#include "core/hd.h"
#include "core/min_max.h"

namespace visopt {

struct TransferLookup {
  const glm::vec4* table = nullptr;  // rgb albedo, extinction; entries at t = i / (size - 1)
  int size = 0;

  // Where a normalised value falls in the table: entries i0, i1 and the weight f of i1.
  struct Entry {
    int i0 = 0, i1 = 0;
    float f = 0.f;
  };

  VISOPT_HD Entry locate(float t) const {
    Entry e;
    // minOf/maxOf, not glm::clamp: a NaN t becomes entry 0 instead of an undefined int(NaN).
    const float x = minOf(maxOf(t, 0.f), 1.f) * float(size - 1);
    e.i0 = int(x);
    e.i1 = e.i0 + 1 < size ? e.i0 + 1 : size - 1;
    e.f = x - float(e.i0);
    return e;
  }

  // Linear interpolation in the baked table at normalised value t.
  VISOPT_HD glm::vec4 at(float t) const {
    const Entry e = locate(t);
    return table[e.i0] + e.f * (table[e.i1] - table[e.i0]);
  }

  // The extinction and the albedo of at(t), separately (the ray marcher needs the albedo only
  // where the extinction is not negligible).
  VISOPT_HD float extinction(const Entry& e) const {
    const float a = table[e.i0].w, b = table[e.i1].w;
    return a + e.f * (b - a);
  }
  VISOPT_HD glm::vec3 albedo(const Entry& e) const {
    const glm::vec3 a(table[e.i0]), b(table[e.i1]);
    return a + e.f * (b - a);
  }
};

}  // namespace visopt
