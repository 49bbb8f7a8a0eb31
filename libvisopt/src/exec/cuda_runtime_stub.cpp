// Stubs for a build without the CUDA backend; never called when activeBackend() is the CPU.
#if !defined(VISOPT_WITH_CUDA)
#include "exec/cuda_runtime.h"
#include "visopt/error.h"

namespace visopt::exec {

bool cudaDeviceAnswers(std::string& why) {
  why = "built without CUDA";
  return false;
}
std::string cudaDeviceName() {
  return "none";
}
void* cudaAllocateManaged(size_t) {
  throw Error(ErrorKind::Failure, "CUDA is not built in");
}
void cudaFreeManaged(void*) {}

}  // namespace visopt::exec
#endif
