// When a coarse-to-fine level ends (optimize/level_end.h): converged, or circling in a limit
// cycle without progress, and not while a surface is still on its way or the energy still falls.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "optimize/level_end.h"

namespace visopt {
namespace {

IterationStats stats(double energy, double meanDev = 0.0, double maxDev = 0.0,
                     double motion = 0.0) {
  IterationStats st;
  st.energyQ = energy;
  st.meanDeviationVoxels = meanDev;
  st.maxDeviationVoxels = maxDev;
  st.levelSetMotionVoxels = motion;
  return st;
}

// The first iteration at which the level would end, or -1 when it runs to the end of `seq`.
int endsAt(const std::vector<IterationStats>& seq, const ExtinctionSettings& s = {}) {
  for (size_t n = 1; n <= seq.size(); ++n)
    if (levelSettled(std::span(seq).first(n), s)) return int(n);
  return -1;
}

// The Cranium CT's coarsest level (README command), iterations 31-37 of its cycle: energy,
// mean and largest deviation (voxels), motion bound (voxels per iteration).
constexpr double kCtCycle[7][4] = {{-596904, 0.0412, 1.672, 4.555}, {-598725, 0.0411, 1.638, 5.246},
                                   {-598953, 0.0516, 1.660, 4.286}, {-600564, 0.0491, 1.620, 5.369},
                                   {-600497, 0.0357, 1.585, 4.567}, {-597814, 0.0324, 1.646, 3.152},
                                   {-595443, 0.0463, 1.660, 3.757}};

std::vector<IterationStats> ctCycle(int iterations, double driftPerIteration) {
  std::vector<IterationStats> seq;
  for (int i = 0; i < iterations; ++i) {
    const double* c = kCtCycle[i % 7];
    seq.push_back(stats(c[0] * (1.0 + driftPerIteration * i), c[1], c[2], c[3]));
  }
  return seq;
}

TEST(LevelEnd, ConvergesWhenTheEnergyAndSurfacesSettle) {
  // A geometric approach to -1e6 without surfaces: ends at the first relative change < 1e-4.
  std::vector<IterationStats> seq;
  for (int i = 0; i < 60; ++i) seq.push_back(stats(-1e6 * (1.0 - std::pow(0.7, i + 1))));
  int expected = -1;
  for (int i = 1; i < 60 && expected < 0; ++i) {
    const double rel = std::abs(seq[i].energy() - seq[i - 1].energy()) / std::abs(seq[i].energy());
    if (rel < 1e-4 && i + 1 >= 5) expected = i + 1;
  }
  ASSERT_GT(expected, 0);
  EXPECT_EQ(endsAt(seq), expected);
}

TEST(LevelEnd, NeverBeforeTheMinimumIterations) {
  std::vector<IterationStats> seq(20, stats(-5.0));  // flat from the start
  ExtinctionSettings s;
  s.minIterationsPerLevel = 12;
  EXPECT_EQ(endsAt(seq, s), 12);
}

TEST(LevelEnd, NotWhileASurfaceIsOnItsWay) {
  // The energy is flat but the surface keeps moving away from its base.
  std::vector<IterationStats> seq;
  for (int i = 0; i < 60; ++i) seq.push_back(stats(-5.0, 0.05 * i, 0.3 * i, 2.0));
  EXPECT_EQ(endsAt(seq), -1);
}

TEST(LevelEnd, EndsInTheCraniumCtsLimitCycle) {
  // The recorded cycle with the drift it had (~1e-4 per iteration): the convergence test never
  // passes (the energy changes by up to 0.45 % per iteration), the cycle test does once two
  // windows of it have run.
  const std::vector<IterationStats> seq = ctCycle(60, 1.2e-4 / 7.0);
  for (size_t n = 1; n <= seq.size(); ++n)
    EXPECT_FALSE(levelConverged(std::span(seq).first(n), {}));
  EXPECT_EQ(endsAt(seq), 2 * kLevelCycleWindow);
}

TEST(LevelEnd, NotInACycleThatStillMakesProgress) {
  // The same oscillation riding on a descent of 2e-3 per iteration (20x the tolerance).
  EXPECT_EQ(endsAt(ctCycle(60, 2e-3)), -1);
}

TEST(LevelEnd, NotWhenTheSurfacesDriftThroughTheCycle) {
  // The energy circles but the surfaces' mean deviation grows by 0.01 voxel per iteration.
  std::vector<IterationStats> seq = ctCycle(60, 0.0);
  for (size_t i = 0; i < seq.size(); ++i) seq[i].meanDeviationVoxels += 0.01 * double(i);
  EXPECT_EQ(endsAt(seq), -1);
}

TEST(LevelEnd, JitterAtTheToleranceEndsTheLevel) {
  // A converged energy that jitters by +-1.5e-4 (the default scene's middle level) with steady
  // surfaces: the convergence test's one-step change stays above 1e-4, the cycle test ends it.
  std::vector<IterationStats> seq;
  for (int i = 0; i < 60; ++i)
    seq.push_back(stats(-1e5 * (1.0 + (i % 2 ? 1.5e-4 : -1.5e-4)), 0.5, 2.0, 1.0));
  EXPECT_EQ(endsAt(seq), 2 * kLevelCycleWindow);
}

}  // namespace
}  // namespace visopt
