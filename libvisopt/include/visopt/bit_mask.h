// A binary mask on a volume grid, bit-packed: bit i (x fastest, LSB first) is voxel i. The
// world mask (R5) is held this way, in sessions and in the engine (1 bit per voxel).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace visopt {

class Field3D;

struct BitMask {
  glm::ivec3 dims{0};
  std::vector<uint8_t> bits;  // (voxelCount + 7) / 8 bytes
  size_t voxelCount() const;
  bool get(size_t i) const { return (bits[i >> 3] >> (i & 7)) & 1u; }
  void set(size_t i, bool v);
  bool operator==(const BitMask&) const = default;

  // All clear, sized for `dims` (each component >= 0).
  static BitMask cleared(glm::ivec3 dims);
  // The number of voxels set.
  size_t count() const;
};

// Set where the field is > 0.5 (the level-set step's threshold).
BitMask packMask(const Field3D& mask);

}  // namespace visopt
