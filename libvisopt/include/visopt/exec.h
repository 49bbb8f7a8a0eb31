// What the execution layer reports to users: which backend runs the kernels, and the time spent
// in each named launch. Every kernel launch has a name, so per-stage timings come for free.
#pragma once

#include <string>
#include <vector>

namespace visopt {

enum class Backend { CPU, CUDA };

// Decided once per process: CUDA when the build has it, a device answers, and the environment
// variable VISOPT_BACKEND is not "cpu"; otherwise the CPU (oneTBB).
Backend activeBackend();
std::string backendDescription();  // e.g. "CPU (oneTBB, 2 threads)"
// True when the CUDA backend was compiled in (whether or not a device answers).
bool cudaCompiledIn();

struct StageTiming {
  std::string name;
  double totalMs = 0.0;
  long long calls = 0;
  double items = 0.0;  // work items launched (voxels, rays, samples...), summed over calls
};

// Timings accumulated since the last reset, sorted by name.
std::vector<StageTiming> stageTimings();
void resetStageTimings();

}  // namespace visopt
