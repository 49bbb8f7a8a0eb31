// The front-to-back pass of the grid updates (Himmler & Günther 2026, Eqs. 10-13) for a packet of
// kTileRays adjacent rays at once, the CPU backend's form of kernels/visibility_scan_fast.h's
// frontToBack: SIMD lanes across rays, so the packet's cells at one depth are a contiguous row
// and every per-cell quantity (position, trilinear corners and weights, the interpolations, the
// transmittance's exp) is one vector operation for all rays; the eight corner loads of each field
// are gathers. Each lane computes what frontToBack computes for its ray, in the same order, with
// two differences of round-off size: exp is rayExp2 (3e-7 relative, a polynomial the compiler
// vectorises; expf is a library call per lane) and the compiler may contract multiply-adds
// differently. Loads are branch-free: every lane's corners are in the grid (clamped as
// TrilinearCorners clamps) and a lane that needs no value discards it, so what a lane stores
// does not depend on its neighbours. The whole packet skips a field when no lane needs it
// (kernels/scan_skip.h), so empty space still loads nothing.
//
// Profile of the per-ray form this replaces (bench_scan, 128^3 volume, 512^2 view): half of its
// time went to the strided per-lane stores of the tile buffer (one cache line per cell) and to
// scalar index and interpolation arithmetic; the loads themselves were a minority. An earlier
// lanes pass was slower than the per-ray one (docs/optimization-benchmarks.md): it sampled every
// field in every cell and loaded fp16 values one by one. This one skips per packet, gathers fp16
// as 32-bit words, and finds the skip bricks in vector lanes.
//
// Host only: the CUDA backend runs one thread per ray (FastVisibilityScan<0>).
#pragma once

#include <algorithm>
#include <cstdint>
#include <type_traits>

#include "core/frustum_field.h"
#include "core/half.h"
#include "host/simd_gather.h"
#include "kernels/ray_fast_math.h"
#include "kernels/visibility_scan_fast.h"

namespace visopt {

constexpr int kPacketRays = kTileRays;
static_assert(kPacketRays == kGatherLanes);

// The packet's rays: a shared origin (the eye or the light, in index space) and one direction,
// screen weight and solid angle per lane. Lanes past the frustum's edge are inactive.
struct RayPacket {
  glm::vec3 o{0.f};
  alignas(64) float dx[kPacketRays] = {}, dy[kPacketRays] = {}, dz[kPacketRays] = {};
  alignas(64) float w[kPacketRays] = {}, omega[kPacketRays] = {};
  alignas(64) int active[kPacketRays] = {};
  int lanes = 0;
};

// Whether every field the scan samples is stored in Storage (float or Half) and the volume is
// small enough for 32-bit gather indices; otherwise the scan takes the per-ray pass.
template <class Storage>
bool packetScanApplies(const VisibilityScan& scan) {
  const bool half = std::is_same_v<Storage, Half>;
  if (scan.mu.half != half || scan.importance.half != half) return false;
  for (int s = 0; s < scan.surfaces.count; ++s)
    if (scan.surfaces.phi[s].half != half) return false;
  return scan.mu.size() < (size_t(1) << 31);
}

namespace packet {

// e^-x for x >= 0 (kernels/ray_fast_math.h, relative error below 3e-7): a polynomial the lanes
// vectorise, where expf is a library call per lane (this unit builds with -fno-trapping-math, so
// rayExp2's range clamps if-convert).
inline float expNeg(float x) {
  return rayExp2(-1.44269504088896f * x);
}

// The eight corners of each lane's trilinear sample (as TrilinearCorners: clamped to the grid,
// corner c has +x when c & 1, +y when c & 2, +z when c & 4).
struct Corners {
  alignas(64) int index[8][kPacketRays];
  alignas(64) float fx[kPacketRays], fy[kPacketRays], fz[kPacketRays];

