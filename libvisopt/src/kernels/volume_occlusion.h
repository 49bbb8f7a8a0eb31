// Ambient occlusion of volume samples (Himmler & Günther 2026, R4 and Fig. 6: the darkened eye
// sockets and neck), as a field on the volume's grid refreshed when mu or the surfaces change:
//   AO(x) = 1/6 sum over d in {+-x, +-y, +-z} of exp(-integral_0^R mu(x + s d) ds),
// the mean transmittance of the six axis-aligned rays of length R (the ambient-occlusion radius)
// from the voxel, through the extinction as drawn and the opaque interiors of the context
// surfaces. Along an axis mu is the linear interpolant of the voxel values (as the renderer's
// trilinear samples are along a row), and 0 beyond the grid, so each ray's optical depth is a
// difference of a prefix integral along the row: three passes over the grid instead of 6 R
// samples per voxel. Six axis rays are the usual cheap stencil for volume AO; they miss a
// cavity's diagonal openings, which the renderer's surface AO (along the normal) does not.
//
// Optical depth per voxel is capped at kOcclusionMaxDepthPerVoxel (e^-20 is black to 8 bits):
// the prefix integrals then stay below 20 x the row length, and their differences keep fp32's
// precision (an unbounded mu, such as a surface's interior, would cancel catastrophically).
//
// Written once: every pass is a per-item functor the CPU and CUDA backends launch alike.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "kernels/ray_fast_math.h"
#include "kernels/surface_render.h"
#include "kernels/surface_set.h"
#include "kernels/transfer_lookup.h"
#include "kernels/volume_extinction.h"

namespace visopt {

constexpr float kOcclusionMaxDepthPerVoxel = 20.f;

// Pass 1, per voxel: the extinction per world length as the renderer draws it: the optimised mu
// (or mu_bar), opaque inside a surface (`cap` = kOcclusionMaxDepthPerVoxel / the smallest
// spacing, which every axis's depth per voxel then reaches), with a baseline's fractional surface
// opacity blended towards opaque.
struct OcclusionExtinctionPerVoxel {
  VolumeExtinction extinction;
  SurfaceSet surfaces;
  RayMethod method = RayMethod::Optimized;
  FieldView importanceBehind;  // the baselines' ghat, on the volume's grid
  float cutThreshold = 0.3f;
  float cap = 20.f;
  float* mu = nullptr;

  VISOPT_HD void operator()(int64_t v) const {
    // The scalars, the change and the surfaces are on the volume's grid: voxel values, no
    // interpolation.
    const size_t i = size_t(v);
    const float base = extinction.transfer.at(extinction.scalars.load(i)).w;
    float m =
        extinction.change.valid() ? extinctionWithChange(base, extinction.change.load(i)) : base;
    // Inside a surface: opaque, except where a baseline removes the surface (cut-away: ghat
    // above the threshold; transparency modulation: its opacity is 1 - ghat). The volume's mu
    // is drawn as given, as kernels/ray_march.h does.
    bool inside = false;
    for (int k = 0; k < surfaces.count; ++k) inside = inside || surfaces.phi[k].load(i) < 0.f;
    const bool baseline = method == RayMethod::CutAway || method == RayMethod::Transparency;
    const float gh = inside && baseline ? fminf(fmaxf(importanceBehind.load(i), 0.f), 1.f) : 0.f;
    const float surfaceOpacity = !inside                        ? 0.f
                                 : method == RayMethod::CutAway ? (gh > cutThreshold ? 0.f : 1.f)
                                 : method == RayMethod::Transparency ? 1.f - gh
                                                                     : 1.f;
    m = m < cap ? m : cap;
    mu[v] = m + surfaceOpacity * (cap - m);
  }
};

// The optical depth of one voxel length along an axis of spacing h, capped.
VISOPT_HD VISOPT_INLINE float occlusionDepthPerVoxel(float mu, float h) {
  const float d = mu * h;
  return d < kOcclusionMaxDepthPerVoxel ? d : kOcclusionMaxDepthPerVoxel;
}

// e^-tau for tau >= 0 (kernels/ray_fast_math.h: a polynomial on the host, relative error below
// 3e-7; values below 2^-126 flush to it).
VISOPT_HD VISOPT_INLINE float occlusionTransmittance(float tau) {
  return rayExp2(-1.44269504f * tau);
}

// Pass 2, per row along axis `axis` (rows are indexed by the two other coordinates): the prefix
// integral of the linear interpolant, F[0] = 0, F[i + 1] = F[i] + (m[i] + m[i + 1]) / 2, in
// optical depth (m = occlusionDepthPerVoxel along this axis), into `prefix`.
struct OcclusionPrefixRows {
  glm::ivec3 dims{1};
  int axis = 0;
  float spacing = 1.f;  // along the axis
  const float* mu = nullptr;
  float* prefix = nullptr;

