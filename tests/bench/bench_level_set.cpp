// Himmler & Günther 2026, Table I, the context-surface columns, on the CPU: "SDF Opt." (one
// explicit Euler substep of the level-set PDE, Eq. 23) and "Redist." (one redistancing iteration,
// Eq. 18) on dense 64^3 / 128^3 / 256^3 grids in fp32 and fp16, reported in ns per voxel-iteration;
// and, in the same run, OpenVDB's LevelSetTracker renormalisation (first-order Godunov FIRST_BIAS,
// Euler TVD_RK1, one normalize() iteration) on the same sphere, for a narrow band (half-width
// 3 voxels) and for a band wide enough to cover the whole grid (clipped to it), in ns per active
// voxel-iteration and ms per iteration. See docs/level-set-benchmarks.md.
//
// Counters: ns_per_voxel (wall time / voxels of the grid or active voxels of the band),
// voxels (the count it divides by).
#include <benchmark/benchmark.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetTracker.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "optimize/level_set.h"
#include "optimize/narrow_band.h"
#include "sdf/fast_sweep.h"
#include "visopt/field.h"
#include "visopt/level_set.h"

namespace {

using visopt::Field3D;
using visopt::GridSpec;
using visopt::Precision;

// A sphere of radius n/4 at the centre of an n^3 grid of unit voxels.
float sphereAt(int n, int i, int j, int k) {
  const float c = 0.5f * float(n - 1);
  const float x = float(i) - c, y = float(j) - c, z = float(k) - c;
  return std::sqrt(x * x + y * y + z * z) - 0.25f * float(n);
}

struct DenseSetup {
  Field3D phi, phi0, ghat, out;
  DenseSetup(int n, Precision p) {
    GridSpec g;
    g.dims = glm::ivec3(n);
    phi = Field3D("phi", g, p);
    phi0 = Field3D("phi0", g, p);
    ghat = Field3D("ghat", g, p);
    out = Field3D("out", g, p);
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const size_t v = g.linearIndex(i, j, k);
          phi.set(v, sphereAt(n, i, j, k));
          phi0.set(v, sphereAt(n, i, j, k) - 0.5f);
          ghat.set(v, 0.5f + 0.4f * std::sin(0.1f * float(i)) * std::cos(0.13f * float(j)));
          out.set(v, 0.f);
        }
  }
};

Precision precisionOf(int64_t code) {
  return code == 16 ? Precision::FP16 : Precision::FP32;
}

void setCounters(benchmark::State& state, double voxels) {
  state.counters["voxels"] = voxels;
  state.counters["ns_per_voxel"] = benchmark::Counter(
      voxels * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// One level-set substep (the kernel of Eq. 23, its time step computed once outside).
void BM_SdfOpt(benchmark::State& state) {
  const int n = int(state.range(0));
  DenseSetup d(n, precisionOf(state.range(1)));
  visopt::LevelSetSettings s;
  const double dt = visopt::levelSetTimeStep(d.ghat, s);
  for (auto _ : state) {
    const double change = visopt::levelSetSubstep(d.phi, d.phi0, d.ghat, nullptr, s, dt, d.out);
    benchmark::DoNotOptimize(change);
  }
  setCounters(state, double(d.phi.size()));
}

// One redistancing iteration (second-order ENO by default; range(2) = 1 for first order, as
// OpenVDB's FIRST_BIAS).
void BM_Redist(benchmark::State& state) {
  const int n = int(state.range(0));
  DenseSetup d(n, precisionOf(state.range(1)));
  const int order = int(state.range(2));
  for (auto _ : state) {
    const double msc = visopt::redistanceIteration(d.phi, d.out, order);
    benchmark::DoNotOptimize(msc);
  }
  setCounters(state, double(d.phi.size()));
}

// OpenVDB: one renormalisation iteration of LevelSetTracker, FIRST_BIAS + TVD_RK1, on the same
// sphere; range(1) = 0: narrow band of half-width 3; 1: a band wide enough to cover the grid.
void BM_OpenVdbRenormalize(benchmark::State& state) {
  openvdb::initialize();
  const int n = int(state.range(0));
  const bool whole = state.range(1) != 0;
  const float c = 0.5f * float(n - 1);
  // Half-width in voxels: from the sphere (radius n/4) to the far corner of the grid.
  const float halfWidth = whole ? std::ceil(0.25f * float(n) + std::sqrt(3.f) * c) : 3.f;
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      0.25f * float(n), openvdb::Vec3f(c, c, c), 1.f, halfWidth);
  if (whole) grid->clip(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)));  // the grid
  using Tracker = openvdb::tools::LevelSetTracker<openvdb::FloatGrid>;
  Tracker tracker(*grid);
  tracker.setSpatialScheme(openvdb::math::FIRST_BIAS);
  tracker.setTemporalScheme(openvdb::math::TVD_RK1);
  tracker.setNormCount(1);
  for (auto _ : state) tracker.normalize();
  setCounters(state, double(grid->activeVoxelCount()));
}

