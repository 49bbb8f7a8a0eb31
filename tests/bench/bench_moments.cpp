// Moment images (Rapp et al. 2022; docs/moment-images.md): generation (the march with moment
// accumulation, then §3.5's count) and rendering with the bounded MESE and the Fourier series,
// against the direct emission-absorption march of the volume with the same transfer function and
// step, per scene and image size; the same-run STREAM probe gives the memory system's pace.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <string>

#include "stream_counters.h"
#include "visopt/exec.h"
#include "visopt/moment_image.h"
#include "visopt/scenes.h"

namespace {

using namespace visopt;

struct Case {
  std::string scene;
  int resolution;
};

const BuiltinScene& sceneOf(const Case& c) {
  static std::map<std::string, BuiltinScene> cache;
  auto it = cache.find(c.scene);
  if (it == cache.end())
    it = cache.emplace(c.scene, makeBuiltinScene(c.scene, c.resolution, Precision::FP32)).first;
  return it->second;
}

Camera viewOf(const BuiltinScene& s) {
  return Camera::orbitBounds(s.volume.grid().worldBounds(), s.azimuthDeg, s.elevationDeg,
                             s.distanceInRadii);
}

void generate(benchmark::State& state, const Case& c, int size) {
  const BuiltinScene& s = sceneOf(c);
  MomentImageSettings settings;
  settings.width = settings.height = size;
  MomentGenerationStats stats;
  double march = 0.0, count = 0.0;
  int64_t samples = 0;
  for (auto _ : state) {
    const MomentImage image = generateMomentImage(s.volume, viewOf(s), settings, &stats);
    benchmark::DoNotOptimize(image.moments.data());
    march += stats.marchMs;
    count += stats.countMs;
    samples += stats.samples;
    state.counters["moments_per_hit_pixel"] = stats.meanMoments;
  }
  const double n = double(state.iterations());
  state.counters["march_ms"] = march / n;
  state.counters["count_ms"] = count / n;
  state.counters["ns_per_sample_march"] = march * 1e6 / double(samples);
}

// What a rank of visopt-moments-mpi runs (docs/moment-images.md, "Distributed generation"):
// the volume cut into `slabs` slabs of whole slices, each copied out with its halo and added to
// the partials, which are then finished. Against generate/ in the same run, the cost of cutting.
void generateInSlabs(benchmark::State& state, const Case& c, int size, int slabs) {
  const BuiltinScene& s = sceneOf(c);
  const GridSpec& grid = s.volume.grid();
  MomentImageSettings settings;
  settings.width = settings.height = size;
  const int nz = grid.dims.z, halo = momentSlabHalo(settings);
  const size_t plane = size_t(grid.dims.x) * size_t(grid.dims.y);
  double march = 0.0;
  for (auto _ : state) {
    MomentPartials partials = emptyMomentPartials(settings);
    for (int k = 0; k < slabs; ++k) {
      const int own0 = nz * k / slabs, own1 = nz * (k + 1) / slabs;
      const int z0 = std::max(0, own0 - halo), z1 = std::min(nz, own1 + halo);
      GridSpec g = grid;
      g.dims.z = z1 - z0;
      Field3D slab("slab", g, Precision::FP32);
      for (size_t i = 0; i < slab.size(); ++i)
        slab.set(i, s.volume.normalized.get(size_t(z0) * plane + i));
      addMomentSlab(partials, slab, z0, own0, own1, grid, viewOf(s), settings, &march);
    }
    const MomentImage image = finishMomentImage(partials, grid, viewOf(s), settings,
                                                s.volume.valueMin, s.volume.valueMax);
    benchmark::DoNotOptimize(image.moments.data());
  }
  state.counters["march_ms"] = march / double(state.iterations());
}

void render(benchmark::State& state, const Case& c, int size, MomentReconstruction r,
            bool perSample = false) {
  const BuiltinScene& s = sceneOf(c);
  MomentImageSettings settings;
  settings.width = settings.height = size;
  const MomentImage image = generateMomentImage(s.volume, viewOf(s), settings);
  MomentRenderSettings rs;
  rs.reconstruction = r;
  rs.perSampleReference = perSample;
  for (auto _ : state) benchmark::DoNotOptimize(renderMomentImage(image, s.transferFunction, rs));
  state.counters["ns_per_pixel"] =
      benchmark::Counter(double(image.pixelCount()), benchmark::Counter::kIsIterationInvariantRate |
                                                         benchmark::Counter::kInvert);
  visopt::bench::setTriadFraction(state, "moment_bytes_of_triad",
                                  double(image.moments.size()) * 4.0);
}

void direct(benchmark::State& state, const Case& c, int size) {
  const BuiltinScene& s = sceneOf(c);
  const MomentRenderSettings rs;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        renderVolumeEmissionAbsorption(s.volume, viewOf(s), size, size, s.transferFunction, rs));
  state.counters["ns_per_pixel"] =
      benchmark::Counter(double(size) * size, benchmark::Counter::kIsIterationInvariantRate |
                                                  benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const Case cases[] = {{"marschner-lobb", 64}, {"shepp-logan", 128}};
  for (const Case& c : cases)
    for (int size : {256, 512}) {
      const std::string name = c.scene + "/" + std::to_string(size);
      benchmark::RegisterBenchmark(("generate/" + name).c_str(),
                                   [=](benchmark::State& st) { generate(st, c, size); })
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("generate-in-8-slabs/" + name).c_str(),
                                   [=](benchmark::State& st) { generateInSlabs(st, c, size, 8); })
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      for (MomentReconstruction r :
           {MomentReconstruction::BoundedMese, MomentReconstruction::Fourier})
        benchmark::RegisterBenchmark(("render-" + std::string(toString(r)) + "/" + name).c_str(),
                                     [=](benchmark::State& st) { render(st, c, size, r); })
            ->UseRealTime()
            ->Unit(benchmark::kMillisecond);
      // The renderer's per-sample reference, for the lanes path's speed-up in the same run.
      benchmark::RegisterBenchmark(("render-mese-per-sample/" + name).c_str(),
                                   [=](benchmark::State& st) {
                                     render(st, c, size, MomentReconstruction::BoundedMese, true);
                                   })
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("render-direct/" + name).c_str(),
                                   [=](benchmark::State& st) { direct(st, c, size); })
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
    }
  return visopt::bench::runWithSameRunStream();
}
