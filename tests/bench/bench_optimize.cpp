// Himmler & Günther 2026, Table I on the CPU: the two stages of one extinction-optimisation
// iteration, "grid updates" (the visibility scans of the view and light frustum grids) and
// "extinction step" (gather, AdEMAMix step, projection), in ms per iteration at every level of the
// coarse-to-fine multigrid, for fp32 and fp16 storage, built-in scenes at 64^3..256^3 and
// 256^2 / 512^2 view frustum grids; plus the memory of every field (the engine's ledger) and
// each stage's achieved memory bandwidth as a fraction of a STREAM probe run in the same process.
//
// One benchmark per (scene, volume, frustum, precision, light term) runs Engine::optimize() once
// with kLevels levels and a fixed number of iterations per level (tolerance 0, so no level ends
// early). The first iteration of each level is a warm-up (it allocates and first-touches the
// optimiser state and the frustum fields) and is left out; the others give, per level, the
// median of IterationStats::gridUpdatesMs and ::extinctionStepMs, the view and light scans
// separately (exec::stageTimings), and the CPU share. The time Google Benchmark reports is the
// finest level's median (grid updates + extinction step) per iteration.
//
// Counters (per level l = 0 coarsest .. 2 finest):
//   Ll_grid_ms, Ll_step_ms    median ms per iteration of the two stages
//   Ll_grid_frac, Ll_step_frac achieved bandwidth (minimum byte model, see below) / STREAM triad
//   Ll_cpu                    process CPU seconds / (wall seconds * threads) over the iterations
//   mem_MiB                   the ledger's total at the finest level
//
// Byte model (bytes a stage must move at least; b = 2 (fp16) or 4 (fp32) bytes per value,
// V voxels of the level, F cells of a frustum grid, F_in those whose centres lie in the box):
//   grid updates, per frustum grid   2 V b (read mu and g) + F b (write d)
//     as coded, each of the two passes streams mu and g and the T/d field:  4 V b + 3 F b
//   extinction step   V b (2 (1 + S) + 1): read and write mu and the S optimiser fields
//     (S = 3 for AdEMAMix: m1, m2, rms), read mu_bar's source; plus min(F_in, 8 V) b per frustum
//     grid for the gathered d
// Loads and stores count once each, as STREAM counts them (no write-allocate reads).
//
// After the benchmarks, Markdown tables of all cases (Table-I style, memory per field, bandwidth)
// are printed to stdout. The STREAM probe runs before and after the benchmarks.
// Environment: VISOPT_BENCH_FULL=1 runs the larger set (see cases()); VISOPT_BENCH_STREAM_MIB sets
// the probe's array size (default: twice the last-level cache, at least 256 MiB, at most 2 GiB per
// array).
#include <benchmark/benchmark.h>

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <time.h>

#include "stream_probe.h"
#include "visopt/engine.h"
#include "visopt/exec.h"
#include "visopt/frustum.h"

namespace {

using visopt::Precision;
using Clock = std::chrono::steady_clock;

constexpr int kLevels = 3;
constexpr int kViewport = 512;  // the frustum grid is kViewport * frustumScale rays per side
constexpr double kMiB = 1024.0 * 1024.0;

struct Case {
  std::string scene;
  int volume = 0;   // longest axis in voxels
  int frustum = 0;  // view rays per side at the finest level
  Precision precision = Precision::FP32;
  bool light = false;  // r > 0: the light term and its grid
};

std::string nameOf(const Case& c) {
  return "optimize/" + c.scene + "/vol:" + std::to_string(c.volume) +
         "/frustum:" + std::to_string(c.frustum) + "/" + visopt::toString(c.precision) +
         (c.light ? "/light" : "/view");
}

struct LevelResult {
  int level = 0;
  int measured = 0;  // iterations after the warm-up
  int64_t voxels = 0;
  int64_t viewRays = 0, viewCells = 0, lightRays = 0, lightCells = 0;
  double gridMs = 0, viewMs = 0, lightMs = 0, stepMs = 0;  // medians
  double cpuShare = 0;
  double gridBytes = 0, gridBytesCoded = 0, stepBytes = 0;  // per iteration
  std::vector<visopt::LedgerEntry> ledger;
};

struct CaseResult {
  Case c;
  int iterationsPerLevel = 0;
  double inBoxView = 0, inBoxLight = 0;  // fraction of frustum cells with centres in the box
  std::vector<LevelResult> levels;
};

std::vector<CaseResult>& results() {
  static std::vector<CaseResult> r;
  return r;
}

visopt::bench::StreamResult& streamBefore() {
  static visopt::bench::StreamResult s;
  return s;
}

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Fraction of a frustum's cells (uniform in pixel and depth coordinates) whose centres lie in
// the voxels' cells [-0.5, dims - 0.5]: a property of the framing, not of the resolution, so a
// 96^3 sampling of the frustum serves every grid size.
double fractionInBox(const visopt::FrustumGrid& f, const visopt::GridSpec& grid) {
  const glm::vec3 lo(-0.5f), hi = glm::vec3(grid.dims) - 0.5f;
  int64_t inside = 0, total = 0;
  for (int k = 0; k < f.dims.z; ++k)
    for (int j = 0; j < f.dims.y; ++j)
      for (int i = 0; i < f.dims.x; ++i, ++total) {
        const glm::vec3 x = grid.worldToIndex(f.toWorld(
            glm::vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k))));
        if (glm::all(glm::greaterThanEqual(x, lo)) && glm::all(glm::lessThanEqual(x, hi))) ++inside;
      }
  return static_cast<double>(inside) / static_cast<double>(total);
}

