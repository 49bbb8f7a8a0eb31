// The grid updates of visibility_scan.h (Himmler & Günther 2026, Eqs. 10-13), arranged for speed.
// The same inputs, the same two passes per ray and the same results to float round-off;
// VisibilityScan stays as the reference the tests compare this kernel against. What differs
// (profile of the default scene: the reference scan was 54 % of the run, its trilinear samples the
// bulk of it):
//
// - One set of trilinear corners per cell serves mu, g, the product g mu of the occluder
//   statistic and every surface's phi (the reference finds the corners four times, and reloads
//   mu and g for g mu), and each field's precision is branched on once per cell, not per load.
// - The surfaces are sampled only until the ray is blocked, and only in the front-to-back pass.
// - exp is evaluated only when the optical depth changed (empty space keeps T).
// - With a skip grid (kernels/scan_skip.h), cells that can meet neither extinction, importance
//   nor a surface, and cells behind a surface without importance, load nothing.
// - With kBufferedCells > 0 the front-to-back pass keeps mu, g and T of each cell in a per-ray
//   buffer on the stack, so the back-to-front pass samples nothing and T never goes through the
//   frustum field. The CUDA backend compiles the unbuffered form (kBufferedCells is 0 in device
//   code: a per-thread buffer would live in local memory), which re-samples mu and g as the
//   reference does; rays longer than the buffer use the unbuffered form on the CPU as well.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/half.h"
#include "core/min_max.h"
#include "kernels/ray_box.h"
#include "kernels/scan_skip.h"
#include "kernels/visibility_scan.h"

namespace visopt {

// The eight voxels around a continuous index position p (clamped to the grid, as
// FieldView::sample clamps) and their trilinear weights.
struct TrilinearCorners {
  size_t index[8];
  float fx, fy, fz;

  VISOPT_HD VISOPT_INLINE TrilinearCorners(glm::vec3 p, glm::ivec3 dims) {
    const float px = minOf(maxOf(p.x, 0.f), float(dims.x - 1));
    const float py = minOf(maxOf(p.y, 0.f), float(dims.y - 1));
    const float pz = minOf(maxOf(p.z, 0.f), float(dims.z - 1));
    const int i0 = int(px), j0 = int(py), k0 = int(pz);
    fx = px - float(i0);
    fy = py - float(j0);
    fz = pz - float(k0);
    const size_t sx = i0 + 1 < dims.x ? 1 : 0;
    const size_t sy = j0 + 1 < dims.y ? size_t(dims.x) : 0;
    const size_t sz = k0 + 1 < dims.z ? size_t(dims.x) * size_t(dims.y) : 0;
    const size_t base = (size_t(k0) * size_t(dims.y) + size_t(j0)) * size_t(dims.x) + size_t(i0);
    // Corner c has +x when c & 1, +y when c & 2, +z when c & 4.
    for (int c = 0; c < 8; ++c)
      index[c] = base + ((c & 1) ? sx : 0) + ((c & 2) ? sy : 0) + ((c & 4) ? sz : 0);
  }

  // The field's values at the corners: one precision test for all eight loads.
  VISOPT_HD VISOPT_INLINE void load(const FieldView& f, float v[8]) const {
    if (f.half) {
      const Half* h = static_cast<const Half*>(f.data);
      for (int c = 0; c < 8; ++c) v[c] = halfToFloat(h[index[c]]);
    } else {
      const float* s = static_cast<const float*>(f.data);
      for (int c = 0; c < 8; ++c) v[c] = s[index[c]];
    }
  }

  // Trilinear interpolation of corner values, in FieldView::sample's order of operations.
  VISOPT_HD VISOPT_INLINE float interpolate(const float v[8]) const {
    const float c00 = v[0] + fx * (v[1] - v[0]), c10 = v[2] + fx * (v[3] - v[2]);
    const float c01 = v[4] + fx * (v[5] - v[4]), c11 = v[6] + fx * (v[7] - v[6]);
    const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
  }

