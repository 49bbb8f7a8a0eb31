#include "stream_probe.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

#include <time.h>
#include <unistd.h>

namespace visopt::bench {

namespace {

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Static partitioning, so every pass gives each thread the same chunks it first touched.
template <class F>
void forEachChunk(size_t n, const F& f) {
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, n, 1 << 16),
      [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); },
      tbb::static_partitioner());
}

}  // namespace

size_t lastLevelCacheBytes() {
  for (int name : {_SC_LEVEL3_CACHE_SIZE, _SC_LEVEL2_CACHE_SIZE}) {
    const long bytes = sysconf(name);
    if (bytes > 0) return static_cast<size_t>(bytes);
  }
  return 0;
}

StreamResult runStreamProbe(size_t arrayBytes, int repeats) {
  using Clock = std::chrono::steady_clock;
  const size_t n = std::max<size_t>(arrayBytes / sizeof(double), 1 << 16);
  std::unique_ptr<double[]> a(new double[n]), b(new double[n]), c(new double[n]);
  double* pa = a.get();
  double* pb = b.get();
  double* pc = c.get();
  forEachChunk(n, [=](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) {
      pa[i] = 0.0;
      pb[i] = 2.0;
      pc[i] = 0.0;
    }
  });

  StreamResult result;
  result.arrayBytes = n * sizeof(double);
  result.threads = tbb::info::default_concurrency();
  double wall = 0.0, cpu = 0.0;
  auto timed = [&](const auto& kernel) {
    const double cpu0 = processCpuSeconds();
    const auto t0 = Clock::now();
    kernel();
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    wall += seconds;
    cpu += processCpuSeconds() - cpu0;
    return seconds;
  };
  const double scalar = 3.0;
  double bestCopy = 1e30, bestTriad = 1e30;
  auto copy = [=] {
    forEachChunk(n, [=](size_t lo, size_t hi) {
      for (size_t i = lo; i < hi; ++i) pc[i] = pb[i];
    });
  };
  auto triad = [=] {
    forEachChunk(n, [=](size_t lo, size_t hi) {
      for (size_t i = lo; i < hi; ++i) pa[i] = pb[i] + scalar * pc[i];
    });
  };
  for (int rep = 0; rep < std::max(repeats, 1); ++rep) {
    bestCopy = std::min(bestCopy, timed(copy));
    bestTriad = std::min(bestTriad, timed(triad));
  }
  // Checks that the kernels ran (and keeps the compiler from dropping them): every copy leaves
  // c = b = 2 and every triad a = 2 + 3 * 2 = 8.
  if (pa[n / 2] != 8.0 || pc[n - 1] != 2.0) std::fprintf(stderr, "stream probe: wrong result\n");
  const double bytes = static_cast<double>(n) * sizeof(double);
  result.copyGBs = 2.0 * bytes / bestCopy * 1e-9;
  result.triadGBs = 3.0 * bytes / bestTriad * 1e-9;
  result.cpuShare = wall > 0.0 ? cpu / (wall * result.threads) : 0.0;
  return result;
}

}  // namespace visopt::bench
