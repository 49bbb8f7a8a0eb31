// Device-visible views of dense fields: raw pointer + storage precision + dims. Loads convert to
// fp32, stores convert from fp32. Trilinear sampling uses continuous index coordinates with voxel
// centres at integers and clamps to the border.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/half.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "visopt/field.h"

namespace visopt {

struct FieldView {
  void* data = nullptr;
  bool half = false;
  glm::ivec3 dims{0};

  FieldView() = default;
  explicit FieldView(Field3D& f)
      : data(f.raw()), half(f.precision() == Precision::FP16), dims(f.grid().dims) {}
  explicit FieldView(const Field3D& f)
      : data(const_cast<void*>(f.raw())),
        half(f.precision() == Precision::FP16),
        dims(f.grid().dims) {}

  VISOPT_HD bool valid() const { return data != nullptr; }
  VISOPT_HD size_t size() const { return size_t(dims.x) * size_t(dims.y) * size_t(dims.z); }
  VISOPT_HD VISOPT_INLINE size_t index(int i, int j, int k) const {
    return (size_t(k) * size_t(dims.y) + size_t(j)) * size_t(dims.x) + size_t(i);
  }
  VISOPT_HD VISOPT_INLINE float load(size_t i) const {
    return half ? halfToFloat(static_cast<const Half*>(data)[i])
                : static_cast<const float*>(data)[i];
  }
  // fp16 stores saturate at +-65504 (fp16's largest finite value) rather than overflow to inf;
  // NaN stores as -65504, as fmaxf would.
  VISOPT_HD void store(size_t i, float v) const {
    if (half)
      static_cast<Half*>(data)[i] = floatToHalf(minOf(maxOf(v, -65504.f), 65504.f));
    else
      static_cast<float*>(data)[i] = v;
  }
  VISOPT_HD VISOPT_INLINE float at(int i, int j, int k) const { return load(index(i, j, k)); }

  // Trilinear interpolation at continuous index coordinates p, clamped to the grid.
  VISOPT_HD VISOPT_INLINE float sample(glm::vec3 p) const {
    p = glm::clamp(p, glm::vec3(0.f), glm::vec3(dims - 1));
    glm::ivec3 i0 = glm::ivec3(p);
    glm::ivec3 i1 = glm::min(i0 + 1, dims - 1);
    glm::vec3 f = p - glm::vec3(i0);
    float c000 = at(i0.x, i0.y, i0.z), c100 = at(i1.x, i0.y, i0.z);
    float c010 = at(i0.x, i1.y, i0.z), c110 = at(i1.x, i1.y, i0.z);
    float c001 = at(i0.x, i0.y, i1.z), c101 = at(i1.x, i0.y, i1.z);
    float c011 = at(i0.x, i1.y, i1.z), c111 = at(i1.x, i1.y, i1.z);
    float c00 = c000 + f.x * (c100 - c000), c10 = c010 + f.x * (c110 - c010);
    float c01 = c001 + f.x * (c101 - c001), c11 = c011 + f.x * (c111 - c011);
    float c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
    return c0 + f.z * (c1 - c0);
  }
  // True when p lies within the cell-centred grid's support [-0.5, dims - 0.5].
  VISOPT_HD bool inside(glm::vec3 p) const {
    return p.x >= -0.5f && p.y >= -0.5f && p.z >= -0.5f && p.x <= float(dims.x) - 0.5f &&
           p.y <= float(dims.y) - 0.5f && p.z <= float(dims.z) - 0.5f;
  }
};

}  // namespace visopt
