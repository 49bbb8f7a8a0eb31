// The grid updates (Himmler & Günther 2026, Eqs. 10-13: the visibility scan of one frustum grid)
// kernel by kernel, on the same fields in the same run, against a STREAM-like probe run in the same
// process: the reference per-ray scan (kernels/visibility_scan.h), the fast per-ray scan
// (kernels/visibility_scan_fast.h, buffered: what a one-thread-per-ray backend runs) and the
// tiled scan the CPU backend runs (host/visibility_scan_tiles.h), and the tiled scan with the
// empty-space skip grid the optimiser builds every iteration (kernels/scan_skip.h; its build is
// timed with it). All use the tiled layout of the frustum fields (core/frustum_field.h). mu is
// nowhere zero in this scene, so the skip grid can only skip behind the surface: real scans with
// air around them skip more (see docs/optimization-benchmarks.md for the Cranium CT).
//
// One benchmark per (kernel, volume N^3, view frustum F^2 or the light grid, precision, context
// surface or not). The scene is synthetic and the same for every case: mu a smooth blob
// (extinction up to ~8 per unit length in a unit box), g = 1 in a ball of radius 0.2 (0 outside),
// and, with a surface, a sphere of radius 0.3 around it (its SDF) that blocks the rays that reach
// it, as a skin hides a skull. View: 30 degrees at distance 3, depth cells one per half voxel;
// light: ExtinctionSettings' default 128^2 rays from a point light above the volume.
//
// Counters: ns_cell_core (wall ns x threads per frustum cell), GBs (minimum bytes / time) and
// frac (that / the probe's triad): minimum bytes = read mu and g once (2 V b), write d once and,
// with a surface, the running maximum of g behind each cell (F b each); b = 2 or 4.
// Environment: VISOPT_BENCH_FULL=1 adds the 256^3 volume with the 512^2 frustum.
//
// The extinction step (Himmler & Günther 2026, Eqs. 10-14: gather d_V from the view grid, AdEMAMix
// step, projection) in the same run, per voxel: the reference ExtinctionStep (one voxel per launch
// item, what CUDA runs) and the CPU backend's rows (host/extinction_step_rows.h). Counters:
// ns_voxel_core, GBs and frac with minimum bytes = read mu, mu_bar, m1, m2, rms and write mu, m1,
// m2, rms once (9 V b) plus the view grid's cells read once (min(F, 8 V) b).
#include <benchmark/benchmark.h>

#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "host/extinction_step_rows.h"
#include "host/visibility_scan_tiles.h"
#include "kernels/extinction_step.h"
#include "kernels/visibility_scan_fast.h"
#include "optimize/scan_skip_grid.h"
#include "stream_counters.h"
#include "visopt/camera.h"
#include "visopt/exec.h"
#include "visopt/field.h"
#include "visopt/frustum.h"

namespace {

using visopt::Precision;

enum class Kernel { Reference, PerRay, Tiled, TiledSkip };

struct Case {
  Kernel kernel;
  int volume;
  int frustum;  // view rays per side; 0: the light grid
  Precision precision;
  bool surface;
};

std::string nameOf(const Case& c) {
  const char* kernel = c.kernel == Kernel::Tiled       ? "tiled"
                       : c.kernel == Kernel::TiledSkip ? "tiled+skip"
                       : c.kernel == Kernel::PerRay    ? "per-ray"
                                                       : "reference";
  return std::string("scan/") + kernel + "/vol:" + std::to_string(c.volume) +
         (c.frustum > 0 ? "/view:" + std::to_string(c.frustum) : std::string("/light:128")) + "/" +
         visopt::toString(c.precision) + (c.surface ? "/surface" : "/no-surface");
}

struct Fields {
  visopt::GridSpec grid;
  visopt::Field3D mu, g, phi;
};

// Cached per (volume, precision): building the fields is not what is measured.
Fields& fieldsFor(int n, Precision p) {
  static std::vector<std::unique_ptr<Fields>> cache;
  static std::vector<std::pair<int, Precision>> keys;
  for (size_t i = 0; i < keys.size(); ++i)
    if (keys[i].first == n && keys[i].second == p) return *cache[i];
  if (cache.size() >= 2) {  // keep at most two sets alive (256^3 fp32: 3 x 64 MiB)
    cache.erase(cache.begin());
    keys.erase(keys.begin());
  }
  auto f = std::make_unique<Fields>();
  f->grid.dims = glm::ivec3(n);
  f->grid.spacing = glm::vec3(1.f / float(n));
  f->grid.origin = glm::vec3(-0.5f + 0.5f / float(n));
  f->mu = visopt::Field3D("mu", f->grid, p);
  f->g = visopt::Field3D("g", f->grid, p);
  f->phi = visopt::Field3D("phi", f->grid, p);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const size_t v = (size_t(k) * n + j) * n + i;
        const glm::vec3 x = f->grid.origin + glm::vec3(i, j, k) * f->grid.spacing;
        const float r = glm::length(x);
        f->mu.set(v, 8.f * std::exp(-6.f * r * r) * (0.6f + 0.4f * std::cos(20.f * x.x)));
        f->g.set(v, r < 0.2f ? 1.f : 0.f);
        f->phi.set(v, r - 0.3f);
      }
  keys.emplace_back(n, p);
  cache.push_back(std::move(f));
  return *cache.back();
}