// The band path as the optimiser runs it, per iteration: one level-set substep (Eq. 23) and one
// redistancing iteration (Eq. 18), each over the active bricks of a band of half-width
// range(2) voxels (LevelSetSettings::band). range(3) = 1: the band is kept between calls and
// moved with the surface (NarrowBand, as the optimiser does: the bricks' distances are read
// again over the band only); 0: each call finds it again by a read pass over phi and phi0 of
// the whole grid. ns_per_voxel divides by the band's voxels (bricks of 8^3 within the
// half-width of the surface, so more than OpenVDB's band of the same half-width).
void BM_BandStepRedist(benchmark::State& state) {
  const int n = int(state.range(0));
  DenseSetup d(n, precisionOf(state.range(1)));
  visopt::LevelSetSettings s;
  s.band = float(state.range(2));
  s.substeps = 1;
  s.semiImplicit = false;  // one explicit substep: OpenVDB's counterpart below is one too
  s.redistanceIterations = 1;
  const bool kept = state.range(3) != 0;
  visopt::Field3D scratch;
  visopt::NarrowBand band;
  int64_t bandVoxels = 0;
  for (auto _ : state) {
    visopt::NarrowBand* b = kept ? &band : nullptr;
    const visopt::LevelSetStepStats st =
        visopt::levelSetStep(d.phi, d.phi0, d.ghat, nullptr, s, scratch, b);
    const visopt::RedistanceStats rs = visopt::redistance(d.phi, s, scratch, &d.phi0, 0.f, b);
    bandVoxels = std::max(st.bandVoxels, rs.bandVoxels);
    benchmark::DoNotOptimize(rs.meanSquaredChange);
  }
  setCounters(state, double(bandVoxels > 0 ? bandVoxels : int64_t(d.phi.size())));
}

// The optimiser's level-set step per unit of flow time: one chunk of range(3) explicit
// substeps' time on the kept band (half-width 8), as range(2) = 0: that many explicit substeps of
// Eq. 23, 1: one semi-implicit step over the same time (kernels/implicit_diffusion.h). No
// redistancing. ns_per_voxel divides the chunk's time by the band's voxels.
void BM_BandChunk(benchmark::State& state) {
  const int n = int(state.range(0));
  DenseSetup d(n, precisionOf(state.range(1)));
  visopt::LevelSetSettings s;
  s.semiImplicit = state.range(2) != 0;
  s.substeps = int(state.range(3));
  visopt::Field3D scratch;
  visopt::NarrowBand band;
  int64_t bandVoxels = 0;
  for (auto _ : state) {
    const visopt::LevelSetStepStats st =
        visopt::levelSetStep(d.phi, d.phi0, d.ghat, nullptr, s, scratch, &band);
    bandVoxels = st.bandVoxels;
    benchmark::DoNotOptimize(st.maxChange);
  }
  setCounters(state, double(bandVoxels));
}

// OpenVDB's counterpart of BM_BandStepRedist: LevelSetFilter::meanCurvature(), one explicit
// step of mean-curvature flow followed by the tracker's renormalisation (one iteration,
// FIRST_BIAS + TVD_RK1) and band rebuild, on the same sphere with a band of half-width 3.
void BM_OpenVdbCurvatureStep(benchmark::State& state) {
  openvdb::initialize();
  const int n = int(state.range(0));
  const float c = 0.5f * float(n - 1);
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      0.25f * float(n), openvdb::Vec3f(c, c, c), 1.f, 3.f);
  openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*grid);
  filter.setSpatialScheme(openvdb::math::FIRST_BIAS);
  filter.setTemporalScheme(openvdb::math::TVD_RK1);
  filter.setNormCount(1);
  for (auto _ : state) filter.meanCurvature();
  setCounters(state, double(grid->activeVoxelCount()));
}