  VISOPT_HD VISOPT_INLINE int64_t stride() const {
    return axis == 0 ? 1 : axis == 1 ? int64_t(dims.x) : int64_t(dims.x) * dims.y;
  }
  // The first voxel of row r.
  VISOPT_HD VISOPT_INLINE int64_t rowStart(int64_t r) const {
    if (axis == 0) return r * dims.x;                                            // rows (j, k)
    if (axis == 1) return (r / dims.x) * int64_t(dims.x) * dims.y + r % dims.x;  // rows (i, k)
    return r;                                                                    // rows (i, j)
  }
  VISOPT_HD void operator()(int64_t r) const {
    const int64_t s = stride(), first = rowStart(r);
    const int n = dims[axis];
    float f = 0.f, before = occlusionDepthPerVoxel(mu[first], spacing);
    prefix[first] = 0.f;
    for (int i = 1; i < n; ++i) {
      const float m = occlusionDepthPerVoxel(mu[first + i * s], spacing);
      f += 0.5f * (before + m);
      before = m;
      prefix[first + i * s] = f;
    }
  }
};

// Pass 2 as the CPU backend runs it along y and z: per item a group of up to
// kOcclusionRowGroup rows that lie side by side in memory (consecutive x), swept together so
// that each step along the axis reads and writes a contiguous run (SIMD lanes across rows)
// instead of one strided element per row. The arithmetic per row is OcclusionPrefixRows's, in
// the same order: the results are the same bit for bit (test_volume_occlusion).
constexpr int kOcclusionRowGroup = 32;

struct OcclusionPrefixRowGroups {
  OcclusionPrefixRows rows;  // axis 1 or 2

  // Groups per line of rows that are side by side: along y a line is the nx rows of one z
  // plane; along z it is all nx * ny rows.
  VISOPT_HD VISOPT_INLINE int64_t lineLength() const {
    return rows.axis == 1 ? int64_t(rows.dims.x) : int64_t(rows.dims.x) * rows.dims.y;
  }
  VISOPT_HD VISOPT_INLINE int64_t groupsPerLine() const {
    return (lineLength() + kOcclusionRowGroup - 1) / kOcclusionRowGroup;
  }
  int64_t groups() const {
    const int64_t lines = rows.axis == 1 ? int64_t(rows.dims.z) : 1;
    return lines * groupsPerLine();
  }

  VISOPT_HD void operator()(int64_t g) const {
    const int64_t line = g / groupsPerLine(), inLine = (g % groupsPerLine()) * kOcclusionRowGroup;
    const int64_t rest = lineLength() - inLine;
    const int count = rest < kOcclusionRowGroup ? int(rest) : kOcclusionRowGroup;
    const int64_t s = rows.stride();
    const int64_t first =
        rows.axis == 1 ? line * int64_t(rows.dims.x) * rows.dims.y + inLine : inLine;
    const int n = rows.dims[rows.axis];
    const float h = rows.spacing;
    float f[kOcclusionRowGroup], before[kOcclusionRowGroup];
    for (int l = 0; l < count; ++l) {
      f[l] = 0.f;
      before[l] = occlusionDepthPerVoxel(rows.mu[first + l], h);
      rows.prefix[first + l] = 0.f;
    }
    for (int i = 1; i < n; ++i) {
      const float* in = rows.mu + first + i * s;
      float* out = rows.prefix + first + i * s;
      for (int l = 0; l < count; ++l) {
        const float m = occlusionDepthPerVoxel(in[l], h);
        f[l] += 0.5f * (before[l] + m);
        before[l] = m;
        out[l] = f[l];
      }
    }
  }
};

// Pass 3, per voxel for one axis: adds exp(-tau+) + exp(-tau-) of the two rays of `reach` voxel
// lengths (R / spacing along the axis) to `sum`; the last axis divides by 6 and stores AO.
struct OcclusionAccumulate {
  glm::ivec3 dims{1};
  int axis = 0;
  float reach = 6.f;    // voxels along this axis
  float spacing = 1.f;  // along the axis
  const float* mu = nullptr;
  const float* prefix = nullptr;
  float* sum = nullptr;  // not read on the first axis
  bool firstAxis = true;
  FieldView out;  // valid on the last axis only

  // The prefix integral at fractional position u in [0, n - 1] along the row from `first`.
  VISOPT_HD VISOPT_INLINE float prefixAt(int64_t first, int64_t s, int n, float u) const {
    int j = int(u);
    if (j >= n - 1) return prefix[first + int64_t(n - 1) * s];
    const float f = u - float(j);
    const float m0 = occlusionDepthPerVoxel(mu[first + j * s], spacing);
    const float m1 = occlusionDepthPerVoxel(mu[first + (j + 1) * s], spacing);
    return prefix[first + j * s] + f * (m0 + 0.5f * f * (m1 - m0));
  }

  VISOPT_HD void operator()(int64_t v) const {
    const int64_t nx = dims.x, ny = dims.y;
    const int c[3] = {int(v % nx), int((v / nx) % ny), int(v / (nx * ny))};
    const int i = c[axis], n = dims[axis];
    const int64_t s = axis == 0 ? 1 : axis == 1 ? nx : nx * ny;
    const int64_t first = v - int64_t(i) * s;
    const float here = prefix[v];
    const float up = float(i) + reach, down = float(i) - reach;
    const float ahead = prefixAt(first, s, n, up < float(n - 1) ? up : float(n - 1));
    const float behind = prefixAt(first, s, n, down > 0.f ? down : 0.f);
    const float total = (firstAxis ? 0.f : sum[v]) + expf(-(ahead - here)) + expf(-(here - behind));
    if (out.valid())
      out.store(size_t(v), total * (1.f / 6.f));
    else
      sum[v] = total;
  }
};

}  // namespace visopt
