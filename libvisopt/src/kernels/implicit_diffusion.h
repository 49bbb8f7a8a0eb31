// The semi-implicit step of the context-surface PDE (issue 11; docs/methods.md §3).
//
// Where phi is a signed distance field (|grad phi| = 1, which redistancing, Eq. 18, keeps), the
// occlusion term of Eq. 22 is a divergence:
//   ghat |grad phi| kappa + grad ghat . grad phi = div(ghat grad phi)
// (Caselles, Kimmel & Sapiro 1997, Eq. 14 with |grad phi| = 1; the form Goldenberg, Kimmel,
// Rivlin & Rudzsky 2001 solve semi-implicitly in "Fast geodesic active contours"). Explicit Euler
// (Eq. 25) is stable only for dt <= dx^2 / (6 max ghat): moving a head-sized surface by tens of
// voxels takes thousands of substeps, each a pass over the band. Implicit Euler of the linear
// operator is stable for any dt, and splitting it into one-dimensional solves (locally
// one-dimensional, LOD: (I - dt A_z)(I - dt A_y)(I - dt A_x) phi_D = phi^n, first order in dt
// like Eq. 25) makes each a tridiagonal system along grid lines, solved by the Thomas algorithm:
//   A_l u_i = (w+ (u_{i+1} - u_i) - w- (u_i - u_{i-1})) / h_l^2,
//   w+- = (ghat_i + ghat_{i+-1}) / 2.
// I - dt A_l is an M-matrix for ghat >= 0 (diagonally dominant, off-diagonals <= 0), so each
// solve is bounded by its data: no oscillation at any dt.
//
// The solves run on the increment phi - phi^n (see forwardRow). Then Eq. 23's clamp and its
// return term, the latter integrated exactly (it is linear and
// pointwise; split after the drive):
//   phi^{n+1} = phi0 + (phi^n + [not masked] max(0, phi_D - phi^n) - phi0) exp(-dt lambda(x)),
//   lambda(x) = max(0, lambda - ghat(x)).
//
// Boundaries of a line: voxels outside the solved segment keep their values and enter as
// Dirichlet data (the narrow band's edge, like the stale values the explicit stencils read
// there); a voxel on the grid's face has no second difference along that axis (as in
// kernels/level_set_step.h, whose border extrapolation makes it zero) and keeps its value in
// that axis's solve.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/bit_mask_view.h"
#include "core/field_access.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "kernels/level_set_step.h"

