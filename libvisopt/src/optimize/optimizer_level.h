// One level of the extinction optimiser's coarse-to-fine multigrid (Himmler & Günther 2026,
// §II-C, §III): the fields of the level's grid, its optimiser state and its context surfaces.
// Private to src/optimize: the optimiser's own translation units share it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/device_bit_mask.h"
#include "core/device_buffer.h"
#include "optimize/extinction_optimizer.h"
#include "optimize/narrow_band.h"
#include "optimize/scan_skip_grid.h"
#include "visopt/field.h"
#include "visopt/frustum.h"

namespace visopt {

// What ghat (Eq. 19) is computed from besides the level's grid: the frusta it gathers the maxima
// of g along, and the revision of the importance and the screen weights.
struct ImportanceBehindInputs {
  FrustumGrid view, light;
  uint64_t importanceRevision = 0;
};

inline bool operator==(const ImportanceBehindInputs& a, const ImportanceBehindInputs& b) {
  return a.view == b.view && a.light == b.light && a.importanceRevision == b.importanceRevision;
}

struct ExtinctionOptimizer::Level {
  int index = 0;
  bool finest = false;
  GridSpec grid;
  std::optional<Field3D> mu, base, importance;  // base/importance only on coarse levels
  std::optional<Field3D> m1, m2, rms;
  std::optional<Field3D> dView, dLight;
  // Context surfaces: phi per surface, phi0 on coarse levels (the finest uses the inputs'),
  // the world mask on coarse levels, ghat, the frustum maxima of g and level-set scratch.
  std::vector<Field3D> phi, phi0;
  std::vector<NarrowBand> bands;  // per surface: the narrow band of the level-set numerics
  std::optional<DeviceBitMask> mask;
  std::optional<Field3D> ghat, viewMax, lightMax, scratch;
  FrustumGrid view, light;
  int shrink = 1;  // frustum grids are this many times coarser than at the finest level
  int t = 0;       // optimiser steps taken on this level
  float gradientScale = 1.f;
  double motionSinceRedistance = 0.0;  // bound on the surfaces' motion since the last redistancing
  int substeps = 0;                    // level-set substeps per iteration (LevelSetSettings::reach)
  double insideRiseSinceRedistance = 0.0;  // bound on the inside's rise (LevelSetStepStats)
  double lastMotion = 0.0;  // bound on how far the surfaces moved in the last iteration, world
                            // units
  double lastEnergy = 0.0;
  // The semi-implicit integrator's last chunk (substeps' time per step), where the next
  // iteration starts: a chunk costs the same whatever its length, so restarting each iteration
  // from `substeps` would double the steps of a level whose surfaces move slowly.
  int semiImplicitChunk = 0;
  // ghat (Eq. 19) depends on the importance, the view and light frusta and the screen weights
  // only: while they stay what `ghatFor` records (within a run, and between the workstation's
  // iterations while the camera rests), the frustum maxima of g, the importance-behind gather
  // and the fixed-brick marks are not redone.
  std::optional<ImportanceBehindInputs> ghatFor;  // what ghat was last computed for
  // The side of every surface each voxel lay on when this iteration's level-set steps began
  // (bit set: inside, phi < 0), 64 voxels per word.
  std::vector<DeviceBuffer<uint64_t>> insideAtStart;
  ScanSkipStorage scanSkip;  // the grid updates' empty space, rebuilt every iteration
};

// The coarse level of ExtinctionOptimizer::follow and what it was restricted for.
struct ExtinctionOptimizer::Follower {
  std::unique_ptr<Level> level;
  // mu and each surface's phi on `level` when their change was last prolonged onto the finest.
  std::optional<Field3D> muBefore;
  std::vector<Field3D> phiBefore;
  // The inputs it was restricted from: a change of any makes follow() restrict it anew.
  glm::ivec3 fineDims{0};
  int levels = 0;
  size_t surfaces = 0;
  uint64_t importanceRevision = 0;
  const void* transfer = nullptr;
  float transferMaxExtinction = 0.f;
  const void* worldMask = nullptr;
};

// The upper bound of mu (Eq. 14) on every level: the settings' mu_max, else the transfer
// function's largest extinction; lowered for fp16 storage.
float levelMuMax(const OptimizationInputs& in, const ExtinctionSettings& s, Precision p);

}  // namespace visopt
