// The STREAM probe of this benchmark process, and a Google Benchmark counter that reports a
// case's bytes per iteration as a fraction of the probe's triad rate (the benchmarks that compare
// themselves with the memory system in the same run share these).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <string>

#include <benchmark/benchmark.h>

#include "stream_probe.h"
#include "visopt/exec.h"

namespace visopt::bench {

// Set once by the benchmark's main (runStreamProbe), read by the cases.
inline StreamResult& sameRunStream() {
  static StreamResult s;
  return s;
}

// Runs the probe on arrays of twice the last-level cache (256 MiB to 1 GiB each), keeps it as
// sameRunStream() and adds its rates to the benchmark's context; returns the array size, for a
// second probe after the cases.
inline size_t probeSameRunStream() {
  const size_t arrayBytes =
      std::clamp<size_t>(2 * lastLevelCacheBytes(), size_t(256) << 20, size_t(1) << 30);
  sameRunStream() = runStreamProbe(arrayBytes, 5);
  benchmark::AddCustomContext("stream_triad_GBs", std::to_string(sameRunStream().triadGBs));
  benchmark::AddCustomContext("stream_copy_GBs", std::to_string(sameRunStream().copyGBs));
  return arrayBytes;
}

// counters[name] = bytes moved per iteration / triad bandwidth, as a rate: the fraction of the
// probe's floor the case reaches (nothing when the probe has not run).
inline void setTriadFraction(benchmark::State& state, const std::string& name,
                             double bytesPerIteration) {
  if (sameRunStream().triadGBs > 0)
    state.counters[name] = benchmark::Counter(bytesPerIteration * 1e-9 / sameRunStream().triadGBs,
                                              benchmark::Counter::kIsIterationInvariantRate);
}

// The tail of a benchmark main: the same-run STREAM probe and the backend in the context, the
// registered cases, and with probeAfter a second probe whose rates are printed beside the first
// (a drop says the cases ran on a machine that got busier). Returns main's exit status.
inline int runWithSameRunStream(bool probeAfter = false) {
  const size_t arrayBytes = probeSameRunStream();
  benchmark::AddCustomContext("backend", backendDescription());
  benchmark::RunSpecifiedBenchmarks();
  if (probeAfter) {
    const StreamResult after = runStreamProbe(arrayBytes, 5);
    std::printf("STREAM triad before %.2f GB/s, after %.2f GB/s (copy %.2f / %.2f)\n",
                sameRunStream().triadGBs, after.triadGBs, sameRunStream().copyGBs, after.copyGBs);
  }
  benchmark::Shutdown();
  return 0;
}

}  // namespace visopt::bench
