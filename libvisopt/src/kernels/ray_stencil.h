// Trilinear value and central-difference gradient of a scalar field from one neighbourhood.
//
// The renderer shades with the gradient g = (s(p + e_a) - s(p - e_a)) / 2 of the trilinearly
// interpolated field s. Shifting p by one whole voxel keeps its fractional part, so each
// difference is the trilinear interpolation, with p's weights, of the central differences
// v(c + e_a) - v(c - e_a) at the eight corners c of p's cell — with the same clamping at the
// border as FieldView::sample (an index one past the border reads the border voxel). The
// corners and their 24 outer neighbours along the three axes (32 voxels, not the 56 of seven
// separate trilinear samples) give the value and the gradient, addressed once from p.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/hd.h"
#include "kernels/ray_fast_math.h"

namespace visopt {

// Element T of the storage (float or Half) converted to fp32.
VISOPT_HD VISOPT_INLINE float rayLoadAs(const float* data, ptrdiff_t i) { return data[i]; }
VISOPT_HD VISOPT_INLINE float rayLoadAs(const Half* data, ptrdiff_t i) {
  return rayLoadHalf(data, size_t(i));
}

template <class T>
struct RayStencil {
  const T* base = nullptr;  // the cell's lower corner (i0, j0, k0)
  // Offsets in elements, clamped at the border: o1 to the upper corner, om one below the lower
  // corner, o2 one above the upper corner; per axis x, y, z.
  ptrdiff_t o1[3], om[3], o2[3];
  glm::vec3 f;  // fractional position in the cell

  // Positions p in continuous index coordinates (voxel centres at integers), clamped to the grid.
  VISOPT_HD VISOPT_INLINE RayStencil(const T* data, glm::ivec3 dims, glm::vec3 p) {
    p = glm::clamp(p, glm::vec3(0.f), glm::vec3(dims - 1));
    const glm::ivec3 i0 = glm::ivec3(p);
    f = p - glm::vec3(i0);
    const ptrdiff_t stride[3] = {1, ptrdiff_t(dims.x), ptrdiff_t(dims.x) * ptrdiff_t(dims.y)};
    for (int a = 0; a < 3; ++a) {
      const bool up1 = i0[a] + 1 < dims[a], up2 = i0[a] + 2 < dims[a];
      o1[a] = up1 ? stride[a] : 0;
      o2[a] = up2 ? 2 * stride[a] : o1[a];
      om[a] = i0[a] > 0 ? -stride[a] : 0;
    }
    base = data + (ptrdiff_t(i0.z) * stride[2] + ptrdiff_t(i0.y) * stride[1] + ptrdiff_t(i0.x));
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

  // Sum over the axes of the differences s(p + e_a) - s(p - e_a) (twice the central-difference
  // gradient in index units), from the corners c and 24 more voxels.
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

// Trilinear sample of a FieldView (fp32 or fp16) with the fast fp16 load; same result as
// FieldView::sample.
VISOPT_HD VISOPT_INLINE float raySample(const FieldView& field, glm::vec3 p) {
  float c[8];
  if (field.half) {
    const RayStencil<Half> s(static_cast<const Half*>(field.data), field.dims, p);
    s.corners(c);
    return s.value(c);
  }
  const RayStencil<float> s(static_cast<const float*>(field.data), field.dims, p);
  s.corners(c);
  return s.value(c);
}

}  // namespace visopt
