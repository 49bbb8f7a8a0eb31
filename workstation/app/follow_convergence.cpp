#include "follow_convergence.h"

#include <algorithm>
#include <cmath>

namespace visopt::ws {

void FollowConvergence::reset() {
  history_.clear();
  lastEnergy_ = 0.0;
  quiet_ = 0;
}

bool FollowConvergence::add(const IterationStats& st, const ExtinctionSettings& s) {
  const double e = st.energy();
  const double rel = std::abs(e - lastEnergy_) / std::max(std::abs(e), 1e-30);
  lastEnergy_ = e;
  quiet_ = rel < double(s.tolerance) ? quiet_ + 1 : 0;
  history_.push_back(st);
  return quiet_ >= kQuietIterations || levelInCycle(history_, s) ||
         int(history_.size()) >= s.maxIterationsPerLevel;
}

}  // namespace visopt::ws
