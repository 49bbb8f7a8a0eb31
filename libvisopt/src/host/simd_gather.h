// Loads of 16 values at 16 arbitrary indices of one fp32 or fp16 field, the CPU backend's
// gathers for kernels arranged in SIMD lanes (host/visibility_scan_packet.h, the extinction
// step's rows). With AVX-512 one gather instruction; otherwise a loop the compiler may
// vectorise. fp16 gathers the aligned 32-bit word that holds each value and keeps its low or high
// half (x86 is little-endian): there are no 16-bit gathers, and g++ does not vectorise fp16
// loads one by one. That word never passes the end of the allocation, as fields are allocated in
// whole 64-byte lines (exec::allocate). Host only.
#pragma once

#include <cstdint>
#include <type_traits>

#include "core/half.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace visopt {

constexpr int kGatherLanes = 16;

// gatherLanes without SIMD: what it computes, and what it runs on a CPU without AVX-512.
template <class Storage>
inline void gatherLanesPortable(const void* data, const int* index, float* out) {
  static_assert(std::is_same_v<Storage, float> || std::is_same_v<Storage, Half>);
  const Storage* values = static_cast<const Storage*>(data);
  for (int l = 0; l < kGatherLanes; ++l) {
    if constexpr (std::is_same_v<Storage, Half>)
      out[l] = halfToFloat(values[index[l]]);
    else
      out[l] = values[index[l]];
  }
}

// out[l] = data[index[l]] as float, l < 16; index and out 64-byte aligned.
template <class Storage>
inline void gatherLanes(const void* data, const int* index, float* out) {
  static_assert(std::is_same_v<Storage, float> || std::is_same_v<Storage, Half>);
#if defined(__AVX512F__)
  // g++ 12's intrinsics initialise their unused pass-through operand from itself, which
  // -W(maybe-)uninitialized reports at every call (GCC bug 105593, fixed in g++ 13).
#pragma GCC diagnostic push
#if !defined(__clang__)  // clang (the fuzzing build) has no such warning and warns about the name
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#pragma GCC diagnostic ignored "-Wuninitialized"
  const __m512i i = _mm512_load_si512(index);
  if constexpr (std::is_same_v<Storage, Half>) {
    const __m512i word = _mm512_i32gather_epi32(_mm512_srli_epi32(i, 1), data, 4);
    const __m512i shift = _mm512_slli_epi32(_mm512_and_si512(i, _mm512_set1_epi32(1)), 4);
    const __m256i bits = _mm512_cvtepi32_epi16(_mm512_srlv_epi32(word, shift));
    _mm512_store_ps(out, _mm512_cvtph_ps(bits));
  } else {
    _mm512_store_ps(out, _mm512_i32gather_ps(i, data, 4));
  }
#pragma GCC diagnostic pop
#else
  gatherLanesPortable<Storage>(data, index, out);
#endif
}

}  // namespace visopt
