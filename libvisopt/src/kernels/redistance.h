// Redistancing (Himmler & Günther 2026, Eq. 18, Sussman, Smereka & Osher 1994; docs/methods.md §3):
//   phi_tau + S (|grad phi| - 1) = 0,   S(p) = p / sqrt(p^2 + dx^2),
// with Godunov's upwind |grad phi| on the sign of S (first-order or second-order ENO one-sided
// differences, LevelSetSettings::spatialOrder) and explicit Euler steps, double-buffered (one
// pass reads a buffer and writes the other). dtau = dx_min / 2 for first order; 0.3 dx_min for
// ENO2, which with forward Euler at dx_min / 2 keeps oscillating (mean squared change ~1e-3
// voxel^2 near the grid's corners, so it never stops early); at 0.3 it settles below 1e-5.
//
// The zero level set is kept in place by the subcell fix of Russo & Smereka (2000): a voxel
// with a face neighbour of the other sign (or zero) is next to the interface; its distance is
// estimated once, at the start, from the start field alone,
//   D = phi / |grad phi|, |grad phi|^2 = sum over axes of the central difference squared, or of
//   max(|D-|, |D+|)^2 along an axis where D- and D+ differ in sign (a kink: R&S take the
//   largest of the three everywhere, which on curved surfaces overestimates |grad phi| by O(h)),
// and it keeps that value through the iterations (Russo & Smereka relax towards the same D;
// holding it fixed is their steady state). Every other voxel is upwinded from that band.
//
// At the grid's faces nothing flows in (inflowOnly below): a face voxel follows the interior.
//
// S: its sign is the start field's sign. A voxel away from the interface never changes sign
// (each update is limited to at most halving |phi|, and upwinding only reads same-signed
// neighbours), so the sign of the current value is the start sign; its magnitude uses the
// current value rather than a stored copy of the start field. That saves a third buffer and
// changes only how fast pseudo-time runs near the band, not the steady state.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/hd.h"
#include "kernels/level_set_step.h"

namespace visopt {

// True when phi at the voxel and one of its face neighbours have opposite signs (or one is 0).
VISOPT_HD VISOPT_INLINE bool nextToInterface(float c, float xm, float xp, float ym, float yp,
                                             float zm, float zp) {
  // | rather than ||: no branches, so that the row loops that inline it vectorise.
  return (c * xm <= 0.f) | (c * xp <= 0.f) | (c * ym <= 0.f) | (c * yp <= 0.f) | (c * zm <= 0.f) |
         (c * zp <= 0.f);
}

// The grid's faces let nothing in: the one-sided difference reaching past a face is 0, so
// Godunov's |grad phi| there upwinds from the interior only. With the extrapolation of
// level_set_step.h (the missing difference copies the other) a face voxel is its own upwind
// neighbour, so any value it starts with is a steady state and the interior takes a unit slope
// from it, as if the face were a surface (a face voxel stayed at 1.08 voxels where the
// distance was 16.9). Without inflow, a face value too small (|grad phi| < 1 seen from the
// interior) grows until it is one voxel's distance beyond its neighbour's.
template <class Ax>
VISOPT_HD VISOPT_INLINE OneSided inflowOnly(OneSided d, const Ax& a) {
  return {blendBits(a.loMask, 0.f, d.dm), blendBits(a.hiMask, 0.f, d.dp)};
}

template <class A, int Order>
struct RedistanceKernel {
  A in, out;
  glm::ivec3 dims{1};
  glm::vec3 spacing{1.f};
  float dtau = 0.5f;
  float dxMin = 1.f;
  bool initialise = false;  // the first pass: set the interface band to its subcell distance
  // The surface's base SDF phi0 (Eq. 15): a voxel within keepWithin (world units) of it keeps its
  // value (see the end of nextAt()). Always read (a branch-free loop vectorises): without a base,
  // withoutBase() makes it the input itself with a negative keepWithin, so nothing is held.
  A base{};
  float keepWithin = -1.f;
  VISOPT_HD void withoutBase() {
    base = in;
    keepWithin = -1.f;
  }
  float nearBand = 3.4e38f;  // ChangeSums::nearMaxAbs counts voxels with |phi| <= this

  VISOPT_HD VISOPT_INLINE float current(size_t v) const { return in.load(v); }
  VISOPT_HD VISOPT_INLINE void write(size_t v, float x) const { out.store(v, x); }
  VISOPT_HD VISOPT_INLINE float kept(float x) const { return out.kept(x); }

