// Device-side copies of the grid and frustum mappings (Himmler & Günther 2026, Eqs. 4-5: g_V, g_L
// and their inverses). The public GridSpec / FrustumGrid delegate to these, so the math exists
// once.
#pragma once

#include <glm/glm.hpp>

#include "core/hd.h"
#include "core/voxel_ijk.h"
#include "visopt/frustum.h"
#include "visopt/grid.h"

namespace visopt {

struct GridMap {
  glm::vec3 origin{0.f}, spacing{1.f};
  glm::mat3 direction{1.f};
  glm::ivec3 dims{1};

  GridMap() = default;
  explicit GridMap(const GridSpec& g)
      : origin(g.origin), spacing(g.spacing), direction(g.direction), dims(g.dims) {}
  VISOPT_HD glm::vec3 toWorld(glm::vec3 ijk) const { return origin + direction * (ijk * spacing); }
  // The (i, j, k) of linear voxel index v.
  VISOPT_HD VoxelIjk ijk(int64_t v) const { return voxelIjk(v, dims); }
  VISOPT_HD glm::vec3 toIndex(glm::vec3 p) const {
    return (glm::transpose(direction) * (p - origin)) / spacing;
  }
  // A world-space direction expressed in index units per world unit.
  VISOPT_HD glm::vec3 directionToIndex(glm::vec3 d) const {
    return (glm::transpose(direction) * d) / spacing;
  }
};

struct FrustumMap {
  glm::vec3 eye{0.f}, right{1, 0, 0}, up{0, 1, 0}, forward{0, 0, 1};
  float tanX = 1.f, tanY = 1.f;
  glm::ivec3 dims{1};
  float sNear = 0.f, ds = 1.f;

  FrustumMap() = default;
  explicit FrustumMap(const FrustumGrid& f)
      : eye(f.eye),
        right(f.right),
        up(f.up),
        forward(f.forward),
        tanX(f.tanHalfFovX),
        tanY(f.tanHalfFovY),
        dims(f.dims),
        sNear(f.sNear),
        ds(f.depthStep()) {}

  // Ray direction through continuous pixel coordinates (pixel centres at integers).
  VISOPT_HD glm::vec3 rayDirection(float px, float py) const {
    float u = ((px + 0.5f) / float(dims.x)) * 2.f - 1.f;
    float v = ((py + 0.5f) / float(dims.y)) * 2.f - 1.f;
    return glm::normalize(forward + (u * tanX) * right + (v * tanY) * up);
  }
  // g: world -> (px, py, depth cell) continuous coordinates.
  VISOPT_HD glm::vec3 toGrid(glm::vec3 x) const {
    glm::vec3 d = x - eye;
    float z = glm::dot(d, forward);
    float s = glm::length(d);
    if (z <= 0.f) return glm::vec3(-1e30f);  // behind the eye: outside every frustum
    float u = glm::dot(d, right) / (z * tanX);
    float v = glm::dot(d, up) / (z * tanY);
    return glm::vec3((u + 1.f) * 0.5f * float(dims.x) - 0.5f,
                     (v + 1.f) * 0.5f * float(dims.y) - 0.5f, (s - sNear) / ds - 0.5f);
  }
  // g^-1: continuous coordinates -> world.
  VISOPT_HD glm::vec3 toWorld(glm::vec3 y) const {
    float s = sNear + (y.z + 0.5f) * ds;
    return eye + s * rayDirection(y.x, y.y);
  }
  VISOPT_HD float depthOf(float k) const { return sNear + (k + 0.5f) * ds; }
};

}  // namespace visopt