// The fast sweep that builds a base SDF from the voxels next to an isosurface (sdf/fast_sweep.h):
// a sphere of radius n/4, its band at the exact distances, every other voxel at +infinity, swept
// until a round changes nothing by more than 0.001 voxel. parallel = 1: rows of each
// anti-diagonal in parallel, only voxels next to a change (what sdfFromIsovalue runs);
// 0: the serial reference, every voxel of every sweep. Counter: ns per voxel of the grid.
void BM_FastSweep(benchmark::State& state) {
  const int n = int(state.range(0));
  const bool parallel = state.range(1) != 0;
  const size_t count = size_t(n) * size_t(n) * size_t(n);
  std::vector<float> start(count, std::numeric_limits<float>::infinity()), d(count);
  std::vector<uint8_t> fixed(count, 0);
  for (int k = 1; k + 1 < n; ++k)
    for (int j = 1; j + 1 < n; ++j)
      for (int i = 1; i + 1 < n; ++i) {
        const float c = sphereAt(n, i, j, k);
        const bool band =
            c * sphereAt(n, i - 1, j, k) <= 0.f || c * sphereAt(n, i + 1, j, k) <= 0.f ||
            c * sphereAt(n, i, j - 1, k) <= 0.f || c * sphereAt(n, i, j + 1, k) <= 0.f ||
            c * sphereAt(n, i, j, k - 1) <= 0.f || c * sphereAt(n, i, j, k + 1) <= 0.f;
        const size_t v = (size_t(k) * size_t(n) + size_t(j)) * size_t(n) + size_t(i);
        if (band) {
          fixed[v] = 1;
          start[v] = std::fabs(c);
        }
      }
  for (auto _ : state) {
    state.PauseTiming();
    d = start;
    state.ResumeTiming();
    if (parallel)
      visopt::fastSweep(d, fixed, glm::ivec3(n), glm::vec3(1.f), 1e-3f, 8);
    else
      visopt::fastSweepSerial(d, fixed, glm::ivec3(n), glm::vec3(1.f), 1e-3f, 8);
    benchmark::DoNotOptimize(d.data());
  }
  setCounters(state, double(count));
}

void denseArgs(benchmark::internal::Benchmark* b) {
  for (int n : {64, 128, 256})
    for (int p : {32, 16}) b->Args({n, p});
}
void redistArgs(benchmark::internal::Benchmark* b) {
  for (int n : {64, 128, 256})
    for (int p : {32, 16})
      for (int order : {2, 1}) b->Args({n, p, order});
}
void vdbArgs(benchmark::internal::Benchmark* b) {
  for (int n : {64, 128, 256})
    for (int whole : {0, 1}) b->Args({n, whole});
}

BENCHMARK(BM_SdfOpt)
    ->Apply(denseArgs)
    ->ArgNames({"n", "fp"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Redist)
    ->Apply(redistArgs)
    ->ArgNames({"n", "fp", "order"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
void bandArgs(benchmark::internal::Benchmark* b) {
  for (int n : {128, 256})
    for (int p : {32, 16})
      for (int halfWidth : {3, 8})
        for (int kept : {1, 0}) b->Args({n, p, halfWidth, kept});
}
BENCHMARK(BM_BandStepRedist)
    ->Apply(bandArgs)
    ->ArgNames({"n", "fp", "band", "kept"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
void chunkArgs(benchmark::internal::Benchmark* b) {
  for (int n : {128, 256})
    for (int p : {32, 16})
      for (int semi : {0, 1})
        for (int substeps : {16, 64}) b->Args({n, p, semi, substeps});
}
BENCHMARK(BM_BandChunk)
    ->Apply(chunkArgs)
    ->ArgNames({"n", "fp", "semi", "substeps"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FastSweep)
    ->ArgsProduct({{128, 256}, {1, 0}})
    ->ArgNames({"n", "parallel"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_OpenVdbCurvatureStep)
    ->Arg(128)
    ->Arg(256)
    ->ArgNames({"n"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_OpenVdbRenormalize)
    ->Apply(vdbArgs)
    ->ArgNames({"n", "whole"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
