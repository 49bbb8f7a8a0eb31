// Frustum fields sampled at 16 points at once on the CPU backend (the extinction step's rows,
// the importance-behind gather): the points' frustum coordinates in vector lanes, then the eight
// trilinear corners of all lanes as one gather each (host/simd_gather.h). The values are
// FrustumMap::toGrid's and FrustumFieldView::sample's; only the compiler's contraction of
// multiply-adds may round differently. Host only; the including unit builds with
// -fno-trapping-math so that the selects vectorise (libvisopt/CMakeLists.txt).
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "core/half.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "host/simd_gather.h"

namespace visopt {

constexpr int kFrustumLanes = kGatherLanes;

// FrustumMap::toGrid with its "behind the eye" return as a select, so that a loop over lanes
// vectorises: the same operations in the same order for a point in front of the eye.
VISOPT_INLINE glm::vec3 toGridSelect(const FrustumMap& f, glm::vec3 x) {
  const glm::vec3 d = x - f.eye;
  const float z = glm::dot(d, f.forward);
  const float s = glm::length(d);
  const float u = glm::dot(d, f.right) / (z * f.tanX);
  const float v = glm::dot(d, f.up) / (z * f.tanY);
  // Every value computed, then selected: arithmetic on one side of a ?: alone keeps g++ from
  // if-converting the loop (it might raise a floating-point exception the other side avoids).
  const float gx = (u + 1.f) * 0.5f * float(f.dims.x) - 0.5f;
  const float gy = (v + 1.f) * 0.5f * float(f.dims.y) - 0.5f;
  const float gz = (s - f.sNear) / f.ds - 0.5f;
  const bool front = z > 0.f;
  return glm::vec3(front ? gx : -1e30f, front ? gy : -1e30f, front ? gz : -1e30f);
}

// FrustumFieldView::inside and ::sample at kFrustumLanes positions (0 outside the grid and in lanes
// n and up), in sample's order of operations; the eight corners of all lanes are gathered
// together (host/simd_gather.h).
template <class Storage>
inline void sampleFrustumLanes(const FrustumFieldView& d, const float* x, const float* y,
                               const float* z, int n, float* out) {
  const glm::ivec3 dims = d.dims;
  const int nz = dims.z, tilesX = d.tilesX;
  const float hx = float(dims.x) - 0.5f, hy = float(dims.y) - 0.5f, hz = float(dims.z) - 0.5f;
  alignas(64) int corner[8][kFrustumLanes], in[kFrustumLanes];
  alignas(64) float fx[kFrustumLanes], fy[kFrustumLanes], fz[kFrustumLanes], v[8][kFrustumLanes];
  auto index = [&](int i, int j, int k) {
    return ((j * tilesX + i / kTileRays) * nz + k) * kTileRays + i % kTileRays;
  };
  for (int l = 0; l < kFrustumLanes; ++l) {
    in[l] = (l < n) & (x[l] >= -0.5f) & (y[l] >= -0.5f) & (z[l] >= -0.5f) & (x[l] <= hx) &
            (y[l] <= hy) & (z[l] <= hz);
    // Lanes outside sample the grid's first cell (maxOf(NaN, 0) is 0) and are discarded below.
    const float px = in[l] ? minOf(maxOf(x[l], 0.f), float(dims.x - 1)) : 0.f;
    const float py = in[l] ? minOf(maxOf(y[l], 0.f), float(dims.y - 1)) : 0.f;
    const float pz = in[l] ? minOf(maxOf(z[l], 0.f), float(dims.z - 1)) : 0.f;
    const int i0 = int(px), j0 = int(py), k0 = int(pz);
    const int i1 = i0 + 1 < dims.x ? i0 + 1 : i0, j1 = j0 + 1 < dims.y ? j0 + 1 : j0;
    const int dk = k0 + 1 < dims.z ? kTileRays : 0;
    fx[l] = px - float(i0), fy[l] = py - float(j0), fz[l] = pz - float(k0);
    corner[0][l] = index(i0, j0, k0), corner[1][l] = index(i1, j0, k0);
    corner[2][l] = index(i0, j1, k0), corner[3][l] = index(i1, j1, k0);
    for (int c = 0; c < 4; ++c) corner[c + 4][l] = corner[c][l] + dk;
  }
  for (int c = 0; c < 8; ++c) gatherLanes<Storage>(d.storage.data, corner[c], v[c]);
  for (int l = 0; l < kFrustumLanes; ++l) {
    const float a00 = v[0][l] + fx[l] * (v[1][l] - v[0][l]);
    const float a10 = v[2][l] + fx[l] * (v[3][l] - v[2][l]);
    const float a01 = v[4][l] + fx[l] * (v[5][l] - v[4][l]);
    const float a11 = v[6][l] + fx[l] * (v[7][l] - v[6][l]);
    const float a0 = a00 + fy[l] * (a10 - a00), a1 = a01 + fy[l] * (a11 - a01);
    out[l] = in[l] ? a0 + fz[l] * (a1 - a0) : 0.f;
  }
}

// Whether a frustum field's cells can be gathered with 32-bit indices.
inline bool frustumGathersInLanes(const FrustumFieldView& d) {
  return d.storage.size() < (size_t(1) << 31);
}

// gatherFrustum's rules at kFrustumLanes frustum positions (lanes n and up: 0): 0 where the field
// is absent or the position outside it. Fields past 32-bit indices are sampled lane by lane.
inline void sampleFrustumField(const FrustumFieldView& d, const float* x, const float* y,
                               const float* z, int n, float* out) {
  if (!d.valid()) {
    for (int l = 0; l < kFrustumLanes; ++l) out[l] = 0.f;
  } else if (!frustumGathersInLanes(d)) {
    for (int l = 0; l < kFrustumLanes; ++l) {
      const glm::vec3 p(x[l], y[l], z[l]);
      out[l] = l < n && d.inside(p) ? d.sample(p) : 0.f;
    }
  } else if (d.half()) {
    sampleFrustumLanes<Half>(d, x, y, z, n, out);
  } else {
    sampleFrustumLanes<float>(d, x, y, z, n, out);
  }
}

}  // namespace visopt
