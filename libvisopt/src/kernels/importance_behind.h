// ghat, the importance behind a voxel that drives the context surfaces (Himmler & Günther 2026,
// Eq. 19): half the largest importance behind the voxel along its view ray, half along its light
// ray, both read from the frustum maxima of the grid updates (VisibilityScan::behindMax) at the
// voxel's position. The lens and windowing masks weigh the light half too, by the voxel's screen
// position: under a lens of strength 0 a surface keeps its shape, not opening towards the light
// either. Without a light grid ghat is the view half alone.
//
// Written once: the CUDA backend runs operator() per voxel (in brick order, core/brick_order.h),
// the CPU backend host/importance_behind_rows.h, which samples the frusta 16 voxels at a time and
// forms the same value with ghatOf.
#pragma once

#include <cmath>

#include "core/field_view.h"
#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/extinction_step.h"
#include "kernels/screen_weights.h"

namespace visopt {

struct ImportanceBehind {
  GridMap volume;
  FieldView ghat;  // out, on the volume grid
  FrustumMap view, light;
  FrustumFieldView viewMax, lightMax;  // lightMax invalid without a light grid
  ScreenWeights weights;

  // ghat at world position x from the two maxima sampled there.
  VISOPT_HD VISOPT_INLINE float ghatOf(float viewBehind, float lightBehind, glm::vec3 x) const {
    float g = viewBehind;
    if (lightMax.valid()) {
      float lm = lightBehind;
      if (weights.active()) {
        const glm::vec3 y = view.toGrid(x);
        if (y.z >= -0.5f && y.z <= float(view.dims.z) - 0.5f)
          lm = fminf(lm * weights.atPoint(y.x, y.y, view.dims.x, view.dims.y), 1.f);
      }
      g = 0.5f * viewBehind + 0.5f * lm;
    }
    return fminf(fmaxf(g, 0.f), 1.f);
  }

  VISOPT_HD void operator()(int i, int j, int k) const {
    const size_t v =
        (size_t(k) * size_t(volume.dims.y) + size_t(j)) * size_t(volume.dims.x) + size_t(i);
    const glm::vec3 x = volume.toWorld(glm::vec3(float(i), float(j), float(k)));
    const float vm = gatherFrustum(view, viewMax, x);
    const float lm = lightMax.valid() ? gatherFrustum(light, lightMax, x) : 0.f;
    ghat.store(v, ghatOf(vm, lm, x));
  }
};

}  // namespace visopt