  void set(const float* px, const float* py, const float* pz, glm::ivec3 dims) {
    const float hx = float(dims.x - 1), hy = float(dims.y - 1), hz = float(dims.z - 1);
    const int rowY = dims.x, rowZ = dims.x * dims.y;
    for (int l = 0; l < kPacketRays; ++l) {
      // maxOf(NaN, 0) is 0: a lane whose ray is not finite keeps its corners in the grid.
      const float x = minOf(maxOf(px[l], 0.f), hx);
      const float y = minOf(maxOf(py[l], 0.f), hy);
      const float z = minOf(maxOf(pz[l], 0.f), hz);
      const int i0 = int(x), j0 = int(y), k0 = int(z);
      fx[l] = x - float(i0);
      fy[l] = y - float(j0);
      fz[l] = z - float(k0);
      const int sx = i0 + 1 < dims.x ? 1 : 0;
      const int sy = j0 + 1 < dims.y ? rowY : 0;
      const int sz = k0 + 1 < dims.z ? rowZ : 0;
      const int base = (k0 * dims.y + j0) * dims.x + i0;
      index[0][l] = base;
      index[1][l] = base + sx;
      index[2][l] = base + sy;
      index[3][l] = base + sx + sy;
      index[4][l] = base + sz;
      index[5][l] = base + sx + sz;
      index[6][l] = base + sy + sz;
      index[7][l] = base + sx + sy + sz;
    }
  }

  // The field's values at the corners, per lane (host/simd_gather.h).
  template <class Storage>
  void load(const FieldView& f, float v[8][kPacketRays]) const {
    for (int c = 0; c < 8; ++c) gatherLanes<Storage>(f.data, index[c], v[c]);
  }

  // TrilinearCorners::interpolate per lane.
  void interpolate(const float v[8][kPacketRays], float* out) const {
    for (int l = 0; l < kPacketRays; ++l) {
      const float c00 = v[0][l] + fx[l] * (v[1][l] - v[0][l]);
      const float c10 = v[2][l] + fx[l] * (v[3][l] - v[2][l]);
      const float c01 = v[4][l] + fx[l] * (v[5][l] - v[4][l]);
      const float c11 = v[6][l] + fx[l] * (v[7][l] - v[6][l]);
      const float c0 = c00 + fy[l] * (c10 - c00), c1 = c01 + fy[l] * (c11 - c01);
      out[l] = c0 + fz[l] * (c1 - c0);
    }
  }

