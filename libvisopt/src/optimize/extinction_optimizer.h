// Host orchestration of the extinction optimisation (Himmler & Günther 2026, §II-C, Eqs. 10-14):
// the level loop of the coarse-to-fine multigrid, the frustum grids, the optimiser state,
// statistics.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/device_bit_mask.h"
#include "core/device_buffer.h"
#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/frustum.h"
#include "visopt/level_set.h"
#include "visopt/memory_ledger.h"
#include "visopt/optimization.h"
#include "visopt/volume.h"

namespace visopt {

struct OptimizationInputs {
  const Volume* volume = nullptr;
  const Field3D* importance = nullptr;                // g on the volume grid
  const DeviceBuffer<glm::vec4>* transfer = nullptr;  // baked (albedo, extinction) table
  float transferMaxExtinction = 0.f;
  Camera camera;
  PointLight light;
  int imageWidth = 512, imageHeight = 512;
  // Context surfaces: base SDFs phi0 on the volume grid (filled, or already a thin shell).
  std::vector<const Field3D*> surfaceBases;
  LevelSetSettings levelSet;
  const DeviceBitMask* worldMask = nullptr;  // set: surfaces keep their base shape there
  ImportanceLens lens;
  const Field3D* screenMask = nullptr;  // width x height x 1 weights, row 0 at the top
  // Changes (to any value) whenever `importance`, `lens` or `screenMask` change: ghat (Eq. 19)
  // is kept from iteration to iteration while it and the frusta stay the same.
  uint64_t importanceRevision = 0;
  // The surfaces stay at phi0 and take no part in the visibility scans: the volume-only
  // optimisation of [9] that the Fig. 10 baselines draw under their cut or faded surfaces
  // (Himmler & Günther 2026, §IV-A). ghat (Eq. 19) is still computed for them; it reads no
  // surface (kernels/visibility_scan.h's running maximum ignores them).
  bool surfacesHeld = false;
};

// Returning false from the callback stops the run after that iteration.
using IterationCallback = std::function<bool(const IterationStats&)>;
// Polled between the stages of an iteration (Engine::continueOptimization).
using AbandonCheck = std::function<bool()>;

// The discrete problem on one grid; used by the optimiser and by the gradient tests.
struct ExtinctionProblem {
  GridSpec grid;
  const Field3D* mu = nullptr;
  const Field3D* importance = nullptr;
  const Field3D* baseField = nullptr;  // mu_bar on `grid`, or null: TF of `scalars`
  const Field3D* scalars = nullptr;
  const DeviceBuffer<glm::vec4>* transfer = nullptr;
  float rho = 1.f, q = 1.f, r = 0.f;
  FrustumGrid view, light;
};

struct ProblemEvaluation {
  double energyRho = 0.0, energyQ = 0.0, energyR = 0.0;
  double visibilityView = 0.0, visibilityLight = 0.0;
  double energy() const { return energyRho + energyQ + energyR; }
};

// The discrete energy of the problem (see kernels/visibility_scan.h for its definition).
ProblemEvaluation evaluateProblem(const ExtinctionProblem& problem, Precision scratchPrecision);
// The analytic gradient dE/dmu per unit volume at every voxel (multiply by the voxel volume for
// the derivative of the discrete energy).
std::vector<float> analyticGradient(const ExtinctionProblem& problem, Precision scratchPrecision);

class ExtinctionOptimizer {
 public:
  // `ledgerSuffix` ends the names of its fields in the ledger (a second optimiser's, say).
  ExtinctionOptimizer(MemoryLedger* ledger, Precision precision, std::string ledgerSuffix = {});
  ~ExtinctionOptimizer();

