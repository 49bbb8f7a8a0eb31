// Trilinear value and central-difference gradient of a scalar field from one neighbourhood.
//
// The renderer shades with the gradient g = (s(p + e_a) - s(p - e_a)) / 2 of the trilinearly
// interpolated field s. Shifting p by one whole voxel keeps its fractional part, so each
// difference is the trilinear interpolation, with p's weights, of the central differences
// v(c + e_a) - v(c - e_a) at the eight corners c of p's cell — with the same clamping at the
// border as FieldView::sample (an index one past the border reads the border voxel). The
// corners and their 24 outer neighbours along the three axes (32 voxels, not the 56 of seven
// separate trilinear samples) give the value and the gradient, addressed once from p.
//
// RayStencil is the portable version (host and device). RayVoxels adds, on an AVX2 host, a
// vector path for cells at least one voxel away from the border: there the x-rows
// [x-1, x, x+1, x+2] of the neighbourhood are contiguous, so twelve 4-wide loads cover it and
// the interpolations run on whole rows.
#pragma once

#include <cstddef>
#include <cstring>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "kernels/ray_fast_math.h"

#if !defined(__CUDA_ARCH__) && defined(__AVX2__) && defined(__FMA__) && defined(__F16C__)
#include <immintrin.h>
#define VISOPT_RAY_SIMD 1
#endif

namespace visopt {

// Element i of the storage (float or Half) converted to fp32.
VISOPT_HD VISOPT_INLINE float rayLoadAs(const float* data, ptrdiff_t i) {
  return data[i];
}
VISOPT_HD VISOPT_INLINE float rayLoadAs(const Half* data, ptrdiff_t i) {
  // i may be negative (a neighbour before data): offset the pointer, not a wrapped size_t index.
  return rayLoadHalf(data + i, 0);
}

// The lower corner and fractional position of p's cell, p clamped to the grid as
// FieldView::sample does.
struct RayCell {
  glm::ivec3 i0{0};
  glm::vec3 f{0.f};

  RayCell() = default;

  VISOPT_HD VISOPT_INLINE RayCell(glm::ivec3 dims, glm::vec3 p) {
    const glm::vec3 hi(dims - 1);
    p.x = p.x < 0.f ? 0.f : (p.x > hi.x ? hi.x : p.x);
    p.y = p.y < 0.f ? 0.f : (p.y > hi.y ? hi.y : p.y);
    p.z = p.z < 0.f ? 0.f : (p.z > hi.z ? hi.z : p.z);
    i0 = glm::ivec3(p);
    f = p - glm::vec3(i0);
  }
};

// floor(p) for components above -1 (one truncation; bounded positions only).
VISOPT_HD VISOPT_INLINE glm::ivec3 rayFloorAboveMinusOne(glm::vec3 p) {
  return glm::ivec3(int(p.x + 1.f) - 1, int(p.y + 1.f) - 1, int(p.z + 1.f) - 1);
}

template <class T>
struct RayStencil {
  const T* base = nullptr;  // the cell's lower corner (i0, j0, k0)
  // Offsets in elements, clamped at the border: o1 to the upper corner, om one below the lower
  // corner, o2 one above the upper corner; per axis x, y, z.
  ptrdiff_t o1[3], om[3], o2[3];
  glm::vec3 f;  // fractional position in the cell

  VISOPT_HD VISOPT_INLINE RayStencil(const T* data, glm::ivec3 dims, const RayCell& cell)
      : f(cell.f) {
    const ptrdiff_t stride[3] = {1, ptrdiff_t(dims.x), ptrdiff_t(dims.x) * ptrdiff_t(dims.y)};
    for (int a = 0; a < 3; ++a) {
      const int i = cell.i0[a];
      o1[a] = i + 1 < dims[a] ? stride[a] : 0;
      o2[a] = i + 2 < dims[a] ? 2 * stride[a] : o1[a];
      om[a] = i > 0 ? -stride[a] : 0;
    }
    base = data + (ptrdiff_t(cell.i0.z) * stride[2] + ptrdiff_t(cell.i0.y) * stride[1] +
                   ptrdiff_t(cell.i0.x));
  }

