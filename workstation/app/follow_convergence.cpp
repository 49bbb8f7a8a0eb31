#include "follow_convergence.h"

#include <algorithm>
#include <cmath>

namespace visopt::ws {

void FollowConvergence::reset() {
  history_.clear();
  quiet_ = 0;
}

bool FollowConvergence::add(const IterationStats& st, const ExtinctionSettings& s) {
  const double e = st.energy();
  const double last = history_.empty() ? 0.0 : history_.back().energy();
  const double rel = std::abs(e - last) / std::max(std::abs(e), 1e-30);
  quiet_ = rel < double(s.tolerance) ? quiet_ + 1 : 0;
  history_.push_back(st);
  return quiet_ >= kQuietIterations || levelInCycle(history_, s) ||
         int(history_.size()) >= s.maxIterationsPerLevel;
}

}  // namespace visopt::ws
