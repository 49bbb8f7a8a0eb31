// Launch indices in brick order: launch n visits voxel (local & 7, (local >> 3) & 7, local >> 6)
// of 8^3 brick n / 512, bricks x-fastest. A kernel that only gathers from frustum fields runs
// faster in this order (the importance-behind gather: 20 % on the default scene): a brick's
// voxels project onto a compact block of frustum cells that stays in cache, where a row of
// voxels spans the whole frustum. The extinction step keeps voxel order: its five streamed voxel
// fields lose what its gather gains. Launches past the grid's edge visit nothing.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/hd.h"

namespace visopt {

struct BrickOrder {
  glm::ivec3 dims{0};
  glm::ivec3 bricks{0};

  BrickOrder() = default;
  explicit BrickOrder(glm::ivec3 d) : dims(d), bricks((d + 7) / 8) {}

  int64_t launches() const { return int64_t(bricks.x) * bricks.y * bricks.z * 512; }
  // The voxel of launch n; false past the grid's edge.
  VISOPT_HD VISOPT_INLINE bool voxel(int64_t n, int& i, int& j, int& k) const {
    const int64_t b = n >> 9;
    const int local = int(n & 511);
    const int bx = int(b % bricks.x), by = int((b / bricks.x) % bricks.y);
    const int bz = int(b / (int64_t(bricks.x) * bricks.y));
    i = bx * 8 + (local & 7);
    j = by * 8 + ((local >> 3) & 7);
    k = bz * 8 + (local >> 6);
    return i < dims.x && j < dims.y && k < dims.z;
  }
};

}  // namespace visopt