  VISOPT_HD VISOPT_INLINE float at(ptrdiff_t offset) const { return rayLoadAs(base, offset); }

  // The eight corners, index = x + 2 y + 4 z.
  VISOPT_HD VISOPT_INLINE void corners(float c[8]) const {
    for (int k = 0; k < 8; ++k)
      c[k] = at(((k & 1) ? o1[0] : 0) + ((k & 2) ? o1[1] : 0) + ((k & 4) ? o1[2] : 0));
  }

  // Trilinear interpolation of the corners.
  VISOPT_HD VISOPT_INLINE float value(const float c[8]) const {
    const float c00 = c[0] + f.x * (c[1] - c[0]), c10 = c[2] + f.x * (c[3] - c[2]);
    const float c01 = c[4] + f.x * (c[5] - c[4]), c11 = c[6] + f.x * (c[7] - c[6]);
    const float c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
    return c0 + f.z * (c1 - c0);
  }

  // Per axis a, s(p + e_a) - s(p - e_a) (twice the central-difference gradient in index units),
  // from the corners c and 24 more voxels.
  VISOPT_HD VISOPT_INLINE glm::vec3 gradient2(const float c[8]) const {
    glm::vec3 g;
    for (int a = 0; a < 3; ++a) {
      // The two other axes b, d and the bilinear weights across them.
      const int b = a == 0 ? 1 : 0, d = a == 2 ? 1 : 2;
      const int bitA = 1 << a, bitB = 1 << b, bitD = 1 << d;
      const float fb = f[b], fd = f[d];
      const float w[4] = {(1.f - fb) * (1.f - fd), fb * (1.f - fd), (1.f - fb) * fd, fb * fd};
      // Lines along a through the four (b, d) corners: below (m), lower (0), upper (1), above (2).
      float lm = 0.f, l0 = 0.f, l1 = 0.f, l2 = 0.f;
      for (int q = 0; q < 4; ++q) {
        const int corner = ((q & 1) ? bitB : 0) | ((q & 2) ? bitD : 0);
        const ptrdiff_t off = ((q & 1) ? o1[b] : 0) + ((q & 2) ? o1[d] : 0);
        lm += w[q] * at(off + om[a]);
        l0 += w[q] * c[corner];
        l1 += w[q] * c[corner | bitA];
        l2 += w[q] * at(off + o2[a]);
      }
      // The lower corner's difference is l1 - lm, the upper one's l2 - l0.
      g[a] = (1.f - f[a]) * (l1 - lm) + f[a] * (l2 - l0);
    }
    return g;
  }
};

#if defined(VISOPT_RAY_SIMD)
namespace raysimd {

inline __m128 loadRow(const float* p) {
  return _mm_loadu_ps(p);
}
inline __m128 loadRow(const Half* p) {
  return _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}
inline __m128 lerp(__m128 a, __m128 b, __m128 t) {
  return _mm_fmadd_ps(t, _mm_sub_ps(b, a), a);
}
// Lane 1 + fx (lane 2 - lane 1): the x-interpolation of a row [x-1, x, x+1, x+2].
inline float lerpX(__m128 row, float fx) {
  const float a = _mm_cvtss_f32(_mm_shuffle_ps(row, row, 1));
  const float b = _mm_cvtss_f32(_mm_shuffle_ps(row, row, 2));
  return a + fx * (b - a);
}

// [a[0], a[1], b[0], b[1]].
inline __m128 loadPairs(const float* a, const float* b) {
  const __m128 lo = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(a)));
  return _mm_loadh_pi(lo, reinterpret_cast<const __m64*>(b));
}
inline __m128 loadPairs(const Half* a, const Half* b) {
  int pa, pb;
  std::memcpy(&pa, a, sizeof pa);
  std::memcpy(&pb, b, sizeof pb);
  return _mm_cvtph_ps(_mm_setr_epi32(pa, pb, 0, 0));
}

}  // namespace raysimd
#endif