namespace visopt {

// Lines solved together: the SIMD lanes of one solve, adjacent voxels across the line.
inline constexpr int kImplicitLanes = 8;

// `lanes` parallel lines of `n` voxels along one axis.
struct ImplicitLines {
  int64_t first = 0;     // the voxel of element 0 of lane 0
  int64_t step = 0;      // between elements along the axis
  int64_t laneStep = 0;  // between lanes
  int32_t n = 0;
  int32_t lanes = 0;         // <= kImplicitLanes
  bool lowFace = false;      // element 0 lies on the grid's face
  bool highFace = false;     // element n - 1 lies on the grid's face
  int64_t coefficients = 0;  // offset into the float buffer: 2 n kImplicitLanes floats
};

namespace implicit_detail {

// Element i of the forward sweep for lane l: the row of (I - r A_l) and its c', d', for the
// increment delta = u - phi^n: (I - r A_l) delta_l = delta_{l-1} + r A_l phi^n (delta_0 = 0 for
// the first axis solved). Solving for the increment keeps fp16 storage exact where it matters:
// an increment near 0 has fp16's finest steps, where a stored u would be rounded at |phi|'s
// scale three times per step and the clamp max(0, .) would turn that rounding noise into a drift
// of resting surfaces. Edge rows (the first and last element) carry the faces and the Dirichlet
// data (delta = 0 outside the segment: those voxels do not change); interior rows have neither,
// so their loop over the lanes carries no selects (g++ 12 vectorises it then).
template <class A, bool Edge, bool FirstAxis>
VISOPT_HD VISOPT_INLINE void forwardRow(const A& delta, const A& ghat, const A& before,
                                        const ImplicitLines& L, int64_t v, int32_t i, float r,
                                        float& cPrev, float& dPrev) {
  const float g = ghat.load(size_t(v));
  const float centre = before.load(size_t(v));
  const float previous = FirstAxis ? 0.f : delta.load(size_t(v));
  float wm, wp;
  if constexpr (Edge) {
    const bool first = i == 0, last = i == L.n - 1;
    const bool face = (first && L.lowFace) || (last && L.highFace);
    // Never read across a face: the face voxel's row is the identity.
    const float gm = (first && L.lowFace) ? g : ghat.load(size_t(v - L.step));
    const float gp = (last && L.highFace) ? g : ghat.load(size_t(v + L.step));
    const float pm = (first && L.lowFace) ? centre : before.load(size_t(v - L.step));
    const float pp = (last && L.highFace) ? centre : before.load(size_t(v + L.step));
    wm = face ? 0.f : 0.5f * r * (g + gm);
    wp = face ? 0.f : 0.5f * r * (g + gp);
    const float rhs = previous + wp * (pp - centre) - wm * (centre - pm);
    const float a = first ? 0.f : -wm;
    const float c = last ? 0.f : -wp;
    const float inv = 1.f / (1.f + wm + wp - a * cPrev);
    cPrev = c * inv;
    dPrev = (rhs - a * dPrev) * inv;
  } else {
    const float gm = ghat.load(size_t(v - L.step)), gp = ghat.load(size_t(v + L.step));
    const float pm = before.load(size_t(v - L.step)), pp = before.load(size_t(v + L.step));
    wm = 0.5f * r * (g + gm);
    wp = 0.5f * r * (g + gp);
    const float rhs = previous + wp * (pp - centre) - wm * (centre - pm);
    const float inv = 1.f / (1.f + wm + wp + wm * cPrev);
    cPrev = -wp * inv;
    dPrev = (rhs + wm * dPrev) * inv;
  }
}

// The forward sweep's element i for every lane, its c' and d' kept in cw and dw.
template <class A, bool Edge, bool FirstAxis, class Lane>
VISOPT_HD VISOPT_INLINE void forwardElement(const A& delta, const A& ghat, const A& before,
                                            const ImplicitLines& L, int32_t i, float r,
                                            const Lane& lane, float* cPrev, float* dPrev, float* cw,
                                            float* dw) {
  const int64_t base = L.first + int64_t(i) * L.step;
  for (int l = 0; l < kImplicitLanes; ++l) {
    forwardRow<A, Edge, FirstAxis>(delta, ghat, before, L, base + lane(l), i, r, cPrev[l],
                                   dPrev[l]);
    cw[int64_t(i) * kImplicitLanes + l] = cPrev[l];
    dw[int64_t(i) * kImplicitLanes + l] = dPrev[l];
  }
}

// Full: all kImplicitLanes lanes are lines (else lanes past L.lanes repeat the last line and
// are never stored).
template <class A, bool UnitLanes, bool Full, bool FirstAxis>
VISOPT_HD void solveLines(const A& delta, const A& ghat, const A& before, const ImplicitLines& L,
                          float r, float* work) {
  constexpr int W = kImplicitLanes;
  float* cw = work + L.coefficients;
  float* dw = cw + int64_t(L.n) * W;
  const int64_t laneStep = UnitLanes ? 1 : L.laneStep;
  const int lanes = L.lanes;
  auto lane = [&](int l) { return int64_t(Full ? l : (l < lanes ? l : lanes - 1)) * laneStep; };
  float cPrev[W], dPrev[W];
  for (int l = 0; l < W; ++l) cPrev[l] = dPrev[l] = 0.f;
  forwardElement<A, true, FirstAxis>(delta, ghat, before, L, 0, r, lane, cPrev, dPrev, cw, dw);
  for (int32_t i = 1; i + 1 < L.n; ++i)
    forwardElement<A, false, FirstAxis>(delta, ghat, before, L, i, r, lane, cPrev, dPrev, cw, dw);
  if (L.n > 1)
    forwardElement<A, true, FirstAxis>(delta, ghat, before, L, L.n - 1, r, lane, cPrev, dPrev, cw,
                                       dw);
  float u[W];
  for (int l = 0; l < W; ++l) u[l] = 0.f;
  for (int32_t i = L.n - 1; i >= 0; --i) {
    const int64_t base = L.first + int64_t(i) * L.step;
    for (int l = 0; l < W; ++l) u[l] = dw[int64_t(i) * W + l] - cw[int64_t(i) * W + l] * u[l];
    for (int l = 0; l < W; ++l)
      if (Full || l < lanes) delta.store(size_t(base + int64_t(l) * laneStep), u[l]);
  }
}

}  // namespace implicit_detail

// One LOD solve along one axis for a group of lines, in increments: `before` holds phi^n,
// `delta` the increment so far (not read when firstAxis: 0) and receives the new one,
// (I - r A_l) delta_new = delta + r A_l phi^n, r = dt / h_l^2, i.e. u = phi^n + delta solves
// (I - r A_l) u = phi^n + delta. `work` holds the forward sweep's c' and d' (2 n kImplicitLanes
// floats from L.coefficients). UnitLanes: laneStep == 1 (lines along y or z, lanes along x).
template <class A, bool UnitLanes>
VISOPT_HD void solveImplicitLines(const A& delta, const A& ghat, const A& before,
                                  const ImplicitLines& L, float r, float* work, bool firstAxis) {
  using namespace implicit_detail;
  if (L.n <= 0 || L.lanes <= 0) return;
  const bool full = L.lanes == kImplicitLanes;
  if (firstAxis)
    full ? solveLines<A, UnitLanes, true, true>(delta, ghat, before, L, r, work)
         : solveLines<A, UnitLanes, false, true>(delta, ghat, before, L, r, work);
  else
    full ? solveLines<A, UnitLanes, true, false>(delta, ghat, before, L, r, work)
         : solveLines<A, UnitLanes, false, false>(delta, ghat, before, L, r, work);
}

// After the three solves: the clamp and the implicit return term of Eq. 23, per voxel, with the
// change statistics of the explicit step (ChangeSums, against phi^n in `before`).
template <class A>
struct SemiImplicitFinish {
  A phi;     // the increment phi_D - phi^n in (0 where nothing was solved), phi^{n+1} out
  A before;  // phi^n
  A phi0, ghat;
  BitMaskView mask;  // set bits: the occlusion term is off
  float dt = 0.f, lambda = 0.f, nearBand = 0.f;
  int64_t nx = 0;
  bool solved = true;  // false: no axis had two voxels, phi still holds phi^n

