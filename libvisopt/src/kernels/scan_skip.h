// Empty-space skipping for the grid updates (kernels/visibility_scan_fast.h): a coarse grid of
// bricks of kScanSkipBrick^3 voxels, each flagged with what a trilinear sample whose lower corner
// lies in the brick can meet: extinction (mu != 0), importance (g != 0), and a context surface
// (phi <= 0 in some surface). A sample's corners lie in its brick or in the next brick along +x,
// +y, +z, so each brick's flags are the union of its own voxels' flags and those of the seven
// bricks above it.
//
// A cell whose brick has no extinction samples mu = 0 exactly; no importance, g = 0 exactly; no
// surface, min phi > 0 (a convex combination of positive values cannot round below zero), so it
// is not opaque. Cells behind a surface (T = 0) without importance need neither mu nor g: they
// add nothing to d, G or the sums. So the fast scan skips those loads and its results are the
// same as without skipping, bit for bit (the tests hold it to that).
//
// On a real CT most frustum cells are air in front of the skin or unimportant tissue behind it.
// Built once per iteration (mu and phi change with every step), in two cheap passes.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "core/voxel_ijk.h"
#include "kernels/surface_set.h"

namespace visopt {

constexpr int kScanSkipShift = 2;  // bricks of 4^3 voxels
constexpr int kScanSkipBrick = 1 << kScanSkipShift;

enum ScanSkipFlag : uint8_t {
  kScanHasExtinction = 1,
  kScanHasImportance = 2,
  kScanHasSurface = 4,
  kScanEverything = 7,
};

inline glm::ivec3 scanSkipBricks(glm::ivec3 voxels) {
  return (voxels + (kScanSkipBrick - 1)) / kScanSkipBrick;
}

struct ScanSkipGrid {
  const uint8_t* flags = nullptr;  // per brick, x fastest; null: no skipping
  glm::ivec3 bricks{0};
  glm::ivec3 voxels{0};

  // The flags of the brick holding the lower trilinear corner of index position p (clamped to
  // the grid as TrilinearCorners clamps); everything when there is no grid.
  VISOPT_HD VISOPT_INLINE uint8_t at(glm::vec3 p) const {
    if (!flags) return kScanEverything;
    const int i = int(minOf(maxOf(p.x, 0.f), float(voxels.x - 1))) >> kScanSkipShift;
    const int j = int(minOf(maxOf(p.y, 0.f), float(voxels.y - 1))) >> kScanSkipShift;
    const int k = int(minOf(maxOf(p.z, 0.f), float(voxels.z - 1))) >> kScanSkipShift;
    return flags[(size_t(k) * size_t(bricks.y) + size_t(j)) * size_t(bricks.x) + size_t(i)];
  }
};

// Pass 1: each brick's own voxels.
struct ScanSkipOwnFlags {
  FieldView mu, importance;
  SurfaceSet surfaces;
  glm::ivec3 bricks{0};
  uint8_t* own = nullptr;

  VISOPT_HD void operator()(int64_t brick) const {
    const auto [bx, by, bz] = voxelIjk(brick, bricks);
    const glm::ivec3 lo = glm::ivec3(bx, by, bz) * kScanSkipBrick;
    const glm::ivec3 hi = glm::min(lo + kScanSkipBrick, mu.dims);
    bool extinction = false, important = false, surface = false;
    for (int k = lo.z; k < hi.z; ++k)
      for (int j = lo.y; j < hi.y; ++j) {
        const size_t row = mu.index(lo.x, j, k);
        for (int i = 0; i < hi.x - lo.x; ++i) {
          const size_t v = row + size_t(i);
          // != 0 and !(> 0) also flag NaN: a broken value is never skipped.
          extinction = extinction || mu.load(v) != 0.f;
          important = important || importance.load(v) != 0.f;
          for (int s = 0; s < surfaces.count; ++s)
            surface = surface || !(surfaces.phi[s].load(v) > 0.f);
        }
      }
    own[brick] = uint8_t((extinction ? kScanHasExtinction : 0) |
                         (important ? kScanHasImportance : 0) | (surface ? kScanHasSurface : 0));
  }
};

// Pass 2: the union over the brick and the bricks above it along each axis.
struct ScanSkipDilate {
  glm::ivec3 bricks{0};
  const uint8_t* own = nullptr;
  uint8_t* flags = nullptr;

  VISOPT_HD void operator()(int64_t brick) const {
    const auto [bx, by, bz] = voxelIjk(brick, bricks);
    uint8_t f = 0;
    for (int dz = 0; dz < 2 && bz + dz < bricks.z; ++dz)
      for (int dy = 0; dy < 2 && by + dy < bricks.y; ++dy)
        for (int dx = 0; dx < 2 && bx + dx < bricks.x; ++dx)
          f |= own[(size_t(bz + dz) * size_t(bricks.y) + size_t(by + dy)) * size_t(bricks.x) +
                   size_t(bx + dx)];
    flags[brick] = f;
  }
};

}  // namespace visopt