// Trilinear sample of a FieldView (fp32 or fp16) with the fast fp16 load; same result as
// FieldView::sample.
template <class T>
VISOPT_HD VISOPT_INLINE float raySampleAs(const T* data, glm::ivec3 dims, glm::vec3 p) {
  const ptrdiff_t sy = dims.x, sz = ptrdiff_t(dims.x) * dims.y;
#if defined(VISOPT_RAY_SIMD)
  {
    // Cells whose eight corners are all inside need no clamping (floor for p > -1).
    const glm::ivec3 i = rayFloorAboveMinusOne(p);
    if (unsigned(i.x) < unsigned(dims.x - 1) && unsigned(i.y) < unsigned(dims.y - 1) &&
        unsigned(i.z) < unsigned(dims.z - 1)) {
      using namespace raysimd;
      const glm::vec3 f = p - glm::vec3(i);
      const T* b = data + (i.z * sz + i.y * sy + i.x);
      // Lanes (x, y) = (0, 0), (1, 0), (0, 1), (1, 1): across z, then y, then x.
      const __m128 v = lerp(loadPairs(b, b + sy), loadPairs(b + sz, b + sy + sz), _mm_set1_ps(f.z));
      const __m128 w = lerp(v, _mm_movehl_ps(v, v), _mm_set1_ps(f.y));
      const float w0 = _mm_cvtss_f32(w), w1 = _mm_cvtss_f32(_mm_shuffle_ps(w, w, 1));
      return w0 + f.x * (w1 - w0);
    }
  }
#endif
  const RayCell cell(dims, p);
  const ptrdiff_t ox = cell.i0.x + 1 < dims.x ? 1 : 0, oy = cell.i0.y + 1 < dims.y ? sy : 0,
                  oz = cell.i0.z + 1 < dims.z ? sz : 0;
  const T* b = data + (cell.i0.z * sz + cell.i0.y * sy + cell.i0.x);
  const glm::vec3 f = cell.f;
  const float c000 = rayLoadAs(b, 0), c100 = rayLoadAs(b, ox);
  const float c010 = rayLoadAs(b, oy), c110 = rayLoadAs(b, ox + oy);
  const float c001 = rayLoadAs(b, oz), c101 = rayLoadAs(b, ox + oz);
  const float c011 = rayLoadAs(b, oy + oz), c111 = rayLoadAs(b, ox + oy + oz);
  const float c00 = c000 + f.x * (c100 - c000), c10 = c010 + f.x * (c110 - c010);
  const float c01 = c001 + f.x * (c101 - c001), c11 = c011 + f.x * (c111 - c011);
  const float c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
  return c0 + f.z * (c1 - c0);
}

VISOPT_HD VISOPT_INLINE float raySample(const FieldView& field, glm::vec3 p) {
  return field.half ? raySampleAs(static_cast<const Half*>(field.data), field.dims, p)
                    : raySampleAs(static_cast<const float*>(field.data), field.dims, p);
}

// Value, and on demand the gradient, at one sample position.
template <class T>
struct RayVoxels {
  const T* data;
  glm::ivec3 dims;
  glm::vec3 position;
  RayCell cell;
#if defined(VISOPT_RAY_SIMD)
  bool interior;
  const T* row0;     // (x-1, y, z): the start of the row through the lower corner
  ptrdiff_t sy, sz;  // strides
  __m128 l;          // rows interpolated across y and z: [x-1, x, x+1, x+2]
  __m128 z0, z1;     // rows at y, y+1 interpolated across z
#endif
  float c[8];  // corners (portable path)

