// The speed/accuracy trade of the context-surface optimisation (Himmler & Günther 2026, §III, Eqs.
// 18-23): on a built-in scene with its context surface, for each number of redistancing iterations
// per optimisation iteration, storage precision and number of multigrid levels, the wall time of
// Engine::optimize(), the deviation of the final surface from a converged fp32 reference, and the
// error of the rendered image against the reference's.
//
// Surface deviation: |phi - phi_ref| in voxels over the voxels within 1.5 voxels of either zero
// level set (|phi| < 1.5 h or |phi_ref| < 1.5 h), mean and max. Image error: PSNR (visopt::psnr,
// sRGB) and SSIM (visopt/image_metrics.h, sRGB luma). Every image is rendered with the same
// settings and jitter seed, so images differ only through mu and phi.
//
// The reference: fp32, 3 levels, redistancing until the mean squared change per iteration falls
// below 1e-7 voxel^2 (at most 256 iterations), and a larger iteration budget with a small energy
// tolerance. The runs of the grid all use the library's default iteration budget and energy
// tolerance; only the number of redistancing iterations, the precision and the number of
// levels change. The grid's redistancing tolerance is 0, so every optimisation iteration runs
// exactly that many: with the library's default tolerance (1e-4) redistancing stops after about
// one iteration on this scene, whatever the cap. One more row gives the library's defaults.
//
// Usage: level_set_accuracy [scene [volume [image]]]   defaults: shepp-logan 48 96
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "visopt/engine.h"
#include "visopt/exec.h"
#include "visopt/image_metrics.h"

namespace {

using visopt::Precision;
using Clock = std::chrono::steady_clock;

struct Setup {
  std::string scene = "shepp-logan";
  int volume = 48;
  int image = 96;
};

struct Run {
  double seconds = 0.0;
  std::vector<visopt::IterationStats> stats;
  visopt::Image image;
  std::vector<float> phi;  // the final SDF of surface 0, world units
};

visopt::RenderSettings renderSettings(const Setup& setup) {
  visopt::RenderSettings r;
  r.width = r.height = setup.image;
  r.seed = 7;
  return r;
}

std::vector<float> copyOf(const visopt::Field3D& f) {
  std::vector<float> out(f.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = f.get(i);
  return out;
}

Run optimizeAndRender(visopt::Engine& engine, const visopt::ExtinctionSettings& es,
                      const visopt::LevelSetSettings& ls, const Setup& setup) {
  engine.setExtinctionSettings(es);
  engine.setLevelSetSettings(ls);
  engine.resetOptimization();
  Run run;
  const auto t0 = Clock::now();
  run.stats = engine.optimize();
  run.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  run.image = engine.render(renderSettings(setup));
  if (const visopt::Field3D* phi = engine.contextSurfacePhi(0)) run.phi = copyOf(*phi);
  return run;
}

struct Deviation {
  double mean = NAN, max = NAN;
  size_t voxels = 0;
  size_t worstAt = 0;  // voxel index of the max
};

// |a - b| / h over the voxels within `band` voxels of either zero level set.
Deviation surfaceDeviation(const std::vector<float>& a, const std::vector<float>& b, float h,
                           float band = 1.5f) {
  Deviation d;
  if (a.size() != b.size() || a.empty()) return d;
  double sum = 0.0, worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::abs(a[i]) >= band * h && std::abs(b[i]) >= band * h) continue;
    const double e = std::abs(double(a[i]) - double(b[i])) / double(h);
    sum += e;
    if (e > worst) {
      worst = e;
      d.worstAt = i;
    }
    ++d.voxels;
  }
  if (d.voxels) {
    d.mean = sum / double(d.voxels);
    d.max = worst;
  }
  return d;
}

size_t countOver(const std::vector<float>& a, const std::vector<float>& b, float h, double limit) {
  size_t n = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i)
    if (std::abs(double(a[i]) - double(b[i])) > limit * double(h)) ++n;
  return n;
}

double meanRedistanceIterations(const Run& r) {
  if (r.stats.empty()) return 0.0;
  double n = 0.0;
  for (const auto& s : r.stats) n += s.redistanceIterations;
  return n / double(r.stats.size());
}

double redistanceSeconds(const Run& r) {
  double ms = 0.0;
  for (const auto& s : r.stats) ms += s.redistanceMs;
  return 1e-3 * ms;
}