  // Trilinear interpolation of the per-corner products a_c b_c, in the order of
  // VisibilityScan::importantExtinction.
  VISOPT_HD VISOPT_INLINE float interpolateProduct(const float a[8], const float b[8]) const {
    float acc = 0.f;
    for (int c = 0; c < 8; ++c) {
      const float w =
          ((c & 1) ? fx : 1.f - fx) * ((c & 2) ? fy : 1.f - fy) * ((c & 4) ? fz : 1.f - fz);
      acc += w * a[c] * b[c];
    }
    return acc;
  }
};

// One ray's geometry: its origin and direction in index space (cell k's centre is o + depth(k)
// d), its screen weight and its pixel's solid angle.
struct ScanRay {
  glm::vec3 o, d;
  float w, omega;
};

// The cells [first, last) of a ray that may lie in the volume, [-0.5, dims - 0.5] in index
// space (sampleAt). The interval is widened by a cell or two to either side so that rounding
// never drops a cell; inside it the per-cell test still decides, so nothing changes but the
// work. A ray that misses the box gets an empty range; a non-finite one the whole ray.
struct CellRange {
  int first = 0, last = 0;
};

VISOPT_HD VISOPT_INLINE CellRange cellsInVolume(const FrustumMap& f, const ScanRay& ray,
                                                glm::vec3 hi) {
  const int nz = f.dims.z;
  const RayInterval box = intersectBox(ray.o + 0.5f, ray.d, hi + 0.5f);  // depth along the ray
  const float k0 = (box.t0 - f.sNear) / f.ds - 0.5f, k1 = (box.t1 - f.sNear) / f.ds - 0.5f;
  if (!(k0 == k0) || !(k1 == k1)) return {0, nz};
  if (box.t1 < box.t0) return {0, 0};
  const float first = floorf(minOf(maxOf(k0, -4.f), float(nz))) - 1.f;
  const float last = ceilf(minOf(maxOf(k1, -4.f), float(nz))) + 2.f;
  return {int(minOf(maxOf(first, 0.f), float(nz))), int(minOf(maxOf(last, 0.f), float(nz)))};
}

VISOPT_HD VISOPT_INLINE ScanRay scanRayOf(const VisibilityScan& scan, int i, int j) {
  const FrustumMap& f = scan.frustum;
  ScanRay r;
  r.o = scan.volume.toIndex(f.eye);
  r.d = scan.volume.directionToIndex(f.rayDirection(float(i), float(j)));
  r.w = scan.weights.active() ? scan.weights.at(i, j, f.dims.x, f.dims.y) : 1.f;
  r.omega = scan.solidAngle(i, j);
  return r;
}

// The front-to-back pass of one ray: exclusive transmittance T; a surface blocks everything from
// its first cell. Hands each cell's mu, g (unweighted) and T to cell(k, m, g, t) and adds the
// ray's V_occ terms to sums.
template <class CellSink>
VISOPT_HD VISOPT_INLINE void frontToBack(const VisibilityScan& scan, const ScanRay& ray,
                                         ScanSums& sums, CellSink&& cell) {
  const FrustumMap& frustum = scan.frustum;
  const int nz = frustum.dims.z;
  const float ds = frustum.ds;
  const glm::ivec3 dims = scan.mu.dims;
  const glm::vec3 hi = glm::vec3(scan.volume.dims) - 0.5f;
  float opticalDepth = 0.f, importantDepth = 0.f;
  float t = 1.f, tDepth = 0.f;  // t = exp(-tDepth), recomputed when the optical depth moves
  bool blocked = false;
  // Most cells of a frustum lie outside the volume (63 % of the Cranium CT's view and light
  // cells): bound the ray to the volume once, and before and past it only pass the cells on.
  const CellRange inside = cellsInVolume(frustum, ray, hi);
  for (int k = 0; k < inside.first; ++k) cell(k, 0.f, 0.f, 1.f);
  for (int k = inside.first; k < inside.last; ++k) {
    const float depth = frustum.depthOf(float(k));
    const glm::vec3 idx = ray.o + depth * ray.d;
    // The volume occupies its voxels' cells, [-0.5, dims - 0.5] in index space (sampleAt).
    const bool in = idx.x >= -0.5f && idx.y >= -0.5f && idx.z >= -0.5f && idx.x <= hi.x &&
                    idx.y <= hi.y && idx.z <= hi.z;
    float m = 0.f, g = 0.f, gm = 0.f;  // gm: the interpolated product g_v mu_v
    if (in) {
      // What this cell can meet (kernels/scan_skip.h): behind a surface only importance matters.
      const uint8_t meets = scan.skip.at(idx);
      const bool important = (meets & kScanHasImportance) != 0;
      const bool matter = important || (!blocked && (meets & kScanHasExtinction) != 0);
      const bool surface = !blocked && scan.surfaces.count > 0 && (meets & kScanHasSurface) != 0;
      if (matter || surface) {
        const TrilinearCorners corners(idx, dims);
        if (matter) {
          float muC[8], gC[8];
          corners.load(scan.mu, muC);
          m = corners.interpolate(muC);
          if (important) {
            corners.load(scan.importance, gC);
            g = corners.interpolate(gC);
            if (g > 0.f) gm = corners.interpolateProduct(muC, gC);
          }
        }
        for (int s = 0; s < scan.surfaces.count && surface && !blocked; ++s) {
          float phiC[8];
          corners.load(scan.surfaces.phi[s], phiC);
          blocked = corners.interpolate(phiC) < 0.f;
        }
      }
    }
    if (!blocked && opticalDepth != tDepth) {
      tDepth = opticalDepth;
      t = expf(-opticalDepth);
    }
    const float tCell = blocked ? 0.f : t;
    cell(k, m, g, tCell);
    opticalDepth += m * ds;
    if (in && g > 0.f) {
      // The statistic V_occ (ScanSums): screen weights scale importance as in the energy.
      gm *= minOf(ray.w, 1.f / maxOf(g, 1e-30f));
      const double dV = double(ray.omega) * double(depth) * double(depth) * double(ds);
      sums.importantSeen += double(gm * tCell) * dV;
      sums.importantSeenAlone += double(gm * expf(-importantDepth)) * dV;
      importantDepth += gm * ds;
    }
  }
  // Past the volume nothing changes: the last cell's transmittance carries on.
  if (!blocked && opticalDepth != tDepth) t = expf(-opticalDepth);
  const float tPast = blocked ? 0.f : t;
  for (int k = inside.last; k < nz; ++k) cell(k, 0.f, 0.f, tPast);
}

// Rays of up to this many depth cells are scanned with a buffer (per ray: 3 floats per cell on
// the stack, 48 KiB, well inside a oneTBB worker's stack). One cell per half voxel covers a
// 1180-voxel diagonal.
constexpr int kScanBufferCells = 4096;

// One ray per launch.
template <int kBufferedCells>
struct FastVisibilityScan {
  VisibilityScan scan;  // the inputs, as for the reference

