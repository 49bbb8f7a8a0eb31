// Geometry of a dense regular grid in world space: dims, anisotropic spacing, origin and an
// orthonormal orientation (columns: world directions of the i, j, k index axes).
#pragma once

#include <cstddef>
#include <glm/glm.hpp>

namespace visopt {

struct Bounds {
  glm::vec3 lo{0.f};
  glm::vec3 hi{0.f};
  glm::vec3 center() const { return 0.5f * (lo + hi); }
  glm::vec3 size() const { return hi - lo; }
};

struct GridSpec {
  glm::ivec3 dims{1};
  glm::vec3 spacing{1.f};
  glm::vec3 origin{0.f};
  glm::mat3 direction{1.f};

  size_t voxelCount() const {
    return static_cast<size_t>(dims.x) * static_cast<size_t>(dims.y) * static_cast<size_t>(dims.z);
  }
  size_t linearIndex(int i, int j, int k) const {
    return (static_cast<size_t>(k) * static_cast<size_t>(dims.y) + static_cast<size_t>(j)) *
               static_cast<size_t>(dims.x) +
           static_cast<size_t>(i);
  }
  // Continuous index (voxel centres at integers) to world position, and back.
  glm::vec3 indexToWorld(glm::vec3 ijk) const { return origin + direction * (ijk * spacing); }
  glm::vec3 worldToIndex(glm::vec3 p) const {
    return (glm::transpose(direction) * (p - origin)) / spacing;
  }
  // World extent spanned by the voxel centres along each index axis.
  glm::vec3 extent() const { return glm::vec3(glm::max(dims - 1, glm::ivec3(0))) * spacing; }
  float diagonal() const { return glm::length(extent()); }
  float minSpacing() const { return glm::min(spacing.x, glm::min(spacing.y, spacing.z)); }
  // Axis-aligned world box around the voxel centres (all 8 corners transformed).
  Bounds worldBounds() const;
  bool operator==(const GridSpec&) const = default;
};

}  // namespace visopt
