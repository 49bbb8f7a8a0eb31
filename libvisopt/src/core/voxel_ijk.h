// The (i, j, k) of a linear voxel index on a grid stored x fastest, then y, then z (FieldView's
// and Field3D's layout): written once for every kernel that launches one item per voxel.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/hd.h"

namespace visopt {

struct VoxelIjk {
  int i, j, k;
};

VISOPT_HD VISOPT_INLINE VoxelIjk voxelIjk(int64_t v, glm::ivec3 dims) {
  const int64_t nx = dims.x, ny = dims.y;
  return {int(v % nx), int((v / nx) % ny), int(v / (nx * ny))};
}

}  // namespace visopt
