// When following the camera has settled (EngineController): the energy's relative change below
// the tolerance for kQuietIterations iterations in a row, a limit cycle without progress
// (visopt::levelInCycle, the rule that also ends a coarse-to-fine level), or the level's
// iteration budget spent. Without the cycle test a view of the Cranium CT whose surfaces circle
// kept the worker iterating for the whole budget after every camera move.
#pragma once

#include <vector>

#include "visopt/optimization.h"

namespace visopt::ws {

class FollowConvergence {
 public:
  static constexpr int kQuietIterations = 5;

  // A new camera, a finished task or a settled run: start counting again.
  void reset();
  // One more follow iteration; true once the run has settled.
  bool add(const IterationStats& st, const ExtinctionSettings& s);

 private:
  std::vector<IterationStats> history_;  // since the last reset, oldest first
  int quiet_ = 0;
};

}  // namespace visopt::ws
