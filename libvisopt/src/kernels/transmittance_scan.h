// Front-to-back transmittance along the rays of a frustum grid (paper 000 Eqs. 4-5):
// T(s) = exp(-integral from the eye to s of mu). One ray per (i, j), cells k front to back.
//
// Two discretisations are offered:
//  - Exclusive: T_k = exp(-sum_{j<k} mu_j ds), the discrete energy's definition (METHODS.md §1),
//  - Midpoint:  T_k = exp(-(sum_{j<k} mu_j ds + mu_k ds / 2)), the value at the cell centre,
//    which is what the renderer interpolates (second-order accurate for lookups).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"

namespace visopt {

// Samples the extinction at a world position: mu from an explicit extinction field when given,
// otherwise from the transfer function applied to the scalar field; 0 outside the volume.
template <class ExtinctionAt>
struct TransmittanceScan {
  FrustumMap frustum;
  FieldView out;  // dims == frustum.dims
  ExtinctionAt extinction;
  bool midpoint = true;

  VISOPT_HD void operator()(int64_t ray) const {
    const int i = int(ray % frustum.dims.x), j = int(ray / frustum.dims.x);
    float opticalDepth = 0.f;
    for (int k = 0; k < frustum.dims.z; ++k) {
      glm::vec3 x = frustum.toWorld(glm::vec3(float(i), float(j), float(k)));
      float mu = extinction(x) * frustum.ds;
      out.store(out.index(i, j, k), expf(-(opticalDepth + (midpoint ? 0.5f * mu : 0.f))));
      opticalDepth += mu;
    }
  }
};

}  // namespace visopt
