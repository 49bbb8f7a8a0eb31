// Extinction mu_t at a continuous index position inside the volume: the transfer function's
// base extinction mu_bar(s(x)) (Himmler & Günther 2026, Eq. 3), plus the optimisation's change to
// it when there is one (see extinctionWithChange).
#pragma once

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "kernels/transfer_lookup.h"

namespace visopt {

// The optimised extinction as drawn: mu_bar(s(x)) classified after interpolating the scalar,
// plus the trilinear interpolant of the per-voxel change mu - mu_bar, never below 0. Drawing the
// optimised mu itself (classified per voxel, then interpolated) would change the picture where
// the optimisation changed nothing: at a sharp edge, such as the partial-volume voxels just
// outside a skull, the per-voxel values interpolate into blobs on the voxel lattice, which the
// surfaces' volume ambient occlusion showed as rings of dots all over them. With the change
// field an unchanged region looks exactly as before the optimisation.
VISOPT_HD VISOPT_INLINE float extinctionWithChange(float base, float change) {
  const float mu = base + change;
  return mu > 0.f ? mu : 0.f;
}

struct VolumeExtinction {
  FieldView scalars;
  FieldView change;  // optional: optimised mu - mu_bar per voxel
  TransferLookup transfer;

  VISOPT_HD float operator()(glm::vec3 idx) const {
    const float base = transfer.at(scalars.sample(idx)).w;
    return change.valid() ? extinctionWithChange(base, change.sample(idx)) : base;
  }
};

}  // namespace visopt