  // Coarse to fine from mu_bar: each level runs to its tolerance or iteration cap, then mu is
  // prolonged to the next level; the optimiser state restarts at every level (its moments
  // describe the coarse grid's gradients, which do not transfer).
  // `abandon` (may be empty) is polled between the stages of every iteration: true before the
  // extinction step abandons the iteration in flight, which then changes nothing (mu, phi, the
  // optimiser's moments and step count stay bit for bit), and ends the call; true during the
  // level-set substeps ends them at the next chunk (fewer substeps: a consistent state) and the
  // call after that iteration.
  std::vector<IterationStats> runMultigrid(const OptimizationInputs& in,
                                           const ExtinctionSettings& settings,
                                           const IterationCallback& callback,
                                           const AbandonCheck& abandon = {});
  // Continues at the finest level from the current mu (warm start, e.g. after the camera moved).
  std::vector<IterationStats> iterate(const OptimizationInputs& in,
                                      const ExtinctionSettings& settings, int iterations,
                                      const IterationCallback& callback,
                                      const AbandonCheck& abandon = {});
  // While the camera moves (Himmler & Günther 2026, §III-F: "the visibility optimization adjusts
  // to new viewpoints during interactive camera navigation"): iterations on the coarsest level of
  // the multigrid (settings.levels) for the current camera and light, whose change to mu and to
  // each surface's phi is then prolonged onto the finest level and added there (a coarse-grid
  // correction; mu clamped to [0, mu_max] as Eq. 14 asks). The coarse level is restricted from
  // the finest state at the first call after any finest-level change (mu and the surfaces'
  // deviations as means, mu_bar and g as in the multigrid) and kept, with its own optimiser
  // state, while only these calls follow each other. A finest level is first built from mu_bar
  // when there is none. With one level this runs finest-level iterations (iterate()).
  // `abandon` as for iterate(): an abandoned iteration changes nothing, and what the iterations
  // before it did is prolonged.
  std::vector<IterationStats> follow(const OptimizationInputs& in,
                                     const ExtinctionSettings& settings, int iterations,
                                     const IterationCallback& callback,
                                     const AbandonCheck& abandon = {});
  // The optimised extinction on the volume grid, or null before any run.
  const Field3D* extinction() const;
  // The optimised context surfaces phi on the volume grid (one per base), empty before any run.
  std::vector<const Field3D*> surfaces() const;
  // ghat (Eq. 19) on the volume grid from the last iteration, when there are surfaces.
  const Field3D* importanceBehind() const;
  void reset();

  // Internal steps; public only because nvcc forbids extended device lambdas in private members.
  struct Level;
  // A level's grid and what does not come from the previous level: on coarse levels mu_bar, g,
  // each surface's phi0 and the world mask restricted from the finest inputs; ghat and the
  // level-set scratch when there are surfaces. mu and phi are allocated, not filled. `suffix`
  // ends the fields' names in the ledger.
  std::unique_ptr<Level> newLevel(const OptimizationInputs& in, int level, int levels,
                                  const std::string& suffix = {});
  void buildLevel(const OptimizationInputs& in, const ExtinctionSettings& settings, int level,
                  int levels);
  // One iteration on `level`; empty when abandoned (see runMultigrid).
  std::optional<IterationStats> runIteration(Level& level, const OptimizationInputs& in,
                                             const ExtinctionSettings& settings, int cap);
  // `ghatKept`: ghat already holds what this iteration's inputs give (Level::ghatFor).
  void surfaceStep(const OptimizationInputs& in, Level& level, bool ghatKept,
                   IterationStats& stats);

 private:
  bool abandonRequested() const { return abandon_ && *abandon_ && (*abandon_)(); }

  MemoryLedger* ledger_;
  Precision precision_;
  std::string ledgerSuffix_;
  std::unique_ptr<Level> level_;
  // follow(): the coarsest level restricted from level_, and its mu and phi when its change was
  // last prolonged onto level_.
  struct Follower;
  std::unique_ptr<Follower> follower_;
  const AbandonCheck* abandon_ = nullptr;  // during runMultigrid / iterate
  bool cutShort_ = false;                  // the last iteration's level-set steps were cut short
};

}  // namespace visopt