  VISOPT_HD VISOPT_INLINE void at(int64_t v, ChangeSums& sums) const {
    const float old = before.load(size_t(v));
    const float increment = solved ? phi.load(size_t(v)) : 0.f;
    const bool masked = mask.valid() && mask.get(size_t(v));
    const float drive = masked ? 0.f : maxOf(0.f, increment);
    // The return term's exact solution over dt: phi - phi0 decays by exp(-dt lambda(x)), never
    // past phi0 at any dt (explicit Euler would overshoot beyond dt lambda(x) = 1).
    const float target = phi0.load(size_t(v));
    const float decay = expf(-dt * maxOf(0.f, lambda - ghat.load(size_t(v))));
    const float next = phi.kept(target + (old + drive - target) * decay);
    phi.store(size_t(v), next);
    sums.add(next - old, old, nearBand);
  }
  VISOPT_HD ChangeSums voxel(int64_t v) const {
    ChangeSums s;
    at(v, s);
    return s;
  }
  VISOPT_HD ChangeSums span(int64_t row, int x0, int x1) const {
    ChangeSums s;
    for (int x = x0; x < x1; ++x) at(row * nx + x, s);
    return s;
  }
  VISOPT_HD ChangeSums row(int64_t r) const { return span(r, 0, int(nx)); }
};

}  // namespace visopt