size_t ledgerBytes(const std::vector<visopt::LedgerEntry>& entries, const std::string& name) {
  size_t bytes = 0;
  for (const auto& e : entries)
    if (e.name == name) bytes += e.bytes;
  return bytes;
}

// Iterations per level: enough measured finest-level iterations for a median (at least 3 after
// the warm-up) and about 1.5 s of finest-level work on 2 threads at ~25 ns per frustum cell.
int iterationsFor(const Case& c) {
  const double depth = 2.0 * std::sqrt(3.0) * c.volume;  // one cell per half voxel
  const double cells = double(c.frustum) * c.frustum * depth;
  return std::clamp(static_cast<int>(1.2e8 / cells), 4, 24);
}

// Collects per-level statistics from the optimiser's per-iteration callback.
class Recorder {
 public:
  explicit Recorder(const visopt::Engine& engine) : engine_(engine) { mark(); }

  void operator()(const visopt::IterationStats& st) {
    const double wall = secondsNow(), cpu = processCpuSeconds();
    const Totals now = totals();
    if (levels_.empty() || levels_.back().level != st.level) {
      finish();
      levels_.push_back(LevelResult{});
      LevelResult& r = levels_.back();
      r.level = st.level;
      r.ledger = engine_.ledger().entries();
      const double viewCalls = now.viewCalls - last_.viewCalls;
      const double lightCalls = now.lightCalls - last_.lightCalls;
      if (viewCalls > 0) r.viewRays = std::llround((now.viewItems - last_.viewItems) / viewCalls);
      if (lightCalls > 0)
        r.lightRays = std::llround((now.lightItems - last_.lightItems) / lightCalls);
    } else {
      grid_.push_back(st.gridUpdatesMs);
      step_.push_back(st.extinctionStepMs);
      view_.push_back(now.viewMs - last_.viewMs);
      light_.push_back(now.lightMs - last_.lightMs);
      wall_ += wall - lastWall_;
      cpu_ += cpu - lastCpu_;
    }
    last_ = now;
    lastWall_ = wall;
    lastCpu_ = cpu;
  }

  std::vector<LevelResult> take() {
    finish();
    return std::move(levels_);
  }

 private:
  struct Totals {
    double viewMs = 0, lightMs = 0, viewItems = 0, lightItems = 0, viewCalls = 0, lightCalls = 0;
  };
  static Totals totals() {
    Totals t;
    for (const visopt::StageTiming& s : visopt::stageTimings()) {
      if (s.name == "grid updates: view") {
        t.viewMs = s.totalMs;
        t.viewItems = s.items;
        t.viewCalls = static_cast<double>(s.calls);
      } else if (s.name == "grid updates: light") {
        t.lightMs = s.totalMs;
        t.lightItems = s.items;
        t.lightCalls = static_cast<double>(s.calls);
      }
    }
    return t;
  }
  static double secondsNow() {
    return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
  }
  void mark() {
    last_ = totals();
    lastWall_ = secondsNow();
    lastCpu_ = processCpuSeconds();
  }
  void finish() {
    if (levels_.empty() || grid_.empty()) return;
    LevelResult& r = levels_.back();
    r.measured = static_cast<int>(grid_.size());
    r.gridMs = median(grid_);
    r.stepMs = median(step_);
    r.viewMs = median(view_);
    r.lightMs = median(light_);
    r.cpuShare = wall_ > 0 ? cpu_ / (wall_ * tbb::info::default_concurrency()) : 0.0;
    grid_.clear();
    step_.clear();
    view_.clear();
    light_.clear();
    wall_ = cpu_ = 0;
  }

