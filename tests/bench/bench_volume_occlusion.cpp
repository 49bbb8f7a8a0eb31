// The volume's ambient occlusion field (kernels/volume_occlusion.h, render/volume_occlusion.cpp;
// Himmler & Günther 2026, R4): its cost per voxel on the built-in default scene, per volume size
// and precision, against a STREAM-like probe run in the same process. The Engine computes the
// field once per change of mu, the surfaces or the settings it reads (a full frame after an
// optimisation step) and keeps it across frames; this is that recomputation.
//
// Counters: ns_voxel_core (wall ns x threads per voxel), GBs (minimum bytes / time) and frac
// (that / the probe's triad). Minimum bytes per voxel: read the scalars (b) and, optimised, the
// change (b); write mu (4); per axis write the prefix (4) and read mu and the prefix back (8); the
// running sum written and read (8 per axis but the last) and the field written (b):
// 2 b + 4 + 3 x 12 + 16 + b = 3 b + 56, b = 2 or 4.
#include <benchmark/benchmark.h>

#include <tbb/info.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "core/device_buffer.h"
#include "render/renderer.h"
#include "stream_counters.h"
#include "visopt/exec.h"
#include "visopt/scenes.h"

namespace {

using visopt::Precision;

void runCase(benchmark::State& state, int n, Precision precision) {
  visopt::BuiltinScene built = visopt::makeBuiltinScene("shepp-logan", n, precision);
  const visopt::Volume& volume = built.volume;
  const visopt::TransferTable baked = built.transferFunction.bake(volume.valueMin, volume.valueMax,
                                                                  volume.grid().minSpacing(), 1024);
  visopt::DeviceBuffer<glm::vec4> table(baked.albedoExtinction.size());
  for (size_t i = 0; i < table.size(); ++i) table[i] = baked.albedoExtinction[i];
  // An optimised mu: a change field of the volume's size (its values do not change the cost).
  visopt::Field3D change("change", volume.grid(), precision);
  change.fill(0.f);
  visopt::RenderScene scene;
  scene.volume = &volume;
  scene.transfer = &table;
  scene.extinctionChange = &change;
  visopt::Field3D out("occlusion", volume.grid(), precision);
  const float radius = 6.f * volume.grid().minSpacing();  // RenderSettings' default
  for (auto _ : state) {
    visopt::computeVolumeOcclusion(scene, visopt::RenderMethod::Optimized, 0.3f, radius, out);
    benchmark::DoNotOptimize(out.raw());
  }
  const double voxels = double(volume.normalized.size());
  const double b = precision == Precision::FP16 ? 2.0 : 4.0;
  state.counters["ns_voxel_core"] = benchmark::Counter(
      voxels / (1e9 * tbb::info::default_concurrency()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  const double bytes = voxels * (3.0 * b + 56.0);
  state.counters["GBs"] =
      benchmark::Counter(bytes * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  visopt::bench::setTriadFraction(state, "frac", bytes);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (int n : {64, 128, 256})
    for (Precision p : {Precision::FP32, Precision::FP16}) {
      const std::string name =
          "volume-occlusion/vol:" + std::to_string(n) + "/" + visopt::toString(p);
      benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) { runCase(st, n, p); })
          ->UseRealTime()
          ->MinTime(0.5)
          ->Unit(benchmark::kMillisecond);
    }
  return visopt::bench::runWithSameRunStream();
}
