// ExtinctionOptimizer::follow: the optimisation keeps up with a moving camera (Himmler & Günther
// 2026, §III-F) by iterating on the coarsest multigrid level and prolonging what those
// iterations change onto the finest level — the correction scheme of a two-grid cycle, with the
// coarse problem restricted once from the finest state. A coarse iteration costs about 1/64 of
// a finest one at three levels (the volume and the frustum grids are 4x coarser per axis), so
// the openings move with a drag instead of waiting for the camera to rest.
#include <algorithm>
#include <limits>

#include "optimize/extinction_optimizer.h"
#include "optimize/level_set.h"
#include "optimize/multigrid_transfer.h"
#include "optimize/optimizer_level.h"
#include "visopt/error.h"

namespace visopt {

std::vector<IterationStats> ExtinctionOptimizer::follow(const OptimizationInputs& in,
                                                        const ExtinctionSettings& s, int iterations,
                                                        const IterationCallback& callback,
                                                        const AbandonCheck& abandon) {
  const int levels = std::max(s.levels, 1);
  if (levels == 1) return iterate(in, s, iterations, callback, abandon);
  if (!level_ || !level_->finest || level_->grid.dims != in.volume->grid().dims)
    iterate(in, s, 0, {});  // validates; builds the finest level from mu_bar
  if (iterations <= 0) return {};
  abandon_ = &abandon;
  struct Clear {
    const AbandonCheck*& p;
    ~Clear() { p = nullptr; }
  } clear{abandon_};

  Level& fine = *level_;
  const bool current = follower_ && follower_->fineDims == fine.grid.dims &&
                       follower_->levels == levels &&
                       follower_->surfaces == in.surfaceBases.size() &&
                       follower_->importanceRevision == in.importanceRevision &&
                       follower_->transfer == in.transfer->data() &&
                       follower_->transferMaxExtinction == in.transferMaxExtinction &&
                       follower_->worldMask == in.worldMask;
  if (!current) {
    // Restrict the finest state: mu as means, each surface by the operator that made its base
    // (the minimum, then redistanced), so that where nothing moved the coarse surface is its own
    // base, as at the coarsest level of a coarse-to-fine run. (The mean deviation from the base
    // would read phi outside the finest band, where only its sign is kept: narrow_band.h.)
    follower_.reset();
    auto f = std::make_unique<Follower>();
    f->level = newLevel(in, 0, levels, " (following)");
    Level& c = *f->level;
    const GridMap fineMap(fine.grid);
    restrictMean(*fine.mu, fineMap, *c.mu);
    // g as the maximum over the restriction samples, not the multigrid's mean: ghat (Eq. 19)
    // is a maximum of g along rays, compared with lambda in lambda(x) = max(0, lambda - ghat),
    // and a mean lowers a thin important structure's g below lambda on the coarse grid, whose
    // return term then closed what the finest level had opened (a disc 0.8 voxels thick behind
    // a shell, the camera turned 60 degrees: visibility 0.18 -> 0.06 with the mean, 0.58 with
    // the maximum; test_camera_follow).
    restrictMax(*in.importance, fineMap, *c.importance);
    for (size_t si = 0; si < c.phi.size(); ++si) {
      restrictSdf(fine.phi[si], fineMap, c.phi[si]);
      redistance(c.phi[si], in.levelSet, *c.scratch);
    }
    f->muBefore.emplace("extinction (following, prolonged)", c.grid, precision_, ledger_);
    copyField(*c.mu, *f->muBefore);
    for (size_t si = 0; si < c.phi.size(); ++si) {
      f->phiBefore.emplace_back("surface (following, prolonged)", c.grid, precision_, ledger_);
      copyField(c.phi[si], f->phiBefore.back());
    }
    f->fineDims = fine.grid.dims;
    f->levels = levels;
    f->surfaces = in.surfaceBases.size();
    f->importanceRevision = in.importanceRevision;
    f->transfer = in.transfer->data();
    f->transferMaxExtinction = in.transferMaxExtinction;
    f->worldMask = in.worldMask;
    follower_ = std::move(f);
  }

  Follower& f = *follower_;
  Level& coarse = *f.level;
  std::vector<IterationStats> all;
  for (int it = 0; it < iterations; ++it) {
    std::optional<IterationStats> st =
        runIteration(coarse, in, s, std::max(iterations, s.maxIterationsPerLevel));
    if (!st) break;
    st->following = true;
    all.push_back(*st);
    if (callback && !callback(*st)) break;
    if (cutShort_) break;
  }
  if (all.empty()) return all;  // abandoned before its extinction step: nothing changed

  // The correction: the finest level gains what the coarse iterations changed.
  const GridMap coarseMap(coarse.grid);
  prolongChange(*coarse.mu, *f.muBefore, coarseMap, *fine.mu, 0.f, levelMuMax(in, s, precision_));
  copyField(*coarse.mu, *f.muBefore);
  const float big = std::numeric_limits<float>::max();
  for (size_t si = 0; si < coarse.phi.size(); ++si) {
    const double moved =
        prolongChange(coarse.phi[si], f.phiBefore[si], coarseMap, fine.phi[si], -big, big);
    copyField(coarse.phi[si], f.phiBefore[si]);
    if (moved > 0.0) {
      // phi changed outside the kernels that keep the band: find it again from phi at the next
      // finest step, and redistance there (the prolonged change is no distance function).
      fine.bands[si].clear();
      fine.motionSinceRedistance = std::max(fine.motionSinceRedistance, moved);
    }
  }
  return all;
}

}  // namespace visopt
