// Empty-space skipping for the ray marcher: a coarse grid of blocks of kRaySkipBlock^3 voxels,
// each flagged empty when no sample inside it can have an optical depth the marcher would use
// (mu * step < kRayMinOpticalDepth: such samples contribute nothing and change nothing, see
// kernels/ray_march.h). The marcher jumps over empty blocks to the first sample past them, so
// the samples it does take are exactly the same as without skipping, at the same positions.
//
// Built per frame in two passes (cheap next to rendering, and only when the transfer function
// has transparent ranges or mu is an optimised field):
//  1. RaySkipRange: the range [lo, hi] of the normalised scalars over each block's voxels, and
//     with an optimised mu also that of its change to mu_bar;
//  2. RaySkipFlags: a block is empty when the union of the ranges of its 3x3x3 neighbourhood
//     (which covers every voxel a trilinear sample inside the block, or within rounding of its
//     faces, can read) maps only to negligible extinction through the transfer function's
//     table (any entry between the range's table cells, one more on each side), and the change
//     to it is nowhere positive there.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "kernels/ray_fast_math.h"

namespace visopt {

constexpr int kRaySkipBlock = 4;
// Samples with mu * segment below this are skipped by the marcher (no shading, no attenuation).
constexpr float kRayMinOpticalDepth = 1e-7f;

struct RaySkipGrid {
  const uint8_t* empty = nullptr;  // 1 per empty block, x fastest; null: no skipping
  glm::ivec3 dims{0};              // blocks per axis

  VISOPT_HD bool valid() const { return empty != nullptr; }
};

inline glm::ivec3 raySkipBlocks(glm::ivec3 voxels) {
  return (voxels + (kRaySkipBlock - 1)) / kRaySkipBlock;
}

// Pass 1: per block, the minimum and maximum of the field over its voxels.
struct RaySkipRange {
  FieldView field;
  glm::ivec3 blocks{0};
  glm::vec2* range = nullptr;  // (lo, hi) per block

  VISOPT_HD void operator()(int64_t block) const {
    const int bx = int(block % blocks.x), by = int((block / blocks.x) % blocks.y),
              bz = int(block / (int64_t(blocks.x) * blocks.y));
    const glm::ivec3 lo = glm::ivec3(bx, by, bz) * kRaySkipBlock;
    const glm::ivec3 hi = glm::min(lo + kRaySkipBlock, field.dims);
    float vmin = 3.0e38f, vmax = -3.0e38f;
    for (int k = lo.z; k < hi.z; ++k)
      for (int j = lo.y; j < hi.y; ++j) {
        const size_t row = field.index(lo.x, j, k);
        for (int i = 0; i < hi.x - lo.x; ++i) {
          const float v = rayLoad(field.data, field.half, row + size_t(i));
          vmin = v < vmin ? v : vmin;
          vmax = v > vmax ? v : vmax;
        }
      }
    range[block] = glm::vec2(vmin, vmax);
  }
};

// Pass 2: the empty flags. nonEmptyBefore[i] counts the transfer table's entries before i whose
// extinction is not negligible.
struct RaySkipFlags {
  glm::ivec3 blocks{0};
  const glm::vec2* range = nullptr;
  const glm::vec2* changeRange = nullptr;  // of mu - mu_bar, or null without an optimised mu
  const int* nonEmptyBefore = nullptr;     // size tableSize + 1
  int tableSize = 0;
  uint8_t* empty = nullptr;

  VISOPT_HD void operator()(int64_t block) const {
    const int bx = int(block % blocks.x), by = int((block / blocks.x) % blocks.y),
              bz = int(block / (int64_t(blocks.x) * blocks.y));
    float lo = 3.0e38f, hi = -3.0e38f, changeHi = -3.0e38f;
    for (int k = bz - 1; k <= bz + 1; ++k)
      for (int j = by - 1; j <= by + 1; ++j)
        for (int i = bx - 1; i <= bx + 1; ++i) {
          if (i < 0 || j < 0 || k < 0 || i >= blocks.x || j >= blocks.y || k >= blocks.z) continue;
          const int64_t b = (int64_t(k) * blocks.y + j) * blocks.x + i;
          const glm::vec2 r = range[b];
          lo = r.x < lo ? r.x : lo;
          hi = r.y > hi ? r.y : hi;
          if (changeRange) changeHi = changeRange[b].y > changeHi ? changeRange[b].y : changeHi;
        }
    // The table cells the clamped values fall in, widened by one entry against rounding.
    const float scale = float(tableSize - 1);
    const float a = (lo < 0.f ? 0.f : (lo > 1.f ? 1.f : lo)) * scale;
    const float b = (hi < 0.f ? 0.f : (hi > 1.f ? 1.f : hi)) * scale;
    int first = int(a) - 1, last = int(b) + 2;
    first = first < 0 ? 0 : first;
    last = last > tableSize - 1 ? tableSize - 1 : last;
    const bool isEmpty = nonEmptyBefore[last + 1] - nonEmptyBefore[first] == 0 && !(changeHi > 0.f);
    empty[block] = isEmpty ? 1 : 0;
  }
};

}  // namespace visopt