  // TrilinearCorners::interpolateProduct per lane.
  void interpolateProduct(const float a[8][kPacketRays], const float b[8][kPacketRays],
                          float* out) const {
    for (int l = 0; l < kPacketRays; ++l) {
      float acc = 0.f;
      for (int c = 0; c < 8; ++c) {
        const float w = ((c & 1) ? fx[l] : 1.f - fx[l]) * ((c & 2) ? fy[l] : 1.f - fy[l]) *
                        ((c & 4) ? fz[l] : 1.f - fz[l]);
        acc += w * a[c][l] * b[c][l];
      }
      out[l] = acc;
    }
  }
};

inline bool any(const int* mask) {
  int a = 0;
  for (int l = 0; l < kPacketRays; ++l) a |= mask[l];
  return a != 0;
}

}  // namespace packet

// The front-to-back pass of a packet: writes each cell's mu, g (unweighted) and exclusive
// transmittance T (rounded as the frustum field stores it) into rows k * kPacketRays + lane of
// bm, bg, bt (inactive lanes: zeros), and adds the packet's V_occ terms to sums. What
// frontToBack does per ray, lane by lane.
template <class Storage>
void frontToBackPacket(const VisibilityScan& scan, const RayPacket& rays, ScanSums& sums, float* bm,
                       float* bg, float* bt) {
  using packet::any;
  constexpr int L = kPacketRays;
  const FrustumMap& frustum = scan.frustum;
  const int nz = frustum.dims.z;
  const float ds = frustum.ds;
  const glm::ivec3 dims = scan.mu.dims;
  const glm::vec3 hi = glm::vec3(scan.volume.dims) - 0.5f;
  const bool roundT = scan.out.half();
  auto stored = [roundT](float t) { return roundT ? halfToFloat(floatToHalf(t)) : t; };

  // The cells any lane may find in the volume (cellsInVolume per ray); outside them every lane
  // passes its cells on.
  int kLo = nz, kHi = 0;
  for (int l = 0; l < rays.lanes; ++l) {
    const ScanRay ray{rays.o, {rays.dx[l], rays.dy[l], rays.dz[l]}, rays.w[l], rays.omega[l]};
    const CellRange r = cellsInVolume(frustum, ray, hi);
    if (r.first < r.last) {
      kLo = std::min(kLo, r.first);
      kHi = std::max(kHi, r.last);
    }
  }
  if (kLo >= kHi) kLo = kHi = nz;
  for (int k = 0; k < kLo; ++k)
    for (int l = 0; l < L; ++l) {
      bm[k * L + l] = bg[k * L + l] = 0.f;
      bt[k * L + l] = rays.active[l] ? 1.f : 0.f;
    }

  alignas(64) float opticalDepth[L] = {}, importantDepth[L] = {}, tDepth[L] = {};
  alignas(64) float t[L];
  alignas(64) int blocked[L] = {};
  alignas(64) double seen[L] = {}, seenAlone[L] = {};
  for (int l = 0; l < L; ++l) t[l] = 1.f;

  const uint8_t* const skipFlags = scan.skip.flags;
  const glm::ivec3 skipBricks = scan.skip.bricks;
  const glm::vec3 skipHi = glm::vec3(scan.skip.voxels - 1);
  packet::Corners corners;
  alignas(64) float px[L], py[L], pz[L], m[L], g[L], gm[L], value[L];
  alignas(64) float muC[8][L], gC[8][L], phiC[8][L];
  alignas(64) int in[L], brick[L], matter[L], important[L], surface[L], meets[L], update[L];
  for (int k = kLo; k < kHi; ++k) {
    const float depth = frustum.depthOf(float(k));
    for (int l = 0; l < L; ++l) {
      px[l] = rays.o.x + depth * rays.dx[l];
      py[l] = rays.o.y + depth * rays.dy[l];
      pz[l] = rays.o.z + depth * rays.dz[l];
      // The volume occupies its voxels' cells, [-0.5, dims - 0.5] in index space (sampleAt).
      in[l] = rays.active[l] & (px[l] >= -0.5f) & (py[l] >= -0.5f) & (pz[l] >= -0.5f) &
              (px[l] <= hi.x) & (py[l] <= hi.y) & (pz[l] <= hi.z);
    }
    // What each lane's cell can meet (kernels/scan_skip.h): behind a surface only importance.
    if (skipFlags) {
      // ScanSkipGrid::at per lane: the brick indices in vector lanes, then the byte loads.
      for (int l = 0; l < L; ++l) {
        const int bi = int(minOf(maxOf(px[l], 0.f), skipHi.x)) >> kScanSkipShift;
        const int bj = int(minOf(maxOf(py[l], 0.f), skipHi.y)) >> kScanSkipShift;
        const int bk = int(minOf(maxOf(pz[l], 0.f), skipHi.z)) >> kScanSkipShift;
        brick[l] = in[l] ? (bk * skipBricks.y + bj) * skipBricks.x + bi : 0;
      }
      for (int l = 0; l < L; ++l) meets[l] = in[l] ? skipFlags[brick[l]] : 0;
    } else {
      for (int l = 0; l < L; ++l) meets[l] = in[l] ? kScanEverything : 0;
    }
    for (int l = 0; l < L; ++l) {
      important[l] = (meets[l] & kScanHasImportance) != 0;
      matter[l] = important[l] | (!blocked[l] & ((meets[l] & kScanHasExtinction) != 0));
      surface[l] = (scan.surfaces.count > 0) & !blocked[l] & ((meets[l] & kScanHasSurface) != 0);
      m[l] = g[l] = gm[l] = 0.f;
    }
    const bool anyMatter = any(matter), anySurface = any(surface);
    if (anyMatter || anySurface) {
      corners.set(px, py, pz, dims);
      if (anyMatter) {
        corners.load<Storage>(scan.mu, muC);
        corners.interpolate(muC, value);
        for (int l = 0; l < L; ++l) m[l] = matter[l] ? value[l] : 0.f;
        if (any(important)) {
          corners.load<Storage>(scan.importance, gC);
          corners.interpolate(gC, value);
          for (int l = 0; l < L; ++l) g[l] = important[l] ? value[l] : 0.f;
          corners.interpolateProduct(muC, gC, value);
          for (int l = 0; l < L; ++l) gm[l] = g[l] > 0.f ? value[l] : 0.f;
        }
      }
      for (int s = 0; s < scan.surfaces.count; ++s) {
        for (int l = 0; l < L; ++l) surface[l] &= !blocked[l];
        if (!any(surface)) break;
        corners.load<Storage>(scan.surfaces.phi[s], phiC);
        corners.interpolate(phiC, value);
        for (int l = 0; l < L; ++l) blocked[l] |= surface[l] & (value[l] < 0.f);
      }
    }
    // exp only where the optical depth moved (empty space keeps T).
    for (int l = 0; l < L; ++l) update[l] = !blocked[l] & (opticalDepth[l] != tDepth[l]);
    if (any(update)) {
      // Computed in every lane, then selected: the compiler does not vectorise a loop that
      // evaluates the polynomial only where a lane needs it.
      for (int l = 0; l < L; ++l) value[l] = packet::expNeg(opticalDepth[l]);
      for (int l = 0; l < L; ++l) {
        t[l] = update[l] ? value[l] : t[l];
        tDepth[l] = update[l] ? opticalDepth[l] : tDepth[l];
      }
    }
    float* rowM = bm + size_t(k) * L;
    float* rowG = bg + size_t(k) * L;
    float* rowT = bt + size_t(k) * L;
    alignas(64) float tCell[L];
    for (int l = 0; l < L; ++l) {
      tCell[l] = (blocked[l] | !rays.active[l]) ? 0.f : t[l];
      rowM[l] = m[l];
      rowG[l] = g[l];
      rowT[l] = stored(tCell[l]);
      opticalDepth[l] += m[l] * ds;
    }
    // The statistic V_occ (ScanSums): screen weights scale importance as in the energy.
    int seenHere = 0;
    for (int l = 0; l < L; ++l) seenHere |= in[l] & (g[l] > 0.f);
    if (seenHere) {
      alignas(64) float gmw[L], alone[L];
      for (int l = 0; l < L; ++l) {
        gmw[l] = gm[l] * std::min(rays.w[l], 1.f / std::max(g[l], 1e-30f));
        alone[l] = gmw[l] * packet::expNeg(importantDepth[l]);
      }
      for (int l = 0; l < L; ++l) {
        const bool counts = in[l] & (g[l] > 0.f);
        const double cellV = double(rays.omega[l]) * double(depth) * double(depth) * double(ds);
        seen[l] += counts ? double(gmw[l] * tCell[l]) * cellV : 0.0;
        seenAlone[l] += counts ? double(alone[l]) * cellV : 0.0;
        importantDepth[l] += counts ? gmw[l] * ds : 0.f;
      }
    }
  }
  // Past the volume nothing changes: each lane's last transmittance carries on.
  alignas(64) float tPast[L];
  for (int l = 0; l < L; ++l) {
    const bool moved = !blocked[l] && opticalDepth[l] != tDepth[l];
    const float tl = moved ? packet::expNeg(opticalDepth[l]) : t[l];
    tPast[l] = (blocked[l] || !rays.active[l]) ? 0.f : stored(tl);
  }
  for (int k = kHi; k < nz; ++k)
    for (int l = 0; l < L; ++l) {
      bm[k * L + l] = bg[k * L + l] = 0.f;
      bt[k * L + l] = tPast[l];
    }
  for (int l = 0; l < L; ++l) {
    sums.importantSeen += seen[l];
    sums.importantSeenAlone += seenAlone[l];
  }
}

}  // namespace visopt
