// View-space and light-space frustum grids: the perspective mappings g_V and g_L of
// Himmler & Günther 2026, Eqs. 4-5 and their inverses.
//
// A frustum grid has nx × ny rays (one per pixel centre of a virtual image) and nz depth cells.
// Depth is the Euclidean distance s = |x - eye| along each ray, split uniformly in [sNear, sFar],
// so every cell on every ray has the same length ds: transmittance scans need no Jacobian
// along the ray. Cells are NOT equal in volume: a cell's cross-section grows as s², which the
// gradient gather accounts for (see docs/methods.md §1). Continuous grid coordinates put cell
// centres at integers, like GridSpec.
#pragma once

#include <glm/glm.hpp>

#include "visopt/camera.h"
#include "visopt/grid.h"

namespace visopt {

struct FrustumGrid {
  glm::vec3 eye{0.f};
  glm::vec3 right{1.f, 0.f, 0.f}, up{0.f, 1.f, 0.f}, forward{0.f, 0.f, 1.f};
  float tanHalfFovX = 1.f, tanHalfFovY = 1.f;
  glm::ivec3 dims{1};
  float sNear = 0.f, sFar = 1.f;

  // Equal members: the same rays and cells (what a cache of a frustum's fields compares).
  bool operator==(const FrustumGrid&) const = default;

  float depthStep() const { return (sFar - sNear) / static_cast<float>(dims.z); }
  // g: world -> continuous grid coordinates.
  glm::vec3 toGrid(glm::vec3 world) const;
  // g^-1: continuous grid coordinates -> world.
  glm::vec3 toWorld(glm::vec3 grid) const;
  // Unit direction of the ray through continuous pixel coordinates (px, py).
  glm::vec3 rayDirection(float px, float py) const;

  // The camera's frustum at the given image size; [sNear, sFar] is clipped to the distances
  // from the eye to the points of `bounds`; depthCells == 0 picks one cell per half of the smallest
  // voxel spacing along the bounds' diagonal (`voxelSize`), capped at 1024.
  static FrustumGrid forCamera(const Camera& camera, int width, int height, const Bounds& bounds,
                               int depthCells, float voxelSize);
  // A square frustum from the point light towards `bounds`, wide enough to contain the bounding
  // sphere (at most 160° when the light is inside it), its depth clipped as forCamera's.
  static FrustumGrid forLight(const PointLight& light, const Bounds& bounds, glm::ivec3 dims,
                              float voxelSize);
};

}  // namespace visopt
