// One explicit Euler step of the context-surface PDE (Himmler & Günther 2026, Eq. 23, Eq. 25, Alg.
// 1; docs/methods.md §3), per voxel:
//   phi_t = max(0, ghat |grad phi| kappa + grad ghat . grad phi) + lambda(x) (phi0 - phi),
//   lambda(x) = max(0, lambda - ghat(x)).
// |grad phi| of the curvature part is Godunov-upwinded (Osher & Fedkiw §6.4) on the sign of
// the speed F = -ghat kappa of phi_t + F |grad phi| = 0, from first-order or second-order ENO
// one-sided differences (LevelSetSettings::spatialOrder); grad ghat . grad phi and the mean
// curvature kappa = div(grad phi / |grad phi|) use central differences, kappa with the
// denominator (|grad phi|^2)^(3/2) + eps and clamped to |kappa| <= kappaMax (~1 / dx_min).
// Where the world mask is set the first term is off and phi only relaxes back to phi0.
//
// Boundaries: a missing neighbour is the linear extrapolation of the two nearest values, so at
// a border the one-sided differences D- and D+ coincide, the central difference is one-sided
// and the second difference is zero; an axis with a single voxel has no derivative at all.
//
// The step reads one buffer and writes another (no in-place race). Kernels get the fields
// through an accessor type (core/field_access.h): fp32 and fp16 pointers for the fast paths, any
// FieldView otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>

#include "core/bit_mask_view.h"
#include "core/field_access.h"
#include "core/field_view.h"
#include "core/half.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "core/voxel_ijk.h"

