// Cheap elementary functions for the ray marcher's inner loop (kernels/ray_march.h).
//
// On the host, expf and powf are library calls that are neither inlined nor vectorised; here
// they are replaced by short polynomials after range reduction, accurate to a few 1e-7
// relative — far below what an 8-bit image or the 1 % closed-form tests can see. On the device
// CUDA's own functions are already fast, so these forward to them.
//
// fp16 loads: with g++ half.h converts through _Float16 (one F16C instruction); when nvcc
// compiles the host side it goes through cuda_fp16's host routine, a software conversion.
// rayLoadHalf uses the F16C instruction there too.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/half.h"
#include "core/hd.h"

// Outside the namespace: included within it, the intrinsics' declarations would land in visopt::
// whenever this header came first (it did in test_shading).
#if !defined(__CUDA_ARCH__) && defined(__SSE__)
#include <xmmintrin.h>
#define VISOPT_RAY_SSE 1
#endif

#if defined(__CUDACC__) && !defined(__CUDA_ARCH__) && defined(__F16C__)
#include <immintrin.h>
#define VISOPT_RAY_F16C 1
#endif

namespace visopt {

VISOPT_HD VISOPT_INLINE float rayLoadHalf(const Half* data, size_t i) {
#if defined(VISOPT_RAY_F16C) && !defined(__CUDA_ARCH__)
  return _cvtsh_ss(data[i].bits);
#else
  return halfToFloat(data[i]);
#endif
}

// Loads element i of fp32 or fp16 storage as fp32 (the run-time precision of a FieldView).
VISOPT_HD VISOPT_INLINE float rayLoad(const void* data, bool half, size_t i) {
  return half ? rayLoadHalf(static_cast<const Half*>(data), i) : static_cast<const float*>(data)[i];
}

// 1 / sqrt(x) for x > 0 and 1 / x: on the host the hardware estimates refined by one Newton
// step (relative error below 1e-6), which keep the divider free; sqrtf and division otherwise.
VISOPT_HD VISOPT_INLINE float rayRsqrt(float x) {
#if defined(__CUDA_ARCH__)
  return rsqrtf(x);
#elif defined(VISOPT_RAY_SSE)
  const float r = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  return r * (1.5f - 0.5f * x * r * r);
#else
  return 1.f / sqrtf(x);
#endif
}

VISOPT_HD VISOPT_INLINE float rayRcp(float x) {
#if defined(__CUDA_ARCH__)
  return 1.f / x;
#elif defined(VISOPT_RAY_SSE)
  const float r = _mm_cvtss_f32(_mm_rcp_ss(_mm_set_ss(x)));
  return r * (2.f - x * r);
#else
  return 1.f / x;
#endif
}

#if !defined(__CUDA_ARCH__)
namespace rayfast {

VISOPT_HD VISOPT_INLINE float bitsToFloat(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

VISOPT_HD VISOPT_INLINE uint32_t floatToBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

}  // namespace rayfast
#endif

// 2^x for any finite x; results below 2^-126 flush to 2^-126 (callers only multiply them into
// quantities that are negligible there). Relative error below 3e-7 for |x| < 64.
VISOPT_HD VISOPT_INLINE float rayExp2(float x) {
#if defined(__CUDA_ARCH__)
  return exp2f(x);
#else
  x = x < -126.f ? -126.f : (x > 126.f ? 126.f : x);
  // x = k + r with k = round(x), |r| <= 1/2; the shift makes the truncation a floor.
  const int k = int(x + 127.5f) - 127;
  const float y = (x - float(k)) * 0.693147180559945f;  // e^y = 2^r, |y| <= 0.347
  // Taylor series of e^y to degree 7: truncation error below 6e-9 on |y| <= 0.347.
  float p = 1.f / 5040.f;
  p = p * y + 1.f / 720.f;
  p = p * y + 1.f / 120.f;
  p = p * y + 1.f / 24.f;
  p = p * y + 1.f / 6.f;
  p = p * y + 0.5f;
  p = p * y + 1.f;
  p = p * y + 1.f;
  return p * rayfast::bitsToFloat(uint32_t(k + 127) << 23);
#endif
}

// log2(x) for finite x > 0 (normal numbers). Absolute error below 1e-7 (plus rounding).
VISOPT_HD VISOPT_INLINE float rayLog2(float x) {
#if defined(__CUDA_ARCH__)
  return log2f(x);
#else
  const uint32_t bits = rayfast::floatToBits(x);
  int e = int((bits >> 23) & 0xffu) - 127;
  float m = rayfast::bitsToFloat((bits & 0x007fffffu) | 0x3f800000u);  // in [1, 2)
  if (m > 1.41421356f) {
    m *= 0.5f;
    ++e;
  }
  // ln m = 2 atanh(z), z = (m - 1) / (m + 1), |z| <= 0.1716: odd series to z^9.
  const float z = (m - 1.f) * rayRcp(m + 1.f);
  const float z2 = z * z;
  float s = 1.f / 9.f;
  s = s * z2 + 1.f / 7.f;
  s = s * z2 + 1.f / 5.f;
  s = s * z2 + 1.f / 3.f;
  s = s * z2 + 1.f;
  return float(e) + (2.f * 1.44269504088896f) * z * s;
#endif
}

// x^y for x in [0, 1] and y > 0 (the Blinn-Phong lobe); x^0 = 1.
// yInt: y when y is a whole number in [1, 1024] (then x^y is a few exact squarings), else 0.
VISOPT_HD VISOPT_INLINE float rayPowUnit(float x, float y, int yInt) {
#if defined(__CUDA_ARCH__)
  (void)yInt;
  return powf(x, y);
#else
  if (yInt > 0) {
    float result = 1.f;
    for (unsigned n = unsigned(yInt); n != 0u; n >>= 1u) {
      if (n & 1u) result *= x;
      x *= x;
    }
    return result;
  }
  if (y == 0.f) return 1.f;
  if (x < 1e-30f) return 0.f;
  return rayExp2(y * rayLog2(x));
#endif
}

// The yInt argument of rayPowUnit for exponent y.
inline int rayWholeExponent(float y) {
  return y >= 1.f && y <= 1024.f && float(int(y)) == y ? int(y) : 0;
}

// The opacity of a segment of optical depth tau >= 0: 1 - exp(-tau), without cancellation for
// small tau.
VISOPT_HD VISOPT_INLINE float raySegmentAlpha(float tau) {
#if defined(__CUDA_ARCH__)
  return -expm1f(-tau);
#else
  if (tau < 0.25f) {
    // 1 - e^-tau = tau (1 - tau/2 (1 - tau/3 (1 - ... tau/8))): truncation below 2e-10.
    float s = 1.f - tau * (1.f / 8.f);
    s = 1.f - tau * (1.f / 7.f) * s;
    s = 1.f - tau * (1.f / 6.f) * s;
    s = 1.f - tau * (1.f / 5.f) * s;
    s = 1.f - tau * (1.f / 4.f) * s;
    s = 1.f - tau * (1.f / 3.f) * s;
    s = 1.f - tau * 0.5f * s;
    return tau * s;
  }
  return 1.f - rayExp2(-1.44269504088896f * tau);
#endif
}

}  // namespace visopt