  const visopt::Engine& engine_;
  std::vector<LevelResult> levels_;
  std::vector<double> grid_, step_, view_, light_;
  double wall_ = 0, cpu_ = 0;
  Totals last_;
  double lastWall_ = 0, lastCpu_ = 0;
};

// Fills in cell counts and the byte model of a level from its ledger (see the header comment).
void applyByteModel(LevelResult& r, const CaseResult& cr) {
  const double b = static_cast<double>(visopt::bytesPerValue(cr.c.precision));
  const double muBytes = static_cast<double>(ledgerBytes(r.ledger, "extinction"));
  const double viewBytes = static_cast<double>(ledgerBytes(r.ledger, "view-derivative"));
  const double lightBytes = static_cast<double>(ledgerBytes(r.ledger, "light-derivative"));
  int state = 0;
  for (const auto& e : r.ledger)
    if (e.name.rfind("optimizer-", 0) == 0) ++state;
  r.voxels = std::llround(muBytes / b);
  r.viewCells = std::llround(viewBytes / b);
  r.lightCells = std::llround(lightBytes / b);
  const double v = muBytes;  // V b
  r.gridBytes = (viewBytes > 0 ? 2 * v + viewBytes : 0) + (lightBytes > 0 ? 2 * v + lightBytes : 0);
  r.gridBytesCoded =
      (viewBytes > 0 ? 4 * v + 3 * viewBytes : 0) + (lightBytes > 0 ? 4 * v + 3 * lightBytes : 0);
  r.stepBytes = v * (2.0 * (1 + state) + 1) + std::min(cr.inBoxView * viewBytes, 8 * v) +
                std::min(cr.inBoxLight * lightBytes, 8 * v);
}

double gbs(double bytes, double ms) {
  return ms > 0 ? bytes / (ms * 1e-3) * 1e-9 : 0.0;
}

void runCase(benchmark::State& state, const Case& c) {
  visopt::Engine engine(c.precision);
  engine.loadBuiltinScene(c.scene, c.volume);
  engine.setViewportSize(kViewport, kViewport);
  visopt::ExtinctionSettings s;
  s.levels = kLevels;
  s.frustumScale = static_cast<float>(c.frustum) / kViewport;
  s.maxIterationsPerLevel = iterationsFor(c);
  s.minIterationsPerLevel = s.maxIterationsPerLevel;
  s.tolerance = 0.f;
  if (c.light) {
    if (s.r == 0.f) s.r = 0.5f * s.q;
  } else {
    s.r = 0.f;
  }
  engine.setExtinctionSettings(s);

  CaseResult cr;
  cr.c = c;
  cr.iterationsPerLevel = s.maxIterationsPerLevel;
  const visopt::GridSpec& grid = engine.volume().grid();
  const visopt::Bounds bounds = grid.worldBounds();
  cr.inBoxView = fractionInBox(
      visopt::FrustumGrid::forCamera(engine.camera(), 96, 96, bounds, 96, grid.minSpacing()), grid);
  cr.inBoxLight = fractionInBox(
      visopt::FrustumGrid::forLight(engine.light(), bounds, glm::ivec3(96), grid.minSpacing()),
      grid);

  for (auto _ : state) {
    Recorder recorder(engine);
    engine.optimize([&](const visopt::IterationStats& st) {
      recorder(st);
      return true;
    });
    cr.levels = recorder.take();
    const LevelResult& finest = cr.levels.back();
    state.SetIterationTime((finest.gridMs + finest.stepMs) * 1e-3);
  }

  const double triad = streamBefore().triadGBs;
  for (LevelResult& r : cr.levels) {
    applyByteModel(r, cr);
    // (snprintf: GCC 12 warns falsely about "L" + std::to_string(...), -Wrestrict)
    auto counter = [&](const char* what) -> benchmark::Counter& {
      char key[32];
      std::snprintf(key, sizeof key, "L%d_%s", r.level, what);
      return state.counters[key];
    };
    counter("grid_ms") = r.gridMs;
    counter("step_ms") = r.stepMs;
    counter("cpu") = r.cpuShare;
    if (triad > 0) {
      counter("grid_frac") = gbs(r.gridBytes, r.gridMs) / triad;
      counter("step_frac") = gbs(r.stepBytes, r.stepMs) / triad;
    }
  }
  size_t total = 0;
  for (const auto& e : cr.levels.back().ledger) total += e.bytes;
  state.counters["mem_MiB"] = static_cast<double>(total) / kMiB;
  state.counters["iters_per_level"] = cr.iterationsPerLevel;
  results().push_back(std::move(cr));
}

