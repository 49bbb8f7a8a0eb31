// Extinction mu_t at a world position: the optimised field when there is one, else the transfer
// function's base extinction mu_bar(s(x)) (paper 000 Eq. 3); zero outside the volume's box.
#pragma once

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/transfer_lookup.h"

namespace visopt {

struct VolumeExtinction {
  GridMap volume;
  FieldView scalars;
  FieldView extinction;  // optional
  TransferLookup transfer;

  VISOPT_HD float operator()(glm::vec3 world) const {
    glm::vec3 idx = volume.toIndex(world);
    glm::vec3 hi = glm::vec3(volume.dims - 1);
    if (idx.x < 0.f || idx.y < 0.f || idx.z < 0.f || idx.x > hi.x || idx.y > hi.y || idx.z > hi.z)
      return 0.f;
    if (extinction.valid()) return extinction.sample(idx);
    return transfer.at(scalars.sample(idx)).w;
  }
};

}  // namespace visopt
