// A bit-packed mask as kernels on either backend read it (trivially copyable): a pointer to
// the words, bit i (x fastest, LSB first) for voxel i, and the grid's dims. Owned by a
// DeviceBitMask (core/device_bit_mask.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/hd.h"

namespace visopt {

struct BitMaskView {
  const uint8_t* words = nullptr;  // bit i (x fastest, LSB first) is voxel i
  glm::ivec3 dims{0};

  VISOPT_HD bool valid() const { return words != nullptr; }
  VISOPT_HD VISOPT_INLINE bool get(size_t i) const { return (words[i >> 3] >> (i & 7)) & 1u; }
  VISOPT_HD VISOPT_INLINE bool at(int i, int j, int k) const {
    return get((size_t(k) * size_t(dims.y) + size_t(j)) * size_t(dims.x) + size_t(i));
  }
  // The voxel nearest to index coordinates p; false outside the grid.
  VISOPT_HD VISOPT_INLINE bool nearest(glm::vec3 p) const {
    const int i = int(floorf(p.x + 0.5f)), j = int(floorf(p.y + 0.5f)), k = int(floorf(p.z + 0.5f));
    if (i < 0 || j < 0 || k < 0 || i >= dims.x || j >= dims.y || k >= dims.z) return false;
    return at(i, j, k);
  }
  // Trilinear interpolation of the 0/1 values at continuous index coordinates p, clamped to the
  // grid (the convention of FieldView::sample).
  VISOPT_HD float sample(glm::vec3 p) const {
    p = glm::clamp(p, glm::vec3(0.f), glm::vec3(dims - 1));
    const glm::ivec3 i0 = glm::ivec3(p);
    const glm::ivec3 i1 = glm::min(i0 + 1, dims - 1);
    const glm::vec3 f = p - glm::vec3(i0);
    auto v = [&](int i, int j, int k) { return at(i, j, k) ? 1.f : 0.f; };
    const float c00 = v(i0.x, i0.y, i0.z) + f.x * (v(i1.x, i0.y, i0.z) - v(i0.x, i0.y, i0.z));
    const float c10 = v(i0.x, i1.y, i0.z) + f.x * (v(i1.x, i1.y, i0.z) - v(i0.x, i1.y, i0.z));
    const float c01 = v(i0.x, i0.y, i1.z) + f.x * (v(i1.x, i0.y, i1.z) - v(i0.x, i0.y, i1.z));
    const float c11 = v(i0.x, i1.y, i1.z) + f.x * (v(i1.x, i1.y, i1.z) - v(i0.x, i1.y, i1.z));
    const float c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
    return c0 + f.z * (c1 - c0);
  }
};

}  // namespace visopt