// The default set runs in about 4 minutes on 2 shared cores; VISOPT_BENCH_FULL=1 adds the
// 256^3 volume with the 512^2 frustum (each iteration ~2.5 GB of frustum field and seconds of
// work), the light term at 256^3 and Shepp-Logan at 512^2 (about 12 minutes in all).
std::vector<Case> cases() {
  const char* env = std::getenv("VISOPT_BENCH_FULL");
  const bool full = env && *env && std::string(env) != "0";
  std::vector<Case> out;
  const Precision precisions[] = {Precision::FP32, Precision::FP16};
  for (int volume : {64, 128, 256})
    for (int frustum : {256, 512})
      for (Precision p : precisions)
        if (full || volume * frustum < 256 * 512)
          out.push_back({"earth-mantle", volume, frustum, p, false});
  // The light term adds the light grid (ExtinctionSettings::lightGridSize rays per side).
  for (int volume : {128, 256})
    for (Precision p : precisions)
      if (full || volume == 128) out.push_back({"earth-mantle", volume, 256, p, true});
  for (Precision p : precisions) out.push_back({"shepp-logan", 128, full ? 512 : 256, p, false});
  return out;
}

// ---- the summary --------------------------------------------------------------------------

std::string dims3(int64_t rays, int64_t cells) {
  if (rays <= 0) return "-";
  const int side = static_cast<int>(std::lround(std::sqrt(static_cast<double>(rays))));
  return std::to_string(side) + "²×" + std::to_string(cells / rays);
}

std::string mib(size_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(bytes) / kMiB);
  return buf;
}

