#include "optimize/level_end.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace visopt {
namespace {

// The deviation statistics count as unchanged within these (voxels): the mean to the third
// decimal, the largest (one voxel of the surface, so noisier) to a tenth.
constexpr double kMeanDeviationSteady = 0.002;
constexpr double kMaxDeviationSteady = 0.1;

// The cycle test's energy conditions: the best energy of the last window improves on the best
// of the window before by less than half of how far the energy travelled up and down within the
// last window (it moves more back and forth than forward), and by less than this many times the
// tolerance per iteration (a level that still gains ten times the tolerance each iteration is
// getting somewhere, however much it oscillates on the way).
constexpr double kCycleProgressFactor = 10.0;

struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double x) {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  bool within(const Range& r, double slack) const {
    return lo >= r.lo - slack && hi <= r.hi + slack;
  }
};

}  // namespace

bool levelConverged(std::span<const IterationStats> level, const ExtinctionSettings& s) {
  const size_t n = level.size();
  if (n == 0 || int(n) < s.minIterationsPerLevel) return false;
  const IterationStats& st = level[n - 1];
  const double e = st.energy();
  const double before = n >= 2 ? level[n - 2].energy() : 0.0;
  const double rel = std::abs(e - before) / std::max(std::abs(e), 1e-30);
  // The energy alone can stall while a surface is still on its way through an unimportant
  // layer: the surfaces must have stopped too, having moved by less than a tenth of a voxel in
  // the last iteration, or where they lie stopped changing. levelSetMotionVoxels bounds the
  // motion by the largest change of any substep, so it also counts churn that goes nowhere:
  // where the advection term (grad ghat . grad phi) pushes a surface out each substep and
  // redistancing and the return term pull it back, it stays near a voxel per iteration at a
  // standstill (builtin:ct-head: 0.9 voxel per iteration for 40 iterations while the deviation
  // from the base stayed 0.057 voxel on average and 1.09 at most, to the third decimal). A
  // surface on its way changes how far it lies from its base: both deviation statistics steady
  // from one iteration to the next is a standstill.
  const bool deviationSteady =
      n >= 2 &&
      std::abs(st.meanDeviationVoxels - level[n - 2].meanDeviationVoxels) < kMeanDeviationSteady &&
      std::abs(st.maxDeviationVoxels - level[n - 2].maxDeviationVoxels) < kMaxDeviationSteady;
  const bool surfacesSettled = st.levelSetMotionVoxels < 0.1 || deviationSteady;
  return rel < double(s.tolerance) && surfacesSettled;
}

bool levelInCycle(std::span<const IterationStats> level, const ExtinctionSettings& s) {
  constexpr size_t w = kLevelCycleWindow;
  const size_t n = level.size();
  if (n < 2 * w || int(n) < s.minIterationsPerLevel) return false;
  Range energyBefore, energyLast, meanBefore, meanLast, maxBefore, maxLast;
  double travelled = 0.0;
  for (size_t k = n - 2 * w; k < n; ++k) {
    const IterationStats& st = level[k];
    const bool last = k >= n - w;
    (last ? energyLast : energyBefore).add(st.energy());
    (last ? meanLast : meanBefore).add(st.meanDeviationVoxels);
    (last ? maxLast : maxBefore).add(st.maxDeviationVoxels);
    if (last) travelled += std::abs(st.energy() - level[k - 1].energy());
  }
  // The energy is minimised: progress is how much lower the last window's best lies.
  const double progress = energyBefore.lo - energyLast.lo;
  const double scale = std::max(std::abs(energyLast.lo), 1e-30);
  const bool energyCircles =
      progress < 0.5 * travelled &&
      progress < kCycleProgressFactor * double(s.tolerance) * double(w) * scale;
  // A surface on its way moves its deviation out of the range it kept in the window before.
  const bool surfacesCircle = meanLast.within(meanBefore, kMeanDeviationSteady) &&
                              maxLast.within(maxBefore, kMaxDeviationSteady);
  return energyCircles && surfacesCircle;
}

}  // namespace visopt