int run(const Setup& setup) {
  const auto start = Clock::now();
  std::printf(
      "# Level-set speed/accuracy: %s %d³ with its context surface, %d² image, %s, %d "
      "threads\n\n",
      setup.scene.c_str(), setup.volume, setup.image, visopt::backendDescription().c_str(),
      tbb::info::default_concurrency());

  // Reference: fp32, 3 levels, redistancing to convergence, a larger budget.
  visopt::Engine reference(Precision::FP32);
  reference.loadBuiltinScene(setup.scene, setup.volume, /*contextSurfaces=*/true);
  if (reference.contextSurfaces().empty()) {
    std::fprintf(stderr, "level_set_accuracy: scene %s has no context surface\n",
                 setup.scene.c_str());
    return 1;
  }
  reference.setViewportSize(setup.image, setup.image);
  const float h = reference.volume().grid().minSpacing();
  visopt::ExtinctionSettings refEs;
  refEs.levels = 3;
  refEs.maxIterationsPerLevel = 150;
  refEs.tolerance = 1e-6f;
  visopt::LevelSetSettings refLs;
  refLs.redistanceIterations = 256;
  refLs.redistanceTolerance = 1e-7f;
  const Run ref = optimizeAndRender(reference, refEs, refLs, setup);
  const std::vector<float> base = copyOf(*reference.contextSurfaceBase(0));
  const Deviation moved = surfaceDeviation(base, ref.phi, h);
  reference.setRenderOptimized(false);
  const visopt::Image before = reference.render(renderSettings(setup));
  std::printf(
      "Reference: fp32, 3 levels, at most %d iterations per level (tolerance %g), up to %d "
      "redistancing iterations (tolerance %g): %zu iterations in %.1f s (redistancing %.1f s, "
      "%.1f iterations per step on average), final V %.3f, max surface deviation from phi0 %.2f "
      "voxels.\nHow far the reference surface moved from its base shape phi0 (same measure): "
      "mean %.3f, max %.2f voxels over %zu voxels. The unoptimised image against the "
      "reference: PSNR %.2f dB, SSIM %.4f.\n\n",
      refEs.maxIterationsPerLevel, double(refEs.tolerance), refLs.redistanceIterations,
      double(refLs.redistanceTolerance), ref.stats.size(), ref.seconds, redistanceSeconds(ref),
      meanRedistanceIterations(ref), ref.stats.back().visibilityView,
      ref.stats.back().maxDeviationVoxels, moved.mean, moved.max, moved.voxels,
      visopt::psnr(before, ref.image), visopt::ssim(before, ref.image));
  std::fflush(stdout);

  std::printf(
      "| redist. cap | precision | levels | iterations | redist. it. | time (s) | redist. (s) | "
      "mean dev. (vox) | max dev. (vox) | PSNR (dB) | SSIM | final V |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::string notes;
  const char* only = std::getenv("LEVEL_SET_ACCURACY_ONLY");  // "CAP:LEVELS": one row per precision
  auto row = [&](visopt::Engine& engine, Precision p, int cap, float tolerance, int levels) {
    visopt::ExtinctionSettings es;
    es.levels = levels;
    visopt::LevelSetSettings ls;
    ls.redistanceIterations = cap;
    ls.redistanceTolerance = tolerance;
    if (only && std::string(only) != std::to_string(cap) + ":" + std::to_string(levels)) return;
    const Run r = optimizeAndRender(engine, es, ls, setup);
    const Deviation d = surfaceDeviation(r.phi, ref.phi, h);
    const std::string capText =
        tolerance > 0.f ? "≤ " + std::to_string(cap) + " (tol. 1e-4)" : std::to_string(cap);
    std::printf("| %s | %s | %d | %zu | %.1f | %.2f | %.2f | %.3f | %.2f | %.2f | %.4f | %.3f |\n",
                capText.c_str(), visopt::toString(p), levels, r.stats.size(),
                meanRedistanceIterations(r), r.seconds, redistanceSeconds(r), d.mean, d.max,
                visopt::psnr(r.image, ref.image), visopt::ssim(r.image, ref.image),
                r.stats.empty() ? 0.0 : r.stats.back().visibilityView);
    if (d.max > 3.0) {
      const glm::ivec3 dims = engine.volume().grid().dims;
      const int64_t v = int64_t(d.worstAt);
      notes += "- cap " + capText + ", " + visopt::toString(p) + ", " + std::to_string(levels) +
               " levels: the max deviation is at voxel (" + std::to_string(v % dims.x) + ", " +
               std::to_string((v / dims.x) % dims.y) + ", " +
               std::to_string(v / (dims.x * dims.y)) + ") of " + std::to_string(dims.x) +
               "^3: phi " + std::to_string(r.phi[d.worstAt] / h) + ", phi_ref " +
               std::to_string(ref.phi[d.worstAt] / h) + " voxels; " +
               std::to_string(countOver(r.phi, ref.phi, h, 3.0)) +
               " voxels deviate by more than 3 voxels\n";
    }
    std::fflush(stdout);
  };
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    visopt::Engine engine(p);
    engine.loadBuiltinScene(setup.scene, setup.volume, /*contextSurfaces=*/true);
    engine.setViewportSize(setup.image, setup.image);
    for (int cap : {4, 16, 64})
      for (int levels : {1, 2, 3}) row(engine, p, cap, 0.f, levels);
    if (p == Precision::FP32) row(engine, p, 64, visopt::LevelSetSettings{}.redistanceTolerance, 3);
  }
  if (!notes.empty()) std::printf("\n%s", notes.c_str());
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
    std::fprintf(stderr, "level_set_accuracy: %s\n", e.what());
    return 1;
  }
}