namespace visopt {

// ---- stencil geometry -------------------------------------------------------------------------

// The neighbours of one voxel along one axis.
struct StencilAxis {
  int64_t m = 0, p = 0;         // linear offsets to the minus / plus neighbour (0 where missing)
  int64_t mm = 0, pp = 0;       // ... to the second neighbours (only read where they exist)
  float inv = 0.f;              // 1 / h; 0 for an axis of a single voxel
  float central = 0.f;          // 1 / ((p - m) h): 1/(2h) inside, 1/h at a border, 0 for one voxel
  bool lo = false, hi = false;  // at the minus / plus border
  bool lo2 = false, hi2 = false;  // the minus / plus neighbour is at a border or missing
  // The same flags as bit masks (all ones where set, lo || hi as `edge`) for blendBits: g++ 12
  // does not vectorise a ?: on a loop-invariant bool, so the border rows of sweepStepRow ran
  // scalar (11 % of an optimisation of the Cranium CT, half the level-set step's time).
  uint32_t loMask = 0, hiMask = 0, lo2Mask = 0, hi2Mask = 0, edgeMask = 0;
};

// `set` where mask is all ones, `clear` where it is 0, bit for bit (masks from StencilAxis).
VISOPT_HD VISOPT_INLINE float blendBits(uint32_t mask, float set, float clear) {
#if defined(__CUDA_ARCH__)
  return mask ? set : clear;
#else
  uint32_t a, b;
  std::memcpy(&a, &set, 4);
  std::memcpy(&b, &clear, 4);
  const uint32_t r = (a & mask) | (b & ~mask);
  float f;
  std::memcpy(&f, &r, 4);
  return f;
#endif
}

VISOPT_HD VISOPT_INLINE void setMasks(StencilAxis& a) {
  auto bits = [](bool b) { return b ? ~uint32_t(0) : uint32_t(0); };
  a.loMask = bits(a.lo);
  a.hiMask = bits(a.hi);
  a.lo2Mask = bits(a.lo2);
  a.hi2Mask = bits(a.hi2);
  a.edgeMask = bits(a.lo || a.hi);
}

VISOPT_HD VISOPT_INLINE StencilAxis stencilAxis(int idx, int n, int64_t stride, float h) {
  StencilAxis a;
  if (n <= 1) {
    a.lo = a.hi = a.lo2 = a.hi2 = true;
    setMasks(a);
    return a;
  }
  a.lo = idx == 0;
  a.hi = idx == n - 1;
  a.lo2 = idx <= 1;
  a.hi2 = idx >= n - 2;
  a.m = a.lo ? 0 : -stride;
  a.p = a.hi ? 0 : stride;
  a.mm = a.lo2 ? a.m : -2 * stride;
  a.pp = a.hi2 ? a.p : 2 * stride;
  a.inv = 1.f / h;
  a.central = (a.lo || a.hi) ? a.inv : 0.5f * a.inv;
  setMasks(a);
  return a;
}

// The same for a voxel at least two voxels from both borders of an axis of at least 5: the
// border flags are compile-time false, so the interior loops carry no border selects.
struct InnerAxis {
  int64_t m = 0, p = 0, mm = 0, pp = 0;
  float inv = 0.f, central = 0.f;
  static constexpr bool lo = false, hi = false, lo2 = false, hi2 = false;
  static constexpr uint32_t loMask = 0, hiMask = 0, lo2Mask = 0, hi2Mask = 0, edgeMask = 0;
};

VISOPT_HD VISOPT_INLINE InnerAxis innerAxis(int64_t stride, float h) {
  InnerAxis a;
  a.m = -stride;
  a.p = stride;
  a.mm = -2 * stride;
  a.pp = 2 * stride;
  a.inv = 1.f / h;
  a.central = 0.5f * a.inv;
  return a;
}

// One-sided differences D-, D+ with the border extrapolation described above.
struct OneSided {
  float dm, dp;
};
template <class Ax>
VISOPT_HD VISOPT_INLINE OneSided oneSided(float m, float c, float p, const Ax& a) {
  const float dm = (c - m) * a.inv, dp = (p - c) * a.inv;
  // Two independent selects (lo and hi are both set only on a single-voxel axis, where inv = 0
  // makes both differences 0): a conditional assignment, or a select of a select's result,
  // keeps the border rows of sweepStepRow from vectorising.
  return {blendBits(a.loMask, dp, dm), blendBits(a.hiMask, dm, dp)};
}

VISOPT_HD VISOPT_INLINE float minmod(float a, float b) {
  return a * b > 0.f ? (fabsf(a) < fabsf(b) ? a : b) : 0.f;
}

// Second-order ENO one-sided differences (Osher & Fedkiw §3.3): the first-order ones plus half
// the smaller (minmod) of the two adjacent second differences. Second differences that would
// need a value beyond the border are 0 (linear extrapolation), so borders fall back to first
// order, and so do kinks, where the two second differences disagree in sign.
template <class Ax>
VISOPT_HD VISOPT_INLINE OneSided oneSidedEno2(float mm, float m, float c, float p, float pp,
                                              const Ax& a) {
  const float d2c = blendBits(a.edgeMask, 0.f, p - 2.f * c + m);
  const float d2m = blendBits(a.lo2Mask, 0.f, c - 2.f * m + mm);
  const float d2p = blendBits(a.hi2Mask, 0.f, pp - 2.f * p + c);
  const float dm = (c - m + 0.5f * minmod(d2m, d2c)) * a.inv;
  const float dp = (p - c - 0.5f * minmod(d2p, d2c)) * a.inv;
  return {blendBits(a.loMask, dp, dm), blendBits(a.hiMask, dm, dp)};  // as in oneSided
}

// The upwind differences of the given order (1 or 2) along one axis.
template <class A, int Order, class Ax>
VISOPT_HD VISOPT_INLINE OneSided upwindDifferences(const A& f, int64_t s, float m, float c, float p,
                                                   const Ax& a) {
  if constexpr (Order == 2)
    return oneSidedEno2(f.load(size_t(s + a.mm)), m, c, p, f.load(size_t(s + a.pp)), a);
  else
    return oneSided(m, c, p, a);
}

// Godunov's upwind |D phi|^2 along one axis for a speed of the given sign (phi_t + F|grad phi|).
VISOPT_HD VISOPT_INLINE float godunovSquared(const OneSided& d, bool positiveSpeed) {
  const float a = positiveSpeed ? maxOf(d.dm, 0.f) : minOf(d.dm, 0.f);
  const float b = positiveSpeed ? minOf(d.dp, 0.f) : maxOf(d.dp, 0.f);
  return maxOf(a * a, b * b);
}

// How much of a change of phi at a voxel moves the zero level set next to it, for a voxel
// within `band` of the surface: a crossing on the edge between voxels A and B (opposite signs,
// |A| + |B| ~ dx for a distance function) lies |A| / (|A| + |B|) of the way from A, so a change
// d at A moves it by ~(1 - |A| / dx) d. With band = dx: 1 at the surface, 0 a voxel away (where
// the fixed point of Eq. 23, which is no distance function, and redistancing pull a voxel to
// and fro while the surface stays put).
VISOPT_HD VISOPT_INLINE float surfaceShare(float phi, float band) {
  return band > 0.f ? maxOf(0.f, 1.f - fabsf(phi) / band) : 1.f;
}

// Per-launch reduction of a step: largest and summed |delta phi|, and the largest
// |delta phi| x surfaceShare among voxels within the kernel's nearBand of the surface
// (|phi| <= nearBand before the step): how far the surface itself moved, which the far field's
// kinks (moving at up to ghat / dx) do not inflate.
struct ChangeSums {
  float maxAbs = 0.f;
  double sumAbs = 0.0;
  double sumSquared = 0.0;
  float nearMaxAbs = 0.f;
  double nearSumSquared = 0.0;  // sum of delta phi^2 over the voxels within nearBand
  double nearCount = 0.0;       // how many voxels lie within nearBand
  // The largest rise of phi among voxels inside the surface beyond nearBand (phi < -nearBand):
  // how fast a kink of the inside (its medial axis, raised by the clamped curvature) can come up
  // to zero away from the surface. Elsewhere far from the surface phi can only fall towards a
  // phi0 of the same sign or rise away from zero, so no spurious surface can start there (where
  // phi0 has the other sign, the return term of Eq. 23 brings the surface back: real motion).
  float insideRiseMax = 0.f;
  VISOPT_HD ChangeSums operator+(const ChangeSums& o) const {
    return {maxOf(maxAbs, o.maxAbs),
            sumAbs + o.sumAbs,
            sumSquared + o.sumSquared,
            maxOf(nearMaxAbs, o.nearMaxAbs),
            nearSumSquared + o.nearSumSquared,
            nearCount + o.nearCount,
            maxOf(insideRiseMax, o.insideRiseMax)};
  }
  VISOPT_HD void add(float d, float before, float nearBand) {
    const float a = fabsf(d);
    maxAbs = maxOf(maxAbs, a);
    sumAbs += double(a);
    sumSquared += double(d) * double(d);
    const bool near = fabsf(before) <= nearBand;
    nearMaxAbs = maxOf(nearMaxAbs, near ? a * surfaceShare(before, nearBand) : 0.f);
    nearSumSquared += near ? double(d) * double(d) : 0.0;
    nearCount += near ? 1.0 : 0.0;
    insideRiseMax = maxOf(insideRiseMax, before < -nearBand ? maxOf(d, 0.f) : 0.f);
  }
};

// ---- sweeping the grid ------------------------------------------------------------------------
//
// A stencil kernel K provides dims, spacing, current(v) (the value it replaces), next(v, ax, ay,
// az) (the new value, branch-free), write(v, value) and kept(value) (what storage keeps).
// sweepVoxel runs one voxel (the CUDA path); sweepStepRow (below) one x row or span of a row
// (the CPU path): the y/z stencil is fixed along a row, the two voxels at either end use the
// border stencil, and the interior runs in chunks of kLanes with a fixed x stencil and per-lane
// accumulators, so that the compiler can vectorise it.

// The first voxel of span [x0, x1) at least two voxels from the row's start, and the end of the
// voxels at least two from the row's end (never before `lo`).
VISOPT_HD VISOPT_INLINE int spanInteriorBegin(int x0, int x1, int nx) {
  const int start = nx < 2 ? nx : 2;
  const int lo = x0 > start ? x0 : start;
  return lo < x1 ? lo : x1;
}
VISOPT_HD VISOPT_INLINE int spanInteriorEnd(int x1, int nx, int lo) {
  const int hi = x1 < nx - 2 ? x1 : nx - 2;
  return hi > lo ? hi : lo;
}

template <class K>
VISOPT_HD ChangeSums sweepVoxel(const K& k, int64_t v) {
  const int64_t nx = k.dims.x, ny = k.dims.y;
  const auto [i, j, l] = voxelIjk(v, k.dims);
  const float c = k.current(size_t(v));
  const float next = k.next(size_t(v), stencilAxis(i, k.dims.x, 1, k.spacing.x),
                            stencilAxis(j, k.dims.y, nx, k.spacing.y),
                            stencilAxis(l, k.dims.z, nx * ny, k.spacing.z));
  k.write(size_t(v), next);
  ChangeSums sums;
  sums.add(k.kept(next) - c, c, k.nearBand);
  return sums;
}

// sweepStepRow: the CPU row of a kernel that also provides masked(v) and nextAt(v, masked, ax,
// ay, az) for any mix of StencilAxis and InnerAxis (the level-set step). Rows at least two voxels
// from the y and z borders use InnerAxis on all three axes, so the interior carries no border
// selects; a chunk computes unmasked values into local arrays before it stores, so no store can
// alias a load and the chunk vectorises, then redoes its masked voxels one by one. A row whose
// interior is not a whole number of chunks ends with a chunk that overlaps the previous one: its
// stores repeat the same values and its lanes already counted are left out of the sums.
template <class K, class AY, class AZ>
VISOPT_HD ChangeSums sweepStepRowWith(const K& k, int64_t r, const AY ay, const AZ az, int x0,
                                      int x1) {
  constexpr int kLanes = 16;
  const int nx = k.dims.x;
  const size_t base = size_t(r) * size_t(nx);
  ChangeSums sums;
  auto single = [&](int i) {
    const size_t v = base + size_t(i);
    const float c = k.current(v);
    const float next = k.nextAt(v, k.masked(v), stencilAxis(i, nx, 1, k.spacing.x), ay, az);
    k.write(v, next);
    sums.add(k.kept(next) - c, c, k.nearBand);
  };
  // [lo, hi): the span's voxels at least two from the row's ends (no x border within reach).
  const int lo = spanInteriorBegin(x0, x1, nx);
  const int hi = spanInteriorEnd(x1, nx, lo);
  if (hi - lo < kLanes) {
    for (int i = x0; i < x1; ++i) single(i);
    return sums;
  }
  for (int i = x0; i < lo; ++i) single(i);
  const InnerAxis ax = innerAxis(1, k.spacing.x);
  float maxAbs[kLanes], sumAbs[kLanes], sumSquared[kLanes], nearMaxAbs[kLanes],
      nearSumSquared[kLanes], nearCount[kLanes], insideRiseMax[kLanes];
  for (int l = 0; l < kLanes; ++l)
    maxAbs[l] = sumAbs[l] = sumSquared[l] = nearMaxAbs[l] = nearSumSquared[l] = nearCount[l] =
        insideRiseMax[l] = 0.f;
  for (int done = lo; done < hi;) {
    const int i0 = done + kLanes <= hi ? done : hi - kLanes;
    const size_t v0 = base + size_t(i0);
    float current[kLanes], next[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      current[l] = k.current(v0 + size_t(l));
      next[l] = k.nextAt(v0 + size_t(l), false, ax, ay, az);
    }
    for (int l = 0; l < kLanes; ++l)
      if (k.masked(v0 + size_t(l))) next[l] = k.nextAt(v0 + size_t(l), true, ax, ay, az);
    for (int l = 0; l < kLanes; ++l) {
      k.write(v0 + size_t(l), next[l]);
      const float d = i0 + l >= done ? k.kept(next[l]) - current[l] : 0.f;
      maxAbs[l] = maxOf(maxAbs[l], fabsf(d));
      sumAbs[l] += fabsf(d);
      sumSquared[l] += d * d;
      const bool near = fabsf(current[l]) <= k.nearBand && i0 + l >= done;
      nearMaxAbs[l] =
          maxOf(nearMaxAbs[l], near ? fabsf(d) * surfaceShare(current[l], k.nearBand) : 0.f);
      nearSumSquared[l] += near ? d * d : 0.f;
      nearCount[l] += near ? 1.f : 0.f;
      insideRiseMax[l] = maxOf(insideRiseMax[l], current[l] < -k.nearBand ? maxOf(d, 0.f) : 0.f);
    }
    done = i0 + kLanes;
  }
  for (int i = hi; i < x1; ++i) single(i);
  for (int l = 0; l < kLanes; ++l) {
    sums.maxAbs = maxOf(sums.maxAbs, maxAbs[l]);
    sums.sumAbs += double(sumAbs[l]);
    sums.sumSquared += double(sumSquared[l]);
    sums.nearMaxAbs = maxOf(sums.nearMaxAbs, nearMaxAbs[l]);
    sums.nearSumSquared += double(nearSumSquared[l]);
    sums.nearCount += double(nearCount[l]);
    sums.insideRiseMax = maxOf(sums.insideRiseMax, insideRiseMax[l]);
  }
  return sums;
}

// Voxels [x0, x1) of row r (x1 < 0: to the row's end): the band path runs spans of rows.
template <class K>
VISOPT_HD ChangeSums sweepStepRow(const K& k, int64_t r, int x0 = 0, int x1 = -1) {
  const int ny = k.dims.y, nz = k.dims.z;
  const int j = int(r % ny), l = int(r / ny);
  const int64_t sy = k.dims.x, sz = int64_t(k.dims.x) * ny;
  if (x1 < 0) x1 = k.dims.x;
  if (j >= 2 && j < ny - 2 && l >= 2 && l < nz - 2)
    return sweepStepRowWith(k, r, innerAxis(sy, k.spacing.y), innerAxis(sz, k.spacing.z), x0, x1);
  return sweepStepRowWith(k, r, stencilAxis(j, ny, sy, k.spacing.y),
                          stencilAxis(l, nz, sz, k.spacing.z), x0, x1);
}

// ---- the level-set step -----------------------------------------------------------------------

template <class A, int Order>
struct LevelSetStepKernel {
  A phi, out, phi0, ghat;
  // The world mask, one bit per voxel (invalid: nothing masked).
  BitMaskView mask;
  glm::ivec3 dims{1};
  glm::vec3 spacing{1.f};
  float dt = 0.f;
  float lambda = 0.f;
  float curvatureEpsilon = 1e-6f;
  float kappaMax = 1.f;
  float nearBand = 3.4e38f;  // ChangeSums::nearMaxAbs counts voxels with |phi| <= this