visopt::FrustumGrid frustumFor(const Case& c, const visopt::GridSpec& grid) {
  const visopt::Bounds bounds = grid.worldBounds();
  if (c.frustum == 0) {
    visopt::PointLight light;
    light.position = glm::vec3(-1.5f, -2.f, 2.5f);
    return visopt::FrustumGrid::forLight(light, bounds, glm::ivec3(128, 128, 0), grid.minSpacing());
  }
  visopt::Camera cam;
  cam.eye = glm::vec3(0.8f, -2.8f, 0.6f);
  return visopt::FrustumGrid::forCamera(cam, c.frustum, c.frustum, bounds, 0, grid.minSpacing());
}

// Per iteration: ns per item and core (`perItem`, e.g. "ns_cell_core"), the minimum bytes as
// GB/s and as a fraction of the probe's triad.
void setRateCounters(benchmark::State& state, const char* perItem, double items, double bytes) {
  state.counters[perItem] = benchmark::Counter(
      items / (1e9 * tbb::info::default_concurrency()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["GBs"] =
      benchmark::Counter(bytes * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  visopt::bench::setTriadFraction(state, "frac", bytes);
}

template <class K>
visopt::ScanSums scan(const K& kernel, int64_t rays) {
  return visopt::exec::reduce(
      "bench scan", rays, visopt::ScanSums{}, kernel,
      [](const visopt::ScanSums& a, const visopt::ScanSums& b) { return a + b; });
}

// The scan of `frustum` over the case's fields into `out` (a frustum field in tiled storage).
visopt::VisibilityScan scanOf(const Fields& f, const visopt::FrustumGrid& frustum,
                              visopt::Field3D& out) {
  visopt::VisibilityScan s;
  s.frustum = visopt::FrustumMap(frustum);
  s.volume = visopt::GridMap(f.grid);
  s.mu = visopt::FieldView(f.mu);
  s.importance = visopt::FieldView(f.g);
  s.out = visopt::FrustumFieldView(out, frustum.dims);
  return s;
}

visopt::Field3D frustumField(const char* name, const visopt::FrustumGrid& frustum, Precision p) {
  visopt::GridSpec fg;
  fg.dims = visopt::frustumStorageDims(frustum.dims);
  return visopt::Field3D(name, fg, p);
}

void runCase(benchmark::State& state, const Case& c) {
  Fields& f = fieldsFor(c.volume, c.precision);
  const visopt::FrustumGrid frustum = frustumFor(c, f.grid);
  visopt::Field3D out = frustumField("d", frustum, c.precision);
  std::optional<visopt::Field3D> behind;
  visopt::VisibilityScan s = scanOf(f, frustum, out);
  if (c.surface) {
    s.surfaces.count = 1;
    s.surfaces.phi[0] = visopt::FieldView(f.phi);
    behind.emplace(frustumField("behind max", frustum, c.precision));
    s.behindMax = visopt::FrustumFieldView(*behind, frustum.dims);
  }
  const int64_t rays = int64_t(frustum.dims.x) * frustum.dims.y;
  visopt::ScanSkipStorage skip;
  auto once = [&] {
    if (c.kernel == Kernel::Reference) return scan(s, rays);
    if (c.kernel == Kernel::Tiled) return visopt::scanTilesOnHost("bench scan", s);
    if (c.kernel == Kernel::TiledSkip) {  // the skip grid is rebuilt each time, as per iteration
      visopt::buildScanSkipGrid(f.mu, f.g, s.surfaces, skip);
      s.skip = skip.grid;
      return visopt::scanTilesOnHost("bench scan", s);
    }
    return scan(visopt::FastVisibilityScan<visopt::kScanBufferCells>{s}, rays);
  };
  visopt::ScanSums sums = once();  // first touch of the frustum fields
  for (auto _ : state) {
    sums = once();
    benchmark::DoNotOptimize(sums);
  }
  const double cells = double(rays) * frustum.dims.z;
  const double b = double(visopt::bytesPerValue(c.precision));
  const double bytes = 2.0 * double(f.grid.voxelCount()) * b + cells * b * (c.surface ? 2 : 1);
  state.counters["cells_M"] = cells * 1e-6;
  setRateCounters(state, "ns_cell_core", cells, bytes);
  state.counters["V"] = sums.gMu > 0 ? sums.gMuT / sums.gMu : 0.0;
}

// The extinction step on the view grid's d from the tiled scan (mu_bar: the stored mu).
void runStepCase(benchmark::State& state, int n, int frustumSide, Precision p, bool rows) {
  Fields& f = fieldsFor(n, p);
  const Case scanCase{Kernel::Tiled, n, frustumSide, p, false};
  const visopt::FrustumGrid frustum = frustumFor(scanCase, f.grid);
  visopt::Field3D d = frustumField("d", frustum, p);
  visopt::scanTilesOnHost("bench scan", scanOf(f, frustum, d));
  visopt::Field3D mu("mu", f.grid, p), m1("m1", f.grid, p), m2("m2", f.grid, p),
      rms("rms", f.grid, p);
  for (size_t v = 0; v < mu.size(); ++v) {
    mu.set(v, f.mu.get(v));
    m1.set(v, 0.f);
    m2.set(v, 0.f);
    rms.set(v, 0.f);
  }
  visopt::ExtinctionStep step;
  step.gradient.volume = visopt::GridMap(f.grid);
  step.gradient.mu = visopt::FieldView(mu);
  step.gradient.base.field = visopt::FieldView(f.mu);
  step.gradient.rho = 1.f / 8.f;
  step.gradient.q = 40.f;
  step.gradient.view = visopt::FrustumMap(frustum);
  step.gradient.dView = visopt::FrustumFieldView(d, frustum.dims);
  step.state.m1 = visopt::FieldView(m1);
  step.state.m2 = visopt::FieldView(m2);
  step.state.rms = visopt::FieldView(rms);
  step.coefficients.lr = 0.4f;
  step.coefficients.alpha = 5.f;
  step.muMax = 8.f;
  const int64_t voxels = int64_t(f.grid.voxelCount());
  auto once = [&] {
    if (rows) return visopt::extinctionStepOnHost("bench step", step);
    return visopt::exec::reduce(
        "bench step", voxels, visopt::StepSums{}, step,
        [](const visopt::StepSums& a, const visopt::StepSums& b) { return a + b; });
  };
  for (auto _ : state) benchmark::DoNotOptimize(once());
  const double b = double(visopt::bytesPerValue(p));
  const double cells = double(frustum.dims.x) * frustum.dims.y * frustum.dims.z;
  const double bytes = 9.0 * double(voxels) * b + std::min(cells, 8.0 * double(voxels)) * b;
  setRateCounters(state, "ns_voxel_core", double(voxels), bytes);
}

std::vector<Case> cases() {
  const char* env = std::getenv("VISOPT_BENCH_FULL");
  const bool full = env && *env && std::string(env) != "0";
  std::vector<Case> out;
  for (int volume : {64, 128, 256})
    for (int frustum : {256, 512, 0})
      for (Precision p : {Precision::FP32, Precision::FP16})
        for (bool surface : {false, true})
          for (Kernel k : {Kernel::Reference, Kernel::PerRay, Kernel::Tiled, Kernel::TiledSkip})
            if (full || volume * frustum < 256 * 512)
              out.push_back({k, volume, frustum, p, surface});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (const Case& c : cases())
    benchmark::RegisterBenchmark(nameOf(c).c_str(), [c](benchmark::State& st) { runCase(st, c); })
        ->UseRealTime()
        ->MinTime(0.5)
        ->Unit(benchmark::kMillisecond);
  for (int n : {64, 128, 256})
    for (Precision p : {Precision::FP32, Precision::FP16})
      for (bool rows : {false, true}) {
        const std::string name = std::string("extinction-step/") + (rows ? "rows" : "reference") +
                                 "/vol:" + std::to_string(n) + "/view:256/" + visopt::toString(p);
        benchmark::RegisterBenchmark(
            name.c_str(), [=](benchmark::State& st) { runStepCase(st, n, 256, p, rows); })
            ->UseRealTime()
            ->MinTime(0.5)
            ->Unit(benchmark::kMillisecond);
      }
  return visopt::bench::runWithSameRunStream(/*probeAfter=*/true);
}
