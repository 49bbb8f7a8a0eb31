// The extinction step (Himmler & Günther 2026, Eqs. 10-14; docs/methods.md §1): per object voxel,
// gather the per-unit-volume derivative densities d_V, d_L from the frustum grids by trilinear
// interpolation, form
//   dF/dmu = rho (mu - mu_bar) - q d_V - r d_L,
// take an optimiser step and project onto [0, mu_max] (Eq. 14). A voxel outside the view
// frustum gets no q term: it is not seen (not T = 1).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/field_view.h"
#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "kernels/optimizer_update.h"
#include "kernels/transfer_lookup.h"

namespace visopt {

struct StepSums {
  double energyRho = 0.0;  // rho/2 sum (mu - mu_bar)^2 dV, before the step
  double step2 = 0.0;      // sum (delta mu)^2
  VISOPT_HD StepSums operator+(const StepSums& o) const {
    return {energyRho + o.energyRho, step2 + o.step2};
  }
};

// Where mu_bar comes from: a stored field (coarse levels) or the transfer function applied to
// the scalars at the voxel (finest level, no extra memory).
struct BaseExtinction {
  FieldView field;
  FieldView scalars;
  TransferLookup transfer;
  VISOPT_HD VISOPT_INLINE float at(size_t v) const {
    return field.valid() ? field.load(v) : transfer.at(scalars.load(v)).w;
  }
};

// Gathers a frustum field at a world position; 0 outside the frustum.
VISOPT_HD inline float gatherFrustum(const FrustumMap& f, const FrustumFieldView& d, glm::vec3 x) {
  if (!d.valid()) return 0.f;
  const glm::vec3 y = f.toGrid(x);
  if (!d.inside(y)) return 0.f;
  return d.sample(y);
}

// dF/dmu (Eqs. 10-13) at a voxel from its mu, mu_bar and the gathered d_V, d_L (0 where a term
// is off), and the projection of Eq. 14: written once for the per-voxel step and the CPU rows.
VISOPT_HD VISOPT_INLINE float extinctionGradient(float rho, float mu, float mbar, float q, float dV,
                                                 float r, float dL) {
  float grad = rho * (mu - mbar);
  grad -= q * dV;
  grad -= r * dL;
  return grad;
}
VISOPT_HD VISOPT_INLINE float projectExtinction(float mu, float muMax) {
  return minOf(maxOf(mu, 0.f), muMax);
}

struct ExtinctionGradient {
  GridMap volume;
  FieldView mu;
  BaseExtinction base;
  float rho = 1.f, q = 1.f, r = 0.f;
  FrustumMap view, light;
  FrustumFieldView dView, dLight;  // dLight invalid when r == 0

  VISOPT_HD VISOPT_INLINE float at(int64_t v, float& mbar) const {
    const auto [i, j, k] = volume.ijk(v);
    const glm::vec3 x = volume.toWorld(glm::vec3(float(i), float(j), float(k)));
    mbar = base.at(size_t(v));
    const float dV = q != 0.f ? gatherFrustum(view, dView, x) : 0.f;
    const float dL = r != 0.f ? gatherFrustum(light, dLight, x) : 0.f;
    return extinctionGradient(rho, mu.load(size_t(v)), mbar, q, dV, r, dL);
  }
};

struct ExtinctionStep {
  ExtinctionGradient gradient;
  OptimizerState state;
  OptimizerCoefficients coefficients;
  float muMax = 1.f;
  float voxelVolume = 1.f;
  // Gradients enter the optimiser multiplied by this per-level constant (1 / their RMS at the
  // level's first step), so typical ones are ~1 and fp16 moments keep their precision. Adam-type
  // updates are invariant to a constant gradient scale up to epsilon.
  float gradientScale = 1.f;

  VISOPT_HD StepSums operator()(int64_t v) const {
    float mbar;
    const float g = gradientScale * gradient.at(v, mbar);
    const float m = gradient.mu.load(size_t(v));
    const float next = projectExtinction(m + state.step(size_t(v), g, coefficients), muMax);
    gradient.mu.store(size_t(v), next);
    const float stored = gradient.mu.load(size_t(v));  // what fp16 storage kept
    StepSums s;
    s.energyRho = 0.5 * double(gradient.rho) * double(m - mbar) * double(m - mbar) * voxelVolume;
    s.step2 = double(stored - m) * double(stored - m);
    return s;
  }
};

}  // namespace visopt
