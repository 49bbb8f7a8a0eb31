// Typed access to a field's storage for loops that should vectorise: Fp32Access and Fp16Access
// (one precision, known at compile time, so no branch per load) and AnyAccess (a FieldView, any
// precision). fp16 goes through integer bit operations on the host, which g++ vectorises; the
// values are those of halfToFloat / floatToHalf.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "core/field_view.h"
#include "core/half.h"
#include "core/hd.h"
#include "core/min_max.h"

namespace visopt {

struct Fp32Access {
  float* p = nullptr;
  VISOPT_HD VISOPT_INLINE float load(size_t i) const { return p[i]; }
  VISOPT_HD VISOPT_INLINE void store(size_t i, float v) const { p[i] = v; }
  VISOPT_HD VISOPT_INLINE float kept(float v) const { return v; }  // what a store keeps
};

// fp16 to fp32 for the host row loops: g++ converts _Float16 one value at a time, which keeps
// them scalar, so this widens the bits with integer ops and a multiply by 2^112 (exact for
// normal and subnormal halves) and patches inf/NaN: the same value as halfToFloat, vectorised.
// Device code keeps halfToFloat (the host side of an nvcc-compiled unit takes the bit ops too: a
// scalar F16C conversion there made the fp16 level-set step 3x slower than in a g++ build).
VISOPT_HD VISOPT_INLINE float halfToFloatRow(Half h) {
#if defined(__CUDA_ARCH__)
  return halfToFloat(h);
#else
  const uint32_t bits = h.bits;
  const uint32_t magnitude = (bits & 0x7fffu) << 13;
  float f;
  std::memcpy(&f, &magnitude, 4);
  f *= 0x1p112f;
  uint32_t u;
  std::memcpy(&u, &f, 4);
  u |= (bits & 0x7c00u) == 0x7c00u ? 0x7f800000u : 0u;
  u |= (bits & 0x8000u) << 16;
  std::memcpy(&f, &u, 4);
  return f;
#endif
}

// fp32 to fp16 for |v| <= 65504 (what Fp16Access stores after saturating), rounding to nearest
// even in integer ops (and one add for subnormals) the compiler can vectorise: the same bits as
// floatToHalf there. Device code keeps floatToHalf.
VISOPT_HD VISOPT_INLINE Half floatToHalfRow(float v) {
#if defined(__CUDA_ARCH__)
  return floatToHalf(v);
#else
  uint32_t f;
  std::memcpy(&f, &v, 4);
  const uint32_t sign = f & 0x80000000u;
  f ^= sign;
  // Normal halves: rebias the exponent, round the 13 dropped bits to nearest even.
  const uint32_t normal = (f + 0xc8000fffu + ((f >> 13) & 1u)) >> 13;
  // Subnormal halves (below 2^-14): adding 0.5 lets the FPU round the mantissa into place.
  float t;
  std::memcpy(&t, &f, 4);
  t += 0.5f;
  uint32_t tb;
  std::memcpy(&tb, &t, 4);
  const uint32_t subnormal = tb - 0x3f000000u;
  return Half{uint16_t((f < 0x38800000u ? subnormal : normal) | (sign >> 16))};
#endif
}

struct Fp16Access {
  Half* p = nullptr;
  VISOPT_HD VISOPT_INLINE float load(size_t i) const { return halfToFloatRow(p[i]); }
  // Saturates at fp16's largest finite value, as FieldView::store does.
  VISOPT_HD VISOPT_INLINE void store(size_t i, float v) const {
    p[i] = floatToHalfRow(minOf(maxOf(v, -65504.f), 65504.f));
  }
  VISOPT_HD VISOPT_INLINE float kept(float v) const {
    return halfToFloatRow(floatToHalfRow(minOf(maxOf(v, -65504.f), 65504.f)));
  }
};

struct AnyAccess {
  FieldView f;
  VISOPT_HD VISOPT_INLINE float load(size_t i) const { return f.load(i); }
  VISOPT_HD VISOPT_INLINE void store(size_t i, float v) const { f.store(i, v); }
  VISOPT_HD VISOPT_INLINE float kept(float v) const {
    return f.half ? halfToFloat(floatToHalf(minOf(maxOf(v, -65504.f), 65504.f))) : v;
  }
};

// The storage of `f` through accessor A (Fp32Access, Fp16Access or AnyAccess); for the first
// two the caller has checked that the view's precision is A's.
template <class A>
VISOPT_HD VISOPT_INLINE A accessTo(const FieldView& f) {
  if constexpr (std::is_same_v<A, Fp16Access>)
    return {static_cast<Half*>(f.data)};
  else if constexpr (std::is_same_v<A, Fp32Access>)
    return {static_cast<float*>(f.data)};
  else
    return {f};
}

}  // namespace visopt
