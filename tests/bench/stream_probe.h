// A STREAM-like memory-bandwidth probe (McCalpin's copy and triad kernels) on the threads
// oneTBB uses, so the optimisation stages can be reported as a fraction of what the memory
// system delivers to the same threads in the same run.
#pragma once

#include <cstddef>

namespace visopt::bench {

struct StreamResult {
  size_t arrayBytes = 0;  // bytes of each of the three arrays
  int threads = 0;        // oneTBB's default concurrency
  double copyGBs = 0.0;   // best of the repeats, c[i] = b[i]: 16 bytes per element
  double triadGBs = 0.0;  // best of the repeats, a[i] = b[i] + s * c[i]: 24 bytes per element
  double cpuShare = 0.0;  // process CPU seconds / (wall seconds * threads) over the timed loops
};

// Runs copy and triad on three arrays of doubles of about `arrayBytes` each, `repeats` times
// each, and keeps the best rate (STREAM's convention). Bytes are counted as STREAM counts them:
// the explicit loads and stores, without the write-allocate reads of the stored lines. The
// arrays are first touched by the threads that later stream them (static partitioning).
StreamResult runStreamProbe(size_t arrayBytes, int repeats);

// The last-level cache size from sysfs (the largest cache index of CPU 0), or 0 when unknown.
size_t lastLevelCacheBytes();

}  // namespace visopt::bench
