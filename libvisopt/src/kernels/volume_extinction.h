// Extinction mu_t at a continuous index position inside the volume: the optimised field when
// there is one, else the transfer function's base extinction mu_bar(s(x)) (paper 000 Eq. 3).
#pragma once

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "kernels/transfer_lookup.h"

namespace visopt {

struct VolumeExtinction {
  FieldView scalars;
  FieldView extinction;  // optional
  TransferLookup transfer;

  VISOPT_HD float operator()(glm::vec3 idx) const {
    if (extinction.valid()) return extinction.sample(idx);
    return transfer.at(scalars.sample(idx)).w;
  }
};

}  // namespace visopt
