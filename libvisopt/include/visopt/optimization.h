// Settings and statistics of the visibility optimisation (Himmler & Günther 2026, §II-C, Eqs.
// 10-14).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace visopt {

enum class OptimizerKind { AdEMAMix, Adam };
OptimizerKind parseOptimizerKind(const std::string& text);  // "ademamix" | "adam"
const char* toString(OptimizerKind kind);

struct ExtinctionSettings {
  // Energy weights: F = rho/2 ∫(mu - mu_bar)^2 - q ∫ g mu T_V - r ∫ g mu T_L (Eqs. 11-13).
  // rho < 0 means "1 / mu_max", which makes rho (mu - mu_bar) a number in [-1, 1].
  float rho = -1.f;
  float q = 40.f;  // large: q G must outweigh rho mu_bar behind a dense occluder (G ~ T_occluder)
  // r = q: paper 000's R1, the joint optimisation from the view and the light, weighted equally
  // as Eq. 19 weighs ghat's view and light halves. 0: no light term, and without context
  // surfaces no light-space grids are allocated (a volume-only run is then ~30% cheaper).
  float r = 40.f;
  float muMax = 0.f;  // upper bound of Eq. 14 (1 / world unit); 0: the transfer function's maximum

  OptimizerKind optimizer = OptimizerKind::AdEMAMix;
  float learningRate = 0.05f;                           // in units of mu_max per step
  float beta1 = 0.9f, beta2 = 0.999f, beta3 = 0.9999f;  // AdEMAMix; Adam uses beta1, beta2
  float alpha = 5.f;                                    // AdEMAMix slow-EMA weight
  float epsilon = 1e-8f;
  // Warm-up lengths of AdEMAMix's alpha and beta3 schedulers; 0 = the level's iteration cap.
  int alphaWarmup = 0, beta3Warmup = 0;

  int levels = 3;  // coarse-to-fine multigrid levels
  int maxIterationsPerLevel = 60;
  float tolerance = 1e-4f;  // relative energy change that ends a level
  int minIterationsPerLevel = 5;

  // View frustum grid: rays per side as a fraction of the image size at the finest level, and
  // depth cells (0: one per half voxel along the volume's bounding sphere, at most 1024).
  float frustumScale = 0.5f;
  int depthCells = 0;
  int lightGridSize = 128;  // light frustum rays per side at the finest level
  bool operator==(const ExtinctionSettings&) const = default;
};

// A circular importance lens (Himmler & Günther 2026, §III-F, Fig. 8): inside it the importance
// along the view rays is multiplied by `strength` (0 hides, > 1 boosts, clamped to g <= 1).
struct ImportanceLens {
  float x = 0.5f, y = 0.5f;  // centre in normalised image coordinates, y down
  float radius = 0.f;        // fraction of the image width; 0: no lens
  float strength = 2.f;
};

struct IterationStats {
  int level = 0, iteration = 0;
  bool following = false;  // a coarse iteration of Engine::followCamera, not of the finest level
  double energyRho = 0.0, energyQ = 0.0, energyR = 0.0;
  double energy() const { return energyRho + energyQ + energyR; }
  double visibilityView = 0.0;   // V = ∫ g mu T_V / ∫ g mu over the view frustum
  double visibilityLight = 0.0;  // the same from the light (0 when r = 0)
  // Visibility through occluders: sum g mu T_V / sum g mu T_imp, T_imp the transmittance
  // through important matter alone: how much unimportant matter and context surfaces hide the
  // important structures, 1 when nothing does. What a structure hides of itself (its own front,
  // the back of a skull behind its front) weighs ~0 in both sums (kernels/visibility_scan.h).
  double visibilityViewOccluders = 0.0;
  double stepNorm = 0.0;  // RMS of the change of mu over the voxels
  double gridUpdatesMs =
      0.0;  // T_V, G_V, T_L, G_L (Himmler & Günther 2026, Table I "Grid Updates")
  double extinctionStepMs = 0.0;  // gather, optimiser step, projection ("Ext. Opt.")
  // Context surfaces (Himmler & Günther 2026, Eqs. 18-23), when there are any.
  double sdfStepMs = 0.0;           // ghat gather and the level-set step ("SDF Opt.")
  double redistanceMs = 0.0;        // all redistancing iterations ("Redist." x iterations)
  int redistanceIterations = 0;     // the most of one redistancing call
  int redistanceCalls = 0;          // redistancing calls (all surfaces)
  int redistancePasses = 0;         // redistancing iterations of all calls
  int64_t bandVoxels = 0;           // voxels of the surfaces' narrow bands at the end (0: dense)
  int64_t bandWorkVoxels = 0;       // of which the level-set kernels update (not fixed bricks)
  double redistanceResidual = 0.0;  // mean squared change of the last iteration (voxels^2)
  double levelSetTimeStep = 0.0;
  int levelSetSubsteps = 0;           // substeps of Eq. 23 this iteration
  double levelSetMotionVoxels = 0.0;  // bound on how far phi moved this iteration, voxels
  // Voxels whose side of a surface changed between the iteration's start and end: the net
  // motion, where levelSetMotionVoxels also counts churn that returns to where it started.
  int64_t levelSetCrossedVoxels = 0;
  double maxDeviationVoxels = 0.0;  // |phi0| on the current surface, over surface voxels
  double meanDeviationVoxels = 0.0;
};

// True when a level's iterations so far (oldest first) circle in a limit cycle without progress:
// over the last 8 the energy moves more back and forth than forward and gains less than ten
// times the tolerance per iteration, and the surfaces' deviation from their base shows no trend.
// ExtinctionOptimizer::optimize ends a level on it (besides convergence); a caller iterating on
// its own (the workstation following the camera) can ask the same.
bool levelInCycle(std::span<const IterationStats> level, const ExtinctionSettings& s);

}  // namespace visopt
