// Host-side CUDA runtime calls: device discovery, managed memory, launch error checks.
#include <cuda_runtime.h>

#include <string>

#include "exec/cuda_runtime.h"
#include "exec/parallel.h"
#include "visopt/error.h"

namespace visopt::exec {

bool cudaDeviceAnswers(std::string& why) {
  int count = 0;
  // With no driver this is cudaErrorInsufficientDriver, not cudaErrorNoDevice: any error means
  // "use the CPU".
  cudaError_t err = cudaGetDeviceCount(&count);
  if (err != cudaSuccess) {
    why = cudaGetErrorString(err);
    return false;
  }
  if (count == 0) {
    why = "no device";
    return false;
  }
  return true;
}

std::string cudaDeviceName() {
  cudaDeviceProp prop{};
  if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) return "unknown device";
  return prop.name;
}

void* cudaAllocateManaged(size_t bytes) {
  void* p = nullptr;
  cudaError_t err = cudaMallocManaged(&p, bytes);
  if (err != cudaSuccess)
    throw Error(ErrorKind::Failure, std::string("CUDA allocation of ") +
                                        std::to_string(bytes >> 20) +
                                        " MiB failed: " + cudaGetErrorString(err));
  return p;
}

void cudaFreeManaged(void* p) {
  cudaFree(p);
}

void cudaSynchronizeOrThrow(const char* name) {
  cudaError_t err = cudaGetLastError();
  if (err == cudaSuccess) err = cudaDeviceSynchronize();
  if (err != cudaSuccess)
    throw Error(ErrorKind::Failure,
                std::string("CUDA kernel '") + name + "' failed: " + cudaGetErrorString(err));
}

}  // namespace visopt::exec
