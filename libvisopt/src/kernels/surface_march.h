// Finding where a view ray first meets a context surface (the zero level set of the union of
// the SDFs): sphere tracing with the SDF as a safe step, then a secant refinement between the
// last positive and the first negative sample.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/surface_set.h"

namespace visopt {

struct SurfaceHit {
  bool hit = false;
  float t = 0.f;     // ray parameter (world units) of the hit
  int surface = -1;  // which surface's zero set was crossed
};

// o, d: the ray in index space (d per world unit); the march runs over [t0, t1] in world units.
// minStep: the smallest step (world units), so grazing rays still advance.
VISOPT_HD inline SurfaceHit traceSurfaces(const SurfaceSet& surfaces, glm::vec3 o, glm::vec3 d,
                                          float t0, float t1, float minStep) {
  SurfaceHit h;
  if (surfaces.empty() || !(t1 > t0)) return h;
  float t = t0;
  float prevT = t0, prevPhi = surfaces.unionAt(o + t0 * d);
  if (prevPhi <= 0.f) {  // the ray starts inside a surface (camera inside it or at the box)
    h.hit = true;
    h.t = t0;
  }
  for (int iter = 0; iter < 4096 && !h.hit && t < t1; ++iter) {
    t = fminf(t + fmaxf(0.9f * prevPhi, minStep), t1);
    const float phi = surfaces.unionAt(o + t * d);
    if (phi <= 0.f) {
      // Secant between the last outside sample and this one.
      const float f = prevPhi / fmaxf(prevPhi - phi, 1e-20f);
      h.hit = true;
      h.t = prevT + f * (t - prevT);
      break;
    }
    prevT = t;
    prevPhi = phi;
  }
  if (h.hit) {
    const glm::vec3 p = o + h.t * d;
    float best = 3.0e38f;
    for (int s = 0; s < surfaces.count; ++s) {
      const float v = fabsf(surfaces.phi[s].sample(p));
      if (v < best) {
        best = v;
        h.surface = s;
      }
    }
  }
  return h;
}

}  // namespace visopt