  // Nothing is masked in redistancing; masked(v) and nextAt let sweepStepRow run the kernel:
  // rows two voxels or more from the y and z faces use InnerAxis (no border selects), and the
  // chunks vectorise (docs/level-set-benchmarks.md).
  VISOPT_HD VISOPT_INLINE bool masked(size_t) const { return false; }
  VISOPT_HD VISOPT_INLINE float next(size_t v, const StencilAxis& ax, const StencilAxis& ay,
                                     const StencilAxis& az) const {
    return nextAt(v, false, ax, ay, az);
  }
  template <class AX, class AY, class AZ>
  VISOPT_HD VISOPT_INLINE float nextAt(size_t v, bool, const AX& ax, const AY& ay,
                                       const AZ& az) const {
    const int64_t s = int64_t(v);
    const float c = in.load(v);
    const float xm = in.load(size_t(s + ax.m)), xp = in.load(size_t(s + ax.p));
    const float ym = in.load(size_t(s + ay.m)), yp = in.load(size_t(s + ay.p));
    const float zm = in.load(size_t(s + az.m)), zp = in.load(size_t(s + az.p));
    const bool band = nextToInterface(c, xm, xp, ym, yp, zm, zp);

    // The band's subcell distance: along an axis where phi is monotone the central difference,
    // across a kink or an extremum (one-sided differences of opposite signs) the steeper
    // one-sided one.
    auto slope = [](const OneSided& d) {
      const float a = d.dm * d.dp > 0.f ? 0.5f * (d.dm + d.dp) : maxOf(fabsf(d.dm), fabsf(d.dp));
      return a * a;
    };
    const float bandGrad = sqrtf(slope(oneSided(xm, c, xp, ax)) + slope(oneSided(ym, c, yp, ay)) +
                                 slope(oneSided(zm, c, zp, az)));
    // A band voxel whose neighbourhood is already distance-like (|grad phi| within 3 % of 1) keeps
    // its value: re-estimating it at every redistancing moves the interface by the estimate's
    // own O(h) error each time, which shows as speckles of deviation all over a surface and,
    // next to a thin wall's medial kink a voxel away, does not even settle.
    const bool distanceLike = fabsf(bandGrad - 1.f) < 0.03f;
    // (Every value is computed and then selected: a branch keeps g++ from vectorising the row
    // loop, and so do a select between two pointers and a select of a select's result.)
    const float estimate = c / (bandGrad > 0.f ? bandGrad : 1.f);
    const float bandValue = (initialise & !distanceLike & (bandGrad > 0.f)) ? estimate : c;

    // Sussman's update elsewhere.
    const float sgn = c / sqrtf(c * c + dxMin * dxMin);
    const bool positive = sgn > 0.f;
    const OneSided dx = inflowOnly(upwindDifferences<A, Order>(in, s, xm, c, xp, ax), ax);
    const OneSided dy = inflowOnly(upwindDifferences<A, Order>(in, s, ym, c, yp, ay), ay);
    const OneSided dz = inflowOnly(upwindDifferences<A, Order>(in, s, zm, c, zp, az), az);
    const float grad = sqrtf(godunovSquared(dx, positive) + godunovSquared(dy, positive) +
                             godunovSquared(dz, positive));
    const float moved = c - dtau * sgn * (grad - 1.f);
    // Never more than halve |phi| in one pass: the sign stays the start sign.
    const float up = maxOf(moved, 0.5f * c), down = minOf(moved, 0.5f * c);
    const float limited = sgn > 0.f ? up : down;
    // Where phi is still its base SDF (within keepWithin) nothing needs redistancing: phi0 is a
    // distance already, and redistancing it anew moved unmoved surfaces (the band's estimate,
    // by up to 0.45 voxel, mean 0.03, each time) and their neighbourhood (0.2 voxel on
    // average within a voxel of the surface, the Sussman steady state of another scheme), which
    // the return term of Eq. 23 then pulled back: voxel-scale dimples in the shading all over
    // a surface the optimisation never meant to move. Such voxels are held like the band.
    const float update = band ? bandValue : limited;
    return fabsf(c - base.load(v)) <= keepWithin ? c : update;
  }

  VISOPT_HD ChangeSums voxel(int64_t v) const { return sweepVoxel(*this, v); }
  VISOPT_HD ChangeSums row(int64_t r) const { return sweepStepRow(*this, r); }
  VISOPT_HD ChangeSums span(int64_t r, int x0, int x1) const {
    return sweepStepRow(*this, r, x0, x1);
  }
};

// Counts voxels next to the interface (no interface: nothing to measure distance to).
struct InterfaceCount {
  FieldView phi;
  VISOPT_HD int64_t operator()(int64_t v) const {
    const auto [i, j, k] = voxelIjk(v, phi.dims);
    const float c = phi.load(size_t(v));
    const float xm = phi.at(i > 0 ? i - 1 : i, j, k),
                xp = phi.at(i + 1 < phi.dims.x ? i + 1 : i, j, k);
    const float ym = phi.at(i, j > 0 ? j - 1 : j, k),
                yp = phi.at(i, j + 1 < phi.dims.y ? j + 1 : j, k);
    const float zm = phi.at(i, j, k > 0 ? k - 1 : k),
                zp = phi.at(i, j, k + 1 < phi.dims.z ? k + 1 : k);
    return nextToInterface(c, xm, xp, ym, yp, zm, zp) ? 1 : 0;
  }
};

}  // namespace visopt
