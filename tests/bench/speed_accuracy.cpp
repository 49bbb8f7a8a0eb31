// The speed/accuracy trade of the extinction optimisation (Himmler & Günther 2026, §II-C): for each
// storage precision, number of multigrid levels, view frustum scale and per-level iteration budget,
// the wall time of Engine::optimize() and the error of the rendered image against a converged
// reference (fp32, 3 levels, frustum scale 1, a large budget and a small tolerance): PSNR
// (visopt::psnr, sRGB), SSIM (visopt/image_metrics.h, sRGB luma), the mean LDR-FLIP (the paper's
// metric, visopt::flip at its default observer) and the relative RMS difference of
// the optimised extinction from the reference's. Every image is rendered with the same settings and
// jitter seed, so the images differ only through mu. Prints the results as Markdown.
//
// Budget runs keep the library's default tolerance, so a level may end before its budget; the
// "iterations" column gives the number actually run (all levels).
//
// Usage: speed_accuracy [scene [volume [image]]]   defaults: earth-mantle 64 256
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include <time.h>

#include "visopt/engine.h"
#include "visopt/exec.h"
#include "visopt/image_metrics.h"

namespace {

using visopt::Precision;
using Clock = std::chrono::steady_clock;

// Iterations per level. At 64^3 and a 256^2 image the finest level's iteration costs ~0.3 s
// on 2 free cores, so these keep the whole table (54 runs) to about 3 minutes.
constexpr int kBudgets[] = {10, 30, 60};

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Run {
  double seconds = 0.0, cpuShare = 0.0;
  std::vector<visopt::IterationStats> stats;
  visopt::Image image;
  std::vector<float> mu;
};

struct Setup {
  std::string scene = "earth-mantle";
  int volume = 64;
  int image = 256;
};

visopt::RenderSettings renderSettings(const Setup& setup) {
  visopt::RenderSettings r;
  r.width = r.height = setup.image;
  r.seed = 7;
  return r;
}

Run optimizeAndRender(visopt::Engine& engine, const visopt::ExtinctionSettings& s,
                      const Setup& setup) {
  engine.setExtinctionSettings(s);
  engine.resetOptimization();
  Run run;
  const double cpu0 = processCpuSeconds();
  const auto t0 = Clock::now();
  run.stats = engine.optimize();
  run.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  run.cpuShare = (processCpuSeconds() - cpu0) / (run.seconds * tbb::info::default_concurrency());
  run.image = engine.render(renderSettings(setup));
  if (const visopt::Field3D* mu = engine.optimizedExtinction()) {
    run.mu.resize(mu->size());
    for (size_t i = 0; i < run.mu.size(); ++i) run.mu[i] = mu->get(i);
  }
  return run;
}

double relativeRms(const std::vector<float>& a, const std::vector<float>& ref) {
  if (a.size() != ref.size() || ref.empty()) return NAN;
  double diff = 0.0, norm = 0.0;
  for (size_t i = 0; i < ref.size(); ++i) {
    diff += (double(a[i]) - ref[i]) * (double(a[i]) - ref[i]);
    norm += double(ref[i]) * ref[i];
  }
  return norm > 0 ? std::sqrt(diff / norm) : NAN;
}

// How converged a run's last level is: its iterations and the relative energy change of its
// last iteration.
std::string convergence(const Run& r) {
  if (r.stats.empty()) return "no iterations";
  const int last = r.stats.back().level;
  int n = 0;
  for (const auto& st : r.stats) n += st.level == last ? 1 : 0;
  double rel = NAN;
  if (n >= 2) {
    const double e1 = r.stats.back().energy(), e0 = r.stats[r.stats.size() - 2].energy();
    rel = std::abs(e1 - e0) / std::max(std::abs(e1), 1e-30);
  }
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "%d iterations at the finest level, last relative energy change %.2g, step RMS "
                "%.2g, visibility %.3f",
                n, rel, r.stats.back().stepNorm, r.stats.back().visibilityView);
  return buf;
}

int run(const Setup& setup) {
  const auto start = Clock::now();
  std::printf("# Speed/accuracy: %s %d³, %d² image, %s\n\n", setup.scene.c_str(), setup.volume,
              setup.image, visopt::backendDescription().c_str());

  // Reference: fp32, 3 levels, frustum scale 1, converged.
  visopt::Engine reference(Precision::FP32);
  reference.loadBuiltinScene(setup.scene, setup.volume);
  reference.setViewportSize(setup.image, setup.image);
  visopt::ExtinctionSettings ref;
  ref.levels = 3;
  ref.frustumScale = 1.f;
  ref.maxIterationsPerLevel = 200;
  ref.tolerance = 1e-6f;
  const Run refRun = optimizeAndRender(reference, ref, setup);
  reference.setRenderOptimized(false);
  const visopt::Image unoptimized = reference.render(renderSettings(setup));
  std::printf(
      "Reference: fp32, 3 levels, frustum scale 1, at most %d iterations per level, tolerance "
      "%g: %zu iterations in %.1f s (CPU share %.2f); %s.\nThe unoptimised image (mu_bar) "
      "against it: PSNR %.2f dB, SSIM %.4f, FLIP %.4f.\n\n",
      ref.maxIterationsPerLevel, static_cast<double>(ref.tolerance), refRun.stats.size(),
      refRun.seconds, refRun.cpuShare, convergence(refRun).c_str(),
      visopt::psnr(unoptimized, refRun.image), visopt::ssim(unoptimized, refRun.image),
      visopt::flip(refRun.image, unoptimized).mean);
  std::fflush(stdout);

  std::printf(
      "| precision | levels | frustum scale | budget / level | iterations | time (s) | CPU share "
      "| PSNR (dB) | SSIM | FLIP | mu rel. RMS |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    visopt::Engine engine(p);
    engine.loadBuiltinScene(setup.scene, setup.volume);
    engine.setViewportSize(setup.image, setup.image);
    for (int levels : {1, 2, 3})
      for (float scale : {0.25f, 0.5f, 1.f})
        for (int budget : kBudgets) {
          visopt::ExtinctionSettings s;
          s.levels = levels;
          s.frustumScale = scale;
          s.maxIterationsPerLevel = budget;
          const Run r = optimizeAndRender(engine, s, setup);
          std::printf("| %s | %d | %.2f | %d | %d | %.2f | %.2f | %.2f | %.4f | %.4f | %.4f |\n",
                      visopt::toString(p), levels, static_cast<double>(scale), budget,
                      static_cast<int>(r.stats.size()), r.seconds, r.cpuShare,
                      visopt::psnr(r.image, refRun.image), visopt::ssim(r.image, refRun.image),
                      visopt::flip(refRun.image, r.image).mean, relativeRms(r.mu, refRun.mu));
          std::fflush(stdout);
        }
  }
  std::printf("\nTotal wall time: %.0f s\n",
              std::chrono::duration<double>(Clock::now() - start).count());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Setup setup;
  if (argc > 1) setup.scene = argv[1];
  if (argc > 2) setup.volume = std::atoi(argv[2]);
  if (argc > 3) setup.image = std::atoi(argv[3]);
  try {
    return run(setup);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "speed_accuracy: %s\n", e.what());
    return 1;
  }
}
