// VISOPT_HD marks code callable from host and device. Under nvcc it expands to
// __host__ __device__; under a plain C++ compiler to nothing. Internal only: the public headers
// never name CUDA.
#pragma once

#if defined(__CUDACC__)
#define VISOPT_HD __host__ __device__
#define VISOPT_DEVICE_COMPILE 1
#else
#define VISOPT_HD
#endif

// Hot sampling helpers must inline into the ray-marching loops.
#if defined(__CUDACC__)
#define VISOPT_INLINE __forceinline__
#else
#define VISOPT_INLINE inline __attribute__((always_inline))
#endif

#if defined(__CUDA_ARCH__)
#define VISOPT_ON_DEVICE 1
#endif

// Before a loop over SIMD lanes: keep it a loop so that the vectoriser turns it into vector
// instructions (GCC otherwise unrolls a short constant loop completely first, and then vectorises
// neither it nor the loop around it). A GPU thread runs the lanes one after the other; nvcc
// (which would warn on the pragma in host passes too) gets the plain loop.
#if defined(__CUDACC__) || !defined(__GNUC__) || defined(__clang__)
#define VISOPT_LANE_LOOP
#else
#define VISOPT_LANE_LOOP _Pragma("GCC unroll 1") _Pragma("GCC ivdep")
#endif
