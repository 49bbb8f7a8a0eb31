#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <new>
#include <string>

#include <tbb/info.h>

#include "exec/cuda_runtime.h"
#include "exec/parallel.h"
#include "visopt/error.h"

namespace visopt {

namespace {

Backend decideBackend() {
  const char* env = std::getenv("VISOPT_BACKEND");
  const bool forceCpu = env && std::string(env) == "cpu";
  if (cudaCompiledIn() && !forceCpu) {
    std::string why;
    if (exec::cudaDeviceAnswers(why)) return Backend::CUDA;
    std::fprintf(stderr, "visopt: no CUDA device answers (%s); using the CPU backend\n",
                 why.c_str());
  } else if (!cudaCompiledIn()) {
    std::fprintf(stderr, "visopt: built without CUDA; using the CPU backend\n");
  }
  return Backend::CPU;
}

struct TimingRegistry {
  std::mutex mutex;
  std::map<std::string, StageTiming> stages;
};

TimingRegistry& registry() {
  static TimingRegistry r;
  return r;
}

}  // namespace

bool cudaCompiledIn() {
#if defined(VISOPT_WITH_CUDA)
  return true;
#else
  return false;
#endif
}

namespace {
std::atomic<int> backendOverride{-1};
Backend processBackend() {
  static const Backend backend = decideBackend();
  return backend;
}
}  // namespace

Backend activeBackend() {
  int forced = backendOverride.load(std::memory_order_relaxed);
  return forced >= 0 ? static_cast<Backend>(forced) : processBackend();
}

std::string backendDescription() {
  if (activeBackend() == Backend::CUDA) return "CUDA (" + exec::cudaDeviceName() + ")";
  return "CPU (oneTBB, " + std::to_string(tbb::info::default_concurrency()) + " threads)";
}

std::vector<StageTiming> stageTimings() {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  std::vector<StageTiming> out;
  for (auto& [name, t] : r.stages) out.push_back(t);
  return out;
}

void resetStageTimings() {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  r.stages.clear();
}

namespace exec {

namespace {
Backend checkedBackend(Backend b) {
  if (b == Backend::CUDA && processBackend() != Backend::CUDA)
    throw Error(ErrorKind::Usage, "the CUDA backend is not available");
  return b;
}
}  // namespace

ScopedBackend::ScopedBackend(Backend b)
    : previous_(backendOverride.exchange(static_cast<int>(checkedBackend(b)))) {}
ScopedBackend::~ScopedBackend() {
  backendOverride.store(previous_);
}

void recordLaunch(const char* name, double ms, double items) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  auto& t = r.stages[name];
  t.name = name;
  t.totalMs += ms;
  t.calls += 1;
  t.items += items;
}

void* allocate(size_t bytes) {
  if (bytes == 0) bytes = 1;
  // Managed memory whenever a device answers, so either backend can touch it.
  if (processBackend() == Backend::CUDA) return cudaAllocateManaged(bytes);
  void* p = std::aligned_alloc(64, (bytes + 63) / 64 * 64);
  if (!p)
    throw Error(ErrorKind::Failure,
                "out of memory allocating " + std::to_string(bytes >> 20) + " MiB");
  return p;
}

void deallocate(void* p) {
  if (!p) return;
  if (processBackend() == Backend::CUDA)
    cudaFreeManaged(p);
  else
    std::free(p);
}

}  // namespace exec
}  // namespace visopt
