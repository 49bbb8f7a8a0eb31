// The one place that launches work. parallelFor(name, n, f) runs f(i) for i in [0, n) on the
// active backend; reduce(...) folds f(i) with an associative op. Every launch is timed under its
// name (exec::recordLaunch), so per-stage timings need no extra code.
//
// Backend choice: in a translation unit compiled by nvcc (the device sources, see
// libvisopt/CMakeLists.txt) and when activeBackend() is CUDA, f is launched as a CUDA kernel and
// must be a VISOPT_HD functor or lambda working on memory from exec::allocate. Otherwise the
// same f runs in a oneTBB loop.
#pragma once

#include <chrono>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "core/hd.h"
#include "visopt/exec.h"

namespace visopt::exec {

// Memory reachable from both backends (CUDA managed memory when CUDA is active).
void* allocate(size_t bytes);
void deallocate(void* p);

void recordLaunch(const char* name, double ms, double items);

// Runs launches on a chosen backend for the lifetime of this object (the parity test compares
// CPU and CUDA in one process). Memory from allocate() is reachable from both.
class ScopedBackend {
 public:
  explicit ScopedBackend(Backend b);
  ~ScopedBackend();
  ScopedBackend(const ScopedBackend&) = delete;
  ScopedBackend& operator=(const ScopedBackend&) = delete;

 private:
  int previous_;
};

class LaunchTimer {
 public:
  LaunchTimer(const char* name, double items)
      : name_(name), items_(items), start_(std::chrono::steady_clock::now()) {}
  ~LaunchTimer() {
    auto ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
                  .count();
    recordLaunch(name_, ms, items_);
  }
  LaunchTimer(const LaunchTimer&) = delete;
  LaunchTimer& operator=(const LaunchTimer&) = delete;

 private:
  const char* name_;
  double items_;
  std::chrono::steady_clock::time_point start_;
};

#if defined(VISOPT_WITH_CUDA) && defined(__CUDACC__)
template <class F>
__global__ void parallelForKernel(int64_t n, F f) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += int64_t(blockDim.x) * gridDim.x)
    f(i);
}

template <class T, class F, class Op>
__global__ void reduceKernel(int64_t n, T init, F f, Op op, T* partials) {
  extern __shared__ unsigned char sharedBytes[];
  T* shared = reinterpret_cast<T*>(sharedBytes);
  T acc = init;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += int64_t(blockDim.x) * gridDim.x)
    acc = op(acc, f(i));
  shared[threadIdx.x] = acc;
  __syncthreads();
  for (unsigned s = blockDim.x / 2; s > 0; s >>= 1) {
    if (threadIdx.x < s) shared[threadIdx.x] = op(shared[threadIdx.x], shared[threadIdx.x + s]);
    __syncthreads();
  }
  if (threadIdx.x == 0) partials[blockIdx.x] = shared[0];
}

void cudaSynchronizeOrThrow(const char* name);
#endif

template <class F>
void parallelFor(const char* name, int64_t n, F f) {
  if (n <= 0) return;
  LaunchTimer timer(name, double(n));
#if defined(VISOPT_WITH_CUDA) && defined(__CUDACC__)
  if (activeBackend() == Backend::CUDA) {
    const int block = 256;
    const int64_t blocks = (n + block - 1) / block;
    parallelForKernel<<<unsigned(blocks < 65535 ? blocks : 65535), block>>>(n, f);
    cudaSynchronizeOrThrow(name);
    return;
  }
#endif
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, n), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

template <class T, class F, class Op>
T reduce(const char* name, int64_t n, T init, F f, Op op) {
  if (n <= 0) return init;
  LaunchTimer timer(name, double(n));
#if defined(VISOPT_WITH_CUDA) && defined(__CUDACC__)
  if (activeBackend() == Backend::CUDA) {
    const int block = 256;
    int64_t blocks64 = (n + block - 1) / block;
    const unsigned blocks = unsigned(blocks64 < 1024 ? blocks64 : 1024);
    T* partials = static_cast<T*>(allocate(sizeof(T) * blocks));
    reduceKernel<<<blocks, block, block * sizeof(T)>>>(n, init, f, op, partials);
    cudaSynchronizeOrThrow(name);
    T acc = init;
    for (unsigned b = 0; b < blocks; ++b) acc = op(acc, partials[b]);
    deallocate(partials);
    return acc;
  }
#endif
  // Deterministic: the ranges and the order they are combined in depend on n only (at most 512
  // leaves), not on how the threads stole work, so a floating-point sum is the same in every
  // run (the auto-partitioned reduce differed in its last bits under load).
  const int64_t grain = (n + 255) / 256;
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int64_t>(0, n, size_t(grain)), init,
      [&](const tbb::blocked_range<int64_t>& r, T acc) {
        for (int64_t i = r.begin(); i != r.end(); ++i) acc = op(acc, f(i));
        return acc;
      },
      op);
}

}  // namespace visopt::exec
