// The 16-bit storage type: the same 16 bits on host and device, converted at load and store.
// nvcc crashes on _Float16 in device code, so device code converts with cuda_fp16's intrinsics;
// plain g++ uses _Float16, a single F16C instruction with -march=native. The host side of an
// nvcc-compiled translation unit uses that instruction through its intrinsic when the host
// compiler targets F16C (cuda_fp16's host functions convert in software, which made the CPU path
// of CUDA-enabled builds slower on fp16 fields).
#pragma once

#include <cstdint>
#include <cstring>

#include "core/hd.h"

#if defined(__CUDACC__)
#include <cuda_fp16.h>
#if !defined(__CUDA_ARCH__) && defined(__F16C__)
#include <immintrin.h>
#define VISOPT_HOST_F16C 1
#endif
#elif defined(__clang__) && __clang_major__ < 15 && (defined(__x86_64__) || defined(__i386__))
// clang before 15 accepts _Float16 on x86 only with AVX512-FP16 (the sanitizer and fuzz builds
// use clang 14): convert with the F16C intrinsics there, the same instruction g++ emits.
#if defined(__F16C__)
#include <immintrin.h>
#define VISOPT_HOST_F16C 1
#else
#error "visopt: clang < 15 on x86 needs F16C for fp16 fields (build with -march=native)"
#endif
#endif

namespace visopt {

struct Half {
  uint16_t bits;
};

VISOPT_HD inline float halfToFloat(Half h) {
#if defined(VISOPT_HOST_F16C) && !defined(__CUDA_ARCH__)
  return _cvtsh_ss(h.bits);
#elif defined(__CUDACC__)
  __half_raw raw;
  raw.x = h.bits;
  return __half2float(__half(raw));
#else
  _Float16 f;
  std::memcpy(&f, &h.bits, 2);
  return static_cast<float>(f);
#endif
}

// Round to nearest even; values beyond fp16's range become +-inf, which callers avoid by
// storing normalised or bounded quantities only.
VISOPT_HD inline Half floatToHalf(float v) {
#if defined(VISOPT_HOST_F16C) && !defined(__CUDA_ARCH__)
  // _mm_cvtps_ph rather than _cvtss_sh, whose clang macro is a compound literal (-Wpedantic).
  const __m128i h = _mm_cvtps_ph(_mm_set_ss(v), _MM_FROUND_TO_NEAREST_INT);
  return Half{static_cast<uint16_t>(_mm_cvtsi128_si32(h) & 0xffff)};
#elif defined(__CUDACC__)
  __half_raw raw = __half_raw(__float2half_rn(v));
  return Half{raw.x};
#else
  _Float16 f = static_cast<_Float16>(v);
  Half h;
  std::memcpy(&h.bits, &f, 2);
  return h;
#endif
}

}  // namespace visopt
