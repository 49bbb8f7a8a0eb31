// Front-to-back transmittance along the rays of a frustum grid (Himmler & Günther 2026, Eqs. 4-5):
// T(s) = exp(-integral from the eye to s of mu). One ray per (i, j), cells k front to back.
// Each cell [s_k - ds/2, s_k + ds/2] contributes mu times the length of its overlap with the
// volume's box, sampled at the overlap's midpoint, so a sharp box boundary costs no error.
//
// Two discretisations are offered:
//  - Exclusive: T_k = exp(-sum_{j<k} tau_j), the discrete energy's definition (docs/methods.md §1),
//  - Midpoint:  T_k = exp(-(sum_{j<k} tau_j + tau_k / 2)), the value at the cell centre, which
//    is what the renderer interpolates (second-order accurate for lookups).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/ray_box.h"
#include "kernels/surface_render.h"
#include "kernels/surface_set.h"

namespace visopt {

// ExtinctionAt: mu at a continuous index position inside the volume.
template <class ExtinctionAt>
struct TransmittanceScan {
  FrustumMap frustum;
  GridMap volume;
  FieldView out;  // dims == frustum.dims
  ExtinctionAt extinction;
  bool midpoint = true;
  SurfaceSet surfaces;
  RayMethod method = RayMethod::Optimized;  // CutAway and Transparency change the surfaces' rule
  FieldView importanceBehind;               // ghat on the volume grid, for those two
  float cutThreshold = 0.3f;

  VISOPT_HD void operator()(int64_t ray) const {
    const int i = int(ray % frustum.dims.x), j = int(ray / frustum.dims.x);
    const glm::vec3 dir = frustum.rayDirection(float(i), float(j));
    const glm::vec3 o = volume.toIndex(frustum.eye);
    const glm::vec3 d = volume.directionToIndex(dir);
    const RayInterval box = intersectBox(o, d, glm::vec3(volume.dims - 1));
    float opticalDepth = 0.f;
    bool blocked = false, inside = false, faded = false;
    float surfaceT = 1.f;  // what the surfaces a baseline cut or faded let through
    // exp only when its argument moved: cells before, past and between the volume's matter keep
    // T (most of a light frustum's cells; the same bits as evaluating it every cell).
    float lastArgument = 0.f, lastT = 1.f;
    for (int k = 0; k < frustum.dims.z; ++k) {
      if (!surfaces.empty() && !blocked && !box.empty()) {
        const float s = frustum.depthOf(float(k));
        const glm::vec3 x = o + s * d;
        const bool in = s >= box.t0 && s <= box.t1 && surfaces.unionAt(x) < 0.f;
        if (in && !inside) {  // entering a surface's interior
          if (method == RayMethod::CutAway) {
            blocked = !(importanceBehind.sample(x) > cutThreshold);
          } else if (method == RayMethod::Transparency) {
            if (!faded) surfaceT = fminf(fmaxf(importanceBehind.sample(x), 0.f), 1.f);
            faded = true;
          } else {
            blocked = true;
          }
        }
        inside = in;
      }
      if (blocked) {
        out.store(out.index(i, j, k), 0.f);
        continue;
      }
      float tau = 0.f;
      if (!box.empty()) {
        const float a = fmaxf(frustum.depthOf(float(k)) - 0.5f * frustum.ds, box.t0);
        const float b = fminf(frustum.depthOf(float(k)) + 0.5f * frustum.ds, box.t1);
        if (b > a) tau = extinction(o + (0.5f * (a + b)) * d) * (b - a);
      }
      const float argument = opticalDepth + (midpoint ? 0.5f * tau : 0.f);
      if (argument != lastArgument) {
        lastArgument = argument;
        lastT = expf(-argument);
      }
      out.store(out.index(i, j, k), surfaceT * lastT);
      opticalDepth += tau;
    }
  }
};

}  // namespace visopt