  VISOPT_HD VISOPT_INLINE float current(size_t v) const { return phi.load(v); }
  VISOPT_HD VISOPT_INLINE void write(size_t v, float x) const { out.store(v, x); }
  VISOPT_HD VISOPT_INLINE float kept(float x) const { return out.kept(x); }

  VISOPT_HD VISOPT_INLINE bool masked(size_t v) const { return mask.valid() && mask.get(v); }

  VISOPT_HD VISOPT_INLINE float next(size_t v, const StencilAxis& ax, const StencilAxis& ay,
                                     const StencilAxis& az) const {
    return nextAt(v, masked(v), ax, ay, az);
  }

  // The new value at v for the given mask bit and stencil axes (StencilAxis or InnerAxis).
  template <class AX, class AY, class AZ>
  VISOPT_HD VISOPT_INLINE float nextAt(size_t v, bool isMasked, const AX& ax, const AY& ay,
                                       const AZ& az) const {
    const int64_t s = int64_t(v);
    const float c = phi.load(v);
    const float xm = phi.load(size_t(s + ax.m)), xp = phi.load(size_t(s + ax.p));
    const float ym = phi.load(size_t(s + ay.m)), yp = phi.load(size_t(s + ay.p));
    const float zm = phi.load(size_t(s + az.m)), zp = phi.load(size_t(s + az.p));
    const float g = ghat.load(v);

    const OneSided dx = oneSided(xm, c, xp, ax), dy = oneSided(ym, c, yp, ay),
                   dz = oneSided(zm, c, zp, az);
    // Central first and second derivatives; mixed ones as central differences of central
    // differences (the border rule makes them one-sided there).
    const float px = (xp - xm) * ax.central, py = (yp - ym) * ay.central,
                pz = (zp - zm) * az.central;
    const float pxx = (dx.dp - dx.dm) * ax.inv, pyy = (dy.dp - dy.dm) * ay.inv,
                pzz = (dz.dp - dz.dm) * az.inv;
    auto mixed = [&](const auto& a, const auto& b) {
      const float pp = phi.load(size_t(s + a.p + b.p)), pm = phi.load(size_t(s + a.p + b.m));
      const float mp = phi.load(size_t(s + a.m + b.p)), mm = phi.load(size_t(s + a.m + b.m));
      return (pp - pm - mp + mm) * a.central * b.central;
    };
    const float pxy = mixed(ax, ay), pxz = mixed(ax, az), pyz = mixed(ay, az);
    const float px2 = px * px, py2 = py * py, pz2 = pz * pz;
    const float grad2 = px2 + py2 + pz2;
    const float num = px2 * (pyy + pzz) + py2 * (pxx + pzz) + pz2 * (pxx + pyy) -
                      2.f * (px * py * pxy + px * pz * pxz + py * pz * pyz);
    float kappa = num / (grad2 * sqrtf(grad2) + curvatureEpsilon);
    kappa = minOf(maxOf(kappa, -kappaMax), kappaMax);

    // phi_t = g kappa |grad phi| is phi_t + F |grad phi| = 0 with F = -g kappa.
    const bool positiveSpeed = -g * kappa > 0.f;
    const OneSided ux = upwindDifferences<A, Order>(phi, s, xm, c, xp, ax);
    const OneSided uy = upwindDifferences<A, Order>(phi, s, ym, c, yp, ay);
    const OneSided uz = upwindDifferences<A, Order>(phi, s, zm, c, zp, az);
    const float upwind =
        sqrtf(godunovSquared(ux, positiveSpeed) + godunovSquared(uy, positiveSpeed) +
              godunovSquared(uz, positiveSpeed));

    const float gx = (ghat.load(size_t(s + ax.p)) - ghat.load(size_t(s + ax.m))) * ax.central;
    const float gy = (ghat.load(size_t(s + ay.p)) - ghat.load(size_t(s + ay.m))) * ay.central;
    const float gz = (ghat.load(size_t(s + az.p)) - ghat.load(size_t(s + az.m))) * az.central;
    const float drive =
        isMasked ? 0.f : maxOf(0.f, g * upwind * kappa + gx * px + gy * py + gz * pz);
    // The relaxation never overshoots phi0, whatever dt the caller chose.
    const float rate = minOf(maxOf(0.f, lambda - g) * dt, 1.f);
    return c + dt * drive + rate * (phi0.load(v) - c);
  }