  VISOPT_HD ScanSums operator()(int64_t rayIndex) const {
#if defined(__CUDA_ARCH__)
    constexpr int kBuffer = 0;
#else
    constexpr int kBuffer = kBufferedCells;
#endif
    const FrustumMap& frustum = scan.frustum;
    const FrustumFieldView& out = scan.out;
    const int i = int(rayIndex % frustum.dims.x), j = int(rayIndex / frustum.dims.x);
    const ScanRay ray = scanRayOf(scan, i, j);
    const glm::ivec3 dims = scan.mu.dims;
    const glm::vec3 hi = glm::vec3(scan.volume.dims) - 0.5f;

    float mBuf[kBuffer > 0 ? kBuffer : 1], gBuf[kBuffer > 0 ? kBuffer : 1],
        tBuf[kBuffer > 0 ? kBuffer : 1];
    ScanSums sums;
    frontToBack(scan, ray, sums, [&](int k, float m, float g, float t) {
      if constexpr (kBuffer > 0) {
        mBuf[k] = m;
        gBuf[k] = g;
        // What the reference reads back from the frustum field (fp16 rounds it).
        tBuf[k] = out.half() ? halfToFloat(floatToHalf(t)) : t;
      } else {
        out.store(out.index(i, j, k), t);
      }
    });

    // Back to front: G (behind, weighted by s^2) and d = g T - G.
    const float ds = frustum.ds;
    float behind = 0.f;      // sum_{j>k} g mu T s^2 ds
    float runningMax = 0.f;  // max_{j>k} g
    for (int k = frustum.dims.z - 1; k >= 0; --k) {
      const float s = frustum.depthOf(float(k));
      const size_t c = out.index(i, j, k);
      float m = 0.f, g = 0.f, tCell;
      if constexpr (kBuffer > 0) {
        m = mBuf[k];
        g = gBuf[k];
        tCell = tBuf[k];
      } else {
        const glm::vec3 idx = ray.o + s * ray.d;
        if (idx.x >= -0.5f && idx.y >= -0.5f && idx.z >= -0.5f && idx.x <= hi.x && idx.y <= hi.y &&
            idx.z <= hi.z) {
          const TrilinearCorners corners(idx, dims);
          float v[8];
          corners.load(scan.mu, v);
          m = corners.interpolate(v);
          corners.load(scan.importance, v);
          g = corners.interpolate(v);
        }
        tCell = out.load(c);
      }
      g = minOf(g * ray.w, 1.f);
      if (scan.behindMax.valid()) {
        scan.behindMax.store(scan.behindMax.index(i, j, k), runningMax);
        runningMax = maxOf(runningMax, g);
      }
      const float s2 = s * s;
      out.store(c, g * tCell - behind / s2);
      const float gmt = g * m * tCell;
      behind += gmt * s2 * ds;
      const double dV = double(ray.omega) * double(s2) * double(ds);
      sums.gMuT += double(gmt) * dV;
      sums.gMu += double(g * m) * dV;
    }
    return sums;
  }
};

}  // namespace visopt