void printSummary(const visopt::bench::StreamResult& before,
                  const visopt::bench::StreamResult& after) {
  std::printf("\n## Memory-bandwidth probe (STREAM-like, %d threads, %.0f MiB per array)\n\n",
              before.threads, static_cast<double>(before.arrayBytes) / kMiB);
  std::printf("| when | copy GB/s | triad GB/s | CPU share |\n|---|---|---|---|\n");
  std::printf("| before | %.2f | %.2f | %.2f |\n", before.copyGBs, before.triadGBs,
              before.cpuShare);
  std::printf("| after | %.2f | %.2f | %.2f |\n", after.copyGBs, after.triadGBs, after.cpuShare);
  const double triad = std::max(before.triadGBs, after.triadGBs);
  std::printf("\nFractions below are of the better triad figure, %.2f GB/s.\n", triad);

  std::printf("\n## Per-iteration stage times (ms, median), %s\n\n",
              visopt::backendDescription().c_str());
  std::printf(
      "| scene | volume | frustum | prec | r | level | voxels | view grid | light grid | grid "
      "updates | (view / light) | extinction step | CPU share | CPU-ms / iteration | ns / view "
      "cell / core | iters |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const double threads = tbb::info::default_concurrency();
  for (const CaseResult& cr : results())
    for (const LevelResult& r : cr.levels) {
      // Wall time times the CPU share actually obtained: robust against other load.
      const double cpuMs = (r.gridMs + r.stepMs) * r.cpuShare * threads;
      const double nsPerCell =
          r.viewCells > 0 ? r.viewMs * r.cpuShare * threads * 1e6 / double(r.viewCells) : 0.0;
      std::printf(
          "| %s | %d³ | %d² | %s | %s | %d | %lld | %s | %s | %.2f | %.2f / %.2f | %.2f | "
          "%.2f | %.1f | %.1f | %d |\n",
          cr.c.scene.c_str(), cr.c.volume, cr.c.frustum, visopt::toString(cr.c.precision),
          cr.c.light ? ">0" : "0", r.level, static_cast<long long>(r.voxels),
          dims3(r.viewRays, r.viewCells).c_str(), dims3(r.lightRays, r.lightCells).c_str(),
          r.gridMs, r.viewMs, r.lightMs, r.stepMs, r.cpuShare, cpuMs, nsPerCell, r.measured);
    }

  std::printf("\n## Memory per field at the finest level (MiB, engine ledger)\n\n");
  std::printf(
      "| scene | volume | frustum | prec | r | extinction | m1 | m2 | rms | view-derivative | "
      "light-derivative | other | total "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const char* named[] = {"extinction",    "optimizer-m1",    "optimizer-m2",
                         "optimizer-rms", "view-derivative", "light-derivative"};
  for (const CaseResult& cr : results()) {
    const auto& ledger = cr.levels.back().ledger;
    size_t total = 0, listed = 0;
    for (const auto& e : ledger) total += e.bytes;
    std::printf("| %s | %d³ | %d² | %s | %s |", cr.c.scene.c_str(), cr.c.volume, cr.c.frustum,
                visopt::toString(cr.c.precision), cr.c.light ? ">0" : "0");
    for (const char* n : named) {
      const size_t bytes = ledgerBytes(ledger, n);
      listed += bytes;
      std::printf(" %s |", mib(bytes).c_str());
    }
    std::printf(" %s | %s |\n", mib(total - listed).c_str(), mib(total).c_str());
  }
  if (!results().empty()) {
    std::printf("\n\"other\" at the finest level of the last case:");
    for (const auto& e : results().back().levels.back().ledger) {
      bool isNamed = false;
      for (const char* n : named) isNamed = isNamed || e.name == n;
      if (!isNamed)
        std::printf(" %s (%s, %s MiB);", e.name.c_str(), e.precision.c_str(), mib(e.bytes).c_str());
    }
    std::printf("\n");
  }

  std::printf("\n## Achieved bandwidth (minimum byte model; fraction of %.2f GB/s triad)\n\n",
              triad);
  std::printf(
      "| scene | volume | frustum | prec | r | level | grid MB | grid GB/s | grid frac | grid frac "
      "as coded | step MB | step GB/s | step frac |\n|---|---|---|---|---|---|---|---|---|---|---|"
      "---|---|\n");
  for (const CaseResult& cr : results())
    for (const LevelResult& r : cr.levels) {
      const double g = gbs(r.gridBytes, r.gridMs), gc = gbs(r.gridBytesCoded, r.gridMs);
      const double st = gbs(r.stepBytes, r.stepMs);
      std::printf(
          "| %s | %d³ | %d² | %s | %s | %d | %.1f | %.2f | %.3f | %.3f | %.1f | %.2f | %.3f |\n",
          cr.c.scene.c_str(), cr.c.volume, cr.c.frustum, visopt::toString(cr.c.precision),
          cr.c.light ? ">0" : "0", r.level, r.gridBytes * 1e-6, g, g / triad, gc / triad,
          r.stepBytes * 1e-6, st, st / triad);
    }
  std::printf(
      "\nFrustum cells inside the volume's box (for the step's gather): view %.3f, light %.3f"
      " (last case)\n",
      results().empty() ? 0.0 : results().back().inBoxView,
      results().empty() ? 0.0 : results().back().inBoxLight);
}

size_t streamArrayBytes() {
  if (const char* env = std::getenv("VISOPT_BENCH_STREAM_MIB"); env && *env)
    return static_cast<size_t>(std::max(1L, std::strtol(env, nullptr, 10))) * (1u << 20);
  const size_t llc = visopt::bench::lastLevelCacheBytes();
  return std::clamp<size_t>(2 * llc, size_t(256) << 20, size_t(2) << 30);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (const Case& c : cases())
    benchmark::RegisterBenchmark(nameOf(c).c_str(), [c](benchmark::State& st) { runCase(st, c); })
        ->Iterations(1)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);

  const size_t arrayBytes = streamArrayBytes();
  std::fprintf(stderr, "STREAM probe: 3 arrays of %.0f MiB...\n",
               static_cast<double>(arrayBytes) / kMiB);
  streamBefore() = visopt::bench::runStreamProbe(arrayBytes, 5);
  benchmark::AddCustomContext("stream_triad_GBs", std::to_string(streamBefore().triadGBs));
  benchmark::AddCustomContext("backend", visopt::backendDescription());
  benchmark::RunSpecifiedBenchmarks();
  const visopt::bench::StreamResult after = visopt::bench::runStreamProbe(arrayBytes, 5);
  printSummary(streamBefore(), after);
  benchmark::Shutdown();
  return 0;
}