  VISOPT_HD ChangeSums voxel(int64_t v) const { return sweepVoxel(*this, v); }
  VISOPT_HD ChangeSums row(int64_t r) const { return sweepStepRow(*this, r); }
  VISOPT_HD ChangeSums span(int64_t r, int x0, int x1) const {
    return sweepStepRow(*this, r, x0, x1);
  }
};

// Maxima over the grid that bound the stable time step (docs/methods.md §3).
struct StepBounds {
  float maxGradG = 0.f;  // max |grad ghat| (central differences, world units)
  float maxG = 0.f;      // max ghat
  float minG = 3.4e38f;  // min ghat (max lambda(x) = max(0, lambda - min ghat))
  VISOPT_HD StepBounds operator+(const StepBounds& o) const {
    return {maxOf(maxGradG, o.maxGradG), maxOf(maxG, o.maxG), minOf(minG, o.minG)};
  }
};

struct StepBoundsKernel {
  FieldView ghat;
  glm::ivec3 dims{1};
  glm::vec3 spacing{1.f};
  VISOPT_HD StepBounds operator()(int64_t v) const {
    const int64_t nx = dims.x, ny = dims.y;
    const auto [i, j, k] = voxelIjk(v, dims);
    const StencilAxis ax = stencilAxis(i, dims.x, 1, spacing.x);
    const StencilAxis ay = stencilAxis(j, dims.y, nx, spacing.y);
    const StencilAxis az = stencilAxis(k, dims.z, nx * ny, spacing.z);
    const float gx = (ghat.load(size_t(v + ax.p)) - ghat.load(size_t(v + ax.m))) * ax.central;
    const float gy = (ghat.load(size_t(v + ay.p)) - ghat.load(size_t(v + ay.m))) * ay.central;
    const float gz = (ghat.load(size_t(v + az.p)) - ghat.load(size_t(v + az.m))) * az.central;
    const float g = ghat.load(size_t(v));
    return {sqrtf(gx * gx + gy * gy + gz * gz), g, g};
  }
};

}  // namespace visopt
