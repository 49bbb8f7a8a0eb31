// The thin host-side interface to the CUDA runtime. Implemented in cuda_runtime.cu when the
// CUDA backend is built, and by stubs (cuda_runtime_stub.cpp) otherwise.
#pragma once

#include <cstddef>
#include <string>

namespace visopt::exec {

// True when a CUDA device answers; otherwise `why` says what the runtime reported.
bool cudaDeviceAnswers(std::string& why);
std::string cudaDeviceName();
void* cudaAllocateManaged(size_t bytes);
void cudaFreeManaged(void* p);

}  // namespace visopt::exec