  VISOPT_HD VISOPT_INLINE RayVoxels(const T* d, glm::ivec3 n, glm::vec3 p)
      : data(d), dims(n), position(p) {}

  VISOPT_HD VISOPT_INLINE float value() {
#if defined(VISOPT_RAY_SIMD)
    // Cells at least one voxel from the border need no clamping (floor for p > -1).
    const glm::ivec3 i = rayFloorAboveMinusOne(position);
    interior = unsigned(i.x - 1) < unsigned(dims.x - 3) &&
               unsigned(i.y - 1) < unsigned(dims.y - 3) && unsigned(i.z - 1) < unsigned(dims.z - 3);
    if (interior) {
      cell.i0 = i;
      cell.f = position - glm::vec3(i);
      sy = dims.x;
      sz = ptrdiff_t(dims.x) * dims.y;
      row0 = data + (i.z * sz + i.y * sy + (i.x - 1));
      const __m128 fy = _mm_set1_ps(cell.f.y), fz = _mm_set1_ps(cell.f.z);
      z0 = raysimd::lerp(raysimd::loadRow(row0), raysimd::loadRow(row0 + sz), fz);
      z1 = raysimd::lerp(raysimd::loadRow(row0 + sy), raysimd::loadRow(row0 + sy + sz), fz);
      l = raysimd::lerp(z0, z1, fy);
      return raysimd::lerpX(l, cell.f.x);
    }
#endif
    cell = RayCell(dims, position);
    const RayStencil<T> s(data, dims, cell);
    s.corners(c);
    return s.value(c);
  }

  // Twice the central-difference gradient in index units (see RayStencil::gradient2); after
  // value().
  VISOPT_HD VISOPT_INLINE glm::vec3 gradient2() const {
#if defined(VISOPT_RAY_SIMD)
    if (interior) {
      using namespace raysimd;
      const glm::vec3 f = cell.f;
      const __m128 fy = _mm_set1_ps(f.y), fz = _mm_set1_ps(f.z);
      // x: the interpolated rows' differences at the two x-corners.
      const float lm = _mm_cvtss_f32(l), l0 = _mm_cvtss_f32(_mm_shuffle_ps(l, l, 1));
      const float l1 = _mm_cvtss_f32(_mm_shuffle_ps(l, l, 2)),
                  l2 = _mm_cvtss_f32(_mm_shuffle_ps(l, l, 3));
      const float gx = (1.f - f.x) * (l1 - lm) + f.x * (l2 - l0);
      // y: rows at y-1 and y+2 across z; the difference rows, then across x.
      const __m128 zm = lerp(loadRow(row0 - sy), loadRow(row0 - sy + sz), fz);
      const __m128 z2 = lerp(loadRow(row0 + 2 * sy), loadRow(row0 + 2 * sy + sz), fz);
      const __m128 dy =
          _mm_fmadd_ps(fy, _mm_sub_ps(_mm_sub_ps(z2, z0), _mm_sub_ps(z1, zm)), _mm_sub_ps(z1, zm));
      // z: rows at z-1 and z+2 across y, with those at z and z+1.
      const __m128 y0 = lerp(loadRow(row0), loadRow(row0 + sy), fy);
      const __m128 y1 = lerp(loadRow(row0 + sz), loadRow(row0 + sy + sz), fy);
      const __m128 ym = lerp(loadRow(row0 - sz), loadRow(row0 + sy - sz), fy);
      const __m128 y2 = lerp(loadRow(row0 + 2 * sz), loadRow(row0 + sy + 2 * sz), fy);
      const __m128 dz =
          _mm_fmadd_ps(fz, _mm_sub_ps(_mm_sub_ps(y2, y0), _mm_sub_ps(y1, ym)), _mm_sub_ps(y1, ym));
      return glm::vec3(gx, lerpX(dy, f.x), lerpX(dz, f.x));
    }
#endif
    const RayStencil<T> s(data, dims, cell);
    return s.gradient2(c);
  }
};

}  // namespace visopt
