// A field on a frustum grid (rays i, j; depth cells k), stored in tiles of kTileRays adjacent
// rays along i: the values of one tile at one depth are contiguous, and a tile's depths follow
// each other,
//   offset(i, j, k) = ((j * tilesX + i / kTileRays) * nz + k) * kTileRays + i % kTileRays.
// A CPU thread scanning the rays of a tile one after another walks its cells 64 bytes apart,
// line after line, in a block that stays in cache for the tile's next rays (with rays plane after
// plane, dims.x * dims.y apart, every cell of a ray was a new page: the stores in the scan's
// back-to-front pass took 40 % of its time in the profile). One CUDA warp of 32 adjacent rays
// stores two contiguous 64-byte runs per depth. Rays past dims.x in the last tile are padding,
// never read.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "visopt/field.h"

namespace visopt {

constexpr int kTileRays = 16;

// The dims of the Field3D that stores a frustum field of `frustumDims`.
inline glm::ivec3 frustumStorageDims(glm::ivec3 frustumDims) {
  const int tilesX = (frustumDims.x + kTileRays - 1) / kTileRays;
  return glm::ivec3(kTileRays, frustumDims.z, tilesX * frustumDims.y);
}

struct FrustumFieldView {
  FieldView storage;
  glm::ivec3 dims{0};  // the frustum grid's (rays x, rays y, depth cells)
  int tilesX = 0;

  FrustumFieldView() = default;
  FrustumFieldView(const Field3D& f, glm::ivec3 frustumDims)
      : storage(f), dims(frustumDims), tilesX((frustumDims.x + kTileRays - 1) / kTileRays) {}

  VISOPT_HD bool valid() const { return storage.valid(); }
  VISOPT_HD bool half() const { return storage.half; }
  VISOPT_HD VISOPT_INLINE size_t index(int i, int j, int k) const {
    const size_t tile = size_t(j) * size_t(tilesX) + size_t(i / kTileRays);
    return (tile * size_t(dims.z) + size_t(k)) * kTileRays + size_t(i % kTileRays);
  }
  VISOPT_HD VISOPT_INLINE float load(size_t c) const { return storage.load(c); }
  VISOPT_HD VISOPT_INLINE void store(size_t c, float v) const { storage.store(c, v); }
  VISOPT_HD VISOPT_INLINE float at(int i, int j, int k) const { return load(index(i, j, k)); }

  // Trilinear interpolation at continuous frustum coordinates (cell centres at integers),
  // clamped to the grid as FieldView::sample clamps.
  VISOPT_HD VISOPT_INLINE float sample(glm::vec3 p) const {
    p = glm::clamp(p, glm::vec3(0.f), glm::vec3(dims - 1));
    const glm::ivec3 i0 = glm::ivec3(p);
    const glm::ivec3 i1 = glm::min(i0 + 1, dims - 1);
    const glm::vec3 f = p - glm::vec3(i0);
    const float c000 = at(i0.x, i0.y, i0.z), c100 = at(i1.x, i0.y, i0.z);
    const float c010 = at(i0.x, i1.y, i0.z), c110 = at(i1.x, i1.y, i0.z);
    const float c001 = at(i0.x, i0.y, i1.z), c101 = at(i1.x, i0.y, i1.z);
    const float c011 = at(i0.x, i1.y, i1.z), c111 = at(i1.x, i1.y, i1.z);
    const float c00 = c000 + f.x * (c100 - c000), c10 = c010 + f.x * (c110 - c010);
    const float c01 = c001 + f.x * (c101 - c001), c11 = c011 + f.x * (c111 - c011);
    const float c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
    return c0 + f.z * (c1 - c0);
  }
  // True when p lies within the cell-centred grid's support [-0.5, dims - 0.5].
  VISOPT_HD bool inside(glm::vec3 p) const {
    return p.x >= -0.5f && p.y >= -0.5f && p.z >= -0.5f && p.x <= float(dims.x) - 0.5f &&
           p.y <= float(dims.y) - 0.5f && p.z <= float(dims.z) - 0.5f;
  }
};

}  // namespace visopt
