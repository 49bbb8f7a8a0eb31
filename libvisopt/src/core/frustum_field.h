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
#include "core/half.h"
#include "core/hd.h"
#include "core/min_max.h"
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
  // Stores kTileRays values at `first` = index(i, j, k) of a tile's first ray i: one tile row at
  // one depth, contiguous, with one precision test (fp16 saturates as FieldView::store).
  VISOPT_HD VISOPT_INLINE void storeRow(size_t first, const float* v) const {
    if (storage.half) {
      Half* h = static_cast<Half*>(storage.data) + first;
      for (int l = 0; l < kTileRays; ++l) h[l] = floatToHalf(minOf(maxOf(v[l], -65504.f), 65504.f));
    } else {
      float* f = static_cast<float*>(storage.data) + first;
      for (int l = 0; l < kTileRays; ++l) f[l] = v[l];
    }
  }

  // Trilinear interpolation at continuous frustum coordinates (cell centres at integers),
  // clamped to the grid as FieldView::sample clamps, in its order of operations. The eight
  // corners lie in four columns (i, j) of a tile, two depths each.
  VISOPT_HD VISOPT_INLINE float sample(glm::vec3 p) const {
    const float px = minOf(maxOf(p.x, 0.f), float(dims.x - 1));
    const float py = minOf(maxOf(p.y, 0.f), float(dims.y - 1));
    const float pz = minOf(maxOf(p.z, 0.f), float(dims.z - 1));
    const int i0 = int(px), j0 = int(py), k0 = int(pz);
    const int i1 = i0 + 1 < dims.x ? i0 + 1 : i0, j1 = j0 + 1 < dims.y ? j0 + 1 : j0;
    const size_t dk = k0 + 1 < dims.z ? kTileRays : 0;
    const float fx = px - float(i0), fy = py - float(j0), fz = pz - float(k0);
    const size_t c00 = index(i0, j0, k0), c10 = index(i1, j0, k0);
    const size_t c01 = index(i0, j1, k0), c11 = index(i1, j1, k0);
    float v[8];
    if (storage.half) {
      const Half* h = static_cast<const Half*>(storage.data);
      v[0] = halfToFloat(h[c00]), v[1] = halfToFloat(h[c10]);
      v[2] = halfToFloat(h[c01]), v[3] = halfToFloat(h[c11]);
      v[4] = halfToFloat(h[c00 + dk]), v[5] = halfToFloat(h[c10 + dk]);
      v[6] = halfToFloat(h[c01 + dk]), v[7] = halfToFloat(h[c11 + dk]);
    } else {
      const float* f = static_cast<const float*>(storage.data);
      v[0] = f[c00], v[1] = f[c10], v[2] = f[c01], v[3] = f[c11];
      v[4] = f[c00 + dk], v[5] = f[c10 + dk], v[6] = f[c01 + dk], v[7] = f[c11 + dk];
    }
    const float a00 = v[0] + fx * (v[1] - v[0]), a10 = v[2] + fx * (v[3] - v[2]);
    const float a01 = v[4] + fx * (v[5] - v[4]), a11 = v[6] + fx * (v[7] - v[6]);
    const float a0 = a00 + fy * (a10 - a00), a1 = a01 + fy * (a11 - a01);
    return a0 + fz * (a1 - a0);
  }
  // True when p lies within the cell-centred grid's support [-0.5, dims - 0.5].
  VISOPT_HD bool inside(glm::vec3 p) const {
    return p.x >= -0.5f && p.y >= -0.5f && p.z >= -0.5f && p.x <= float(dims.x) - 0.5f &&
           p.y <= float(dims.y) - 0.5f && p.z <= float(dims.z) - 0.5f;
  }
};

}  // namespace visopt
