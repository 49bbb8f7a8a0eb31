// Following a dragged camera (Engine::followCamera, optimize/camera_follow.cpp): the coarse-grid
// correction at 128³ (the fast row path against the per-voxel reference, same fields, same run)
// and a whole follow call of 4 coarse iterations on the default scene after a 3° turn, the work
// the workstation does after each preview while the user drags (docs/optimization-benchmarks.md).
//
//   bench_follow --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "optimize/multigrid_transfer.h"
#include "stream_counters.h"
#include "visopt/engine.h"
#include "visopt/scenes.h"

namespace {

using namespace visopt;

struct Correction {
  GridSpec fine, coarse;
  Field3D now, before, target;
  Correction()
      : fine(makeFine()),
        coarse(levelGrid(fine, 4)),
        now("now", coarse, Precision::FP32),
        before("before", coarse, Precision::FP32),
        target("mu", fine, Precision::FP32) {
    // A change in a third of the coarse rows, as a turned camera makes it.
    for (size_t c = 0; c < now.size(); ++c) {
      before.set(c, 0.5f);
      now.set(c, (c / size_t(coarse.dims.x)) % 3 == 0 ? 0.5f + 1e-3f * float(c % 7) : 0.5f);
    }
    for (size_t v = 0; v < target.size(); ++v) target.set(v, 0.5f);
  }
  static GridSpec makeFine() {
    GridSpec g;
    g.dims = glm::ivec3(128);
    return g;
  }
};

void BM_CoarseGridCorrection(benchmark::State& state) {
  static Correction c;
  const bool fast = state.range(0) == 1;
  for (auto _ : state) {
    const double most =
        fast ? prolongChange(c.now, c.before, GridMap(c.coarse), c.target, 0.f, 1.f)
             : prolongChangeReference(c.now, c.before, GridMap(c.coarse), c.target, 0.f, 1.f);
    benchmark::DoNotOptimize(most);
  }
  state.SetLabel(fast ? "fast rows" : "reference");
  state.counters["ns/fine voxel"] = benchmark::Counter(
      double(c.target.size()) * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  // As if every fine voxel were read and written once (fp32; the coarse fields are cache-sized):
  // an upper bound on the bytes, since the fast path skips rows without change.
  bench::setTriadFraction(state, "frac_triad_whole_field", double(c.target.size()) * 8.0);
}
BENCHMARK(BM_CoarseGridCorrection)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_FollowCall(benchmark::State& state) {
  static std::unique_ptr<Engine> engine = [] {
    auto e = std::make_unique<Engine>();
    e->loadBuiltinScene(defaultSceneName(), 128);
    e->setViewportSize(256, 256);
    e->optimize();
    return e;
  }();
  float azimuth = 0.f;
  for (auto _ : state) {
    state.PauseTiming();
    azimuth += 3.f;
    engine->orbitCamera(azimuth, 10.f, 2.6f);
    state.ResumeTiming();
    benchmark::DoNotOptimize(engine->followCamera(4));
  }
}
BENCHMARK(BM_FollowCall)->Unit(benchmark::kMillisecond)->Iterations(30);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  bench::probeSameRunStream();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
