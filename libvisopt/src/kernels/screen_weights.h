// Screen-space modulation of the importance along view rays (Himmler & Günther 2026, §III-F, Fig.
// 8): a circular lens and a windowing mask, both evaluated per frustum ray (pixel).
#pragma once

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"

namespace visopt {

struct ScreenWeights {
  // Lens: centre and radius in normalised screen coordinates ([0,1]^2, y down like images);
  // inside it g is multiplied by `lensStrength` (clamped to [0, 1] afterwards), with a smooth
  // rim of 10 % of the radius. radius <= 0: no lens.
  glm::vec2 lensCentre{0.5f};
  float lensRadius = 0.f;
  float lensStrength = 1.f;
  // Windowing mask over the screen: an nx x ny x 1 field of weights in [0,1] (bilinear);
  // invalid: no mask.
  FieldView mask;

  VISOPT_HD bool active() const { return lensRadius > 0.f || mask.valid(); }

  // Weight of the ray through frustum pixel (i, j) of an nx x ny grid (j = 0 at the bottom).
  VISOPT_HD float at(int i, int j, int nx, int ny) const {
    return atPoint(float(i), float(j), nx, ny);
  }
  // The same at a continuous frustum position (x, y): pixel (i, j)'s centre is (i, j).
  VISOPT_HD float atPoint(float x, float y, int nx, int ny) const {
    const float u = (x + 0.5f) / float(nx);
    const float v = 1.f - (y + 0.5f) / float(ny);
    float w = 1.f;
    if (mask.valid())
      w *=
          mask.sample(glm::vec3(u * float(mask.dims.x) - 0.5f, v * float(mask.dims.y) - 0.5f, 0.f));
    if (lensRadius > 0.f) {
      const float r = glm::length(glm::vec2(u, v) - lensCentre) / lensRadius;
      const float inside = fminf(fmaxf((1.f - r) / 0.1f, 0.f), 1.f);  // 1 inside, 0 outside
      w *= 1.f + inside * (lensStrength - 1.f);
    }
    return w;
  }
};

}  // namespace visopt
