// The narrow band of one context surface (issue 11): bricks of kBrick^3 voxels of the volume grid
// that the level-set step (Eq. 23) and redistancing (Eq. 18) update, kept from call to call and
// moved with the surface instead of being found again by a pass over the whole grid.
//
// A brick is active when one of its voxels lies within the band's half-width of the surface
// (|phi|) or of its base shape (|phi0|), or where the two differ in sign (the region the surface
// swept, where the return term of Eq. 23 can flip the sign back; left out, a surface relaxing from
// far away would leave its old inside behind as a spurious one). The storage of phi is dense: an
// inactive brick keeps the values it had when it left the band (or the base SDF's), of which only
// the sign is read.
//
// Following the surface: the kernels write only active bricks, so an inactive brick's values
// never change by themselves and cannot say that the surface came near. The active bricks' faces
// say it instead: when a face's voxels come within half-width + 1 voxel of the surface, the
// brick across that face may hold a voxel within the half-width and is activated, its values
// bounded by the face's distances plus the distance to the face (a distance function is
// 1-Lipschitz; stale values from long ago can be far too large). A brick leaves the band once all
// its voxels are farther than half-width + kReleaseMarginVoxels (hysteresis: a surface
// oscillating about a brick's edge does not switch it on and off) and no active neighbour's face
// claims it.
//
// Bricks that cannot change (markFixed): where ghat is 0 on a brick and one voxel around it and
// phi equals phi0 on it, Eq. 23 leaves every voxel exactly as it is (the drive term is
// max(0, 0 kappa |grad phi| + 0 . grad phi) = 0, the return term lambda (phi0 - phi) = 0), and so
// does redistancing against phi0 (it holds voxels within kRedistanceKeepsBaseWithin of phi0).
// The back of a CT's skin, which hides nothing from the view, is such a region. Nothing but the
// kernels and the claims write phi, and neither writes an active brick's values outside the work
// spans, so a fixed brick stays one until ghat changes, when the caller marks the band anew.
// The kernels then run over the work spans: runs of the other active bricks along x (with a
// fixed brick between two of them, so that rows stay long enough to vectorise).
//
// Host data: the band path runs on the CPU backend.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "kernels/level_set_step.h"
#include "visopt/field.h"

namespace visopt {

inline constexpr int kBrick = 8;

// Voxels [x0, x1) of the x row `row` (= j + dims.y * k).
struct RowSpan {
  int64_t row;
  int x0, x1;
};

// Runs of bricks along x, one span per voxel row.
struct SpanList {
  std::vector<RowSpan> spans;
  int64_t voxels = 0;
};

// The x-spans (one per voxel row) of the bricks flagged in `flags` (per brick, x fastest) of a
// grid of `dims` voxels.
SpanList spansOfBricks(const std::vector<uint8_t>& flags, glm::ivec3 dims);

class NarrowBand {
 public:
  static constexpr float kReleaseMarginVoxels = 2.f;

  // From phi and phi0 (nullable): every brick's distance, a pass over the whole grid.
  void build(const Field3D& phi, const Field3D* phi0, float halfWidthVoxels);
  // True when built for phi (its storage and grid) and this half-width, from any base.
  bool builtFor(const Field3D& phi, float halfWidthVoxels) const;
  // The band for phi (built from phi and phi0 unless builtFor(phi, halfWidthVoxels) already,
  // then refreshed once so that it also holds the bricks its faces claim).
  void ensure(Field3D& phi, const Field3D* phi0, float halfWidthVoxels);
  // After phi changed inside the active bricks only: their distances again (reading those bricks
  // only), neighbours activated across faces near the surface, bricks far from it released.
  void refresh(Field3D& phi);
  void clear() { *this = NarrowBand(); }

  // Marks the active bricks that are a fixed point of the step with this ghat (on phi's grid)
  // and of redistancing against the band's base (needs a band built with phi0; nothing is
  // marked otherwise). Call again whenever ghat changes: the marks hold for this ghat's values.
  void markFixed(const Field3D& phi, const Field3D& ghat);
  // True when the marks were made for this ghat field (its storage).
  bool fixedFor(const Field3D& ghat) const {
    return fixedGhat_ != nullptr && ghat.raw() == fixedGhat_;
  }
  // The voxels the kernels must update: the band without the fixed bricks (the band itself
  // before any mark), and as far as their stencils reach.
  const SpanList& work() const { return fixedBricks_ > 0 ? work_ : band_; }
  const SpanList& workHalo() const { return fixedBricks_ > 0 ? workHalo_ : halo_; }
  int64_t fixedBricks() const { return fixedBricks_; }
  // The bounds of the stable time step (max |grad ghat|, max and min ghat) over the work spans
  // and, as 0, over the fixed bricks outside them: the same as over the whole band. Needs
  // fixedFor(ghat); each brick's bounds are computed once per mark and kept.
  StepBounds workBounds(const Field3D& ghat);
  // Voxels of the band outside the work spans with |phi| <= nearBand (world units): what a
  // mean over the band counts there (their change is 0). Cached until the spans change.
  int64_t idleNearVoxels(const Field3D& phi, float nearBand);

  // Per brick (x fastest, brickDims() of them): 1 where the kernels update it, i.e. active and,
  // with skipFixed, not fixed (the semi-implicit step's lines run through these).
  std::vector<uint8_t> workBrickFlags(bool skipFixed) const;
  glm::ivec3 brickDims() const { return nb_; }

  bool empty() const { return active_.empty(); }
  const Field3D* base() const { return phi0_; }
  // The active bricks as spans, and their halo (the active bricks and their 26 neighbours,
  // which the stencils of the active voxels reach into: two voxels at most).
  const SpanList& band() const { return band_; }
  const SpanList& halo() const { return halo_; }
  int64_t activeBricks() const { return int64_t(active_.size()); }
  int64_t bricks() const { return int64_t(flags_.size()); }
  // Bricks that the last refresh activated and released.
  int64_t lastActivated() const { return lastActivated_; }
  int64_t lastReleased() const { return lastReleased_; }

 private:
  void rebuildSpans();

  glm::ivec3 dims_{0}, nb_{0};
  const void* phiData_ = nullptr;
  const Field3D* phi0_ = nullptr;
  float halfWidthVoxels_ = 0.f;
  float h_ = 1.f;                // the grid's smallest spacing
  std::vector<uint8_t> flags_;   // per brick (x fastest): 1 = active, 3 = active and fixed
  std::vector<int32_t> active_;  // the active bricks' indices, ascending
  SpanList band_, halo_, work_, workHalo_;
  const void* fixedGhat_ = nullptr;
  int64_t fixedBricks_ = 0;
  std::vector<int32_t> idle_;            // active bricks outside the work spans
  std::vector<int32_t> workBricks_;      // the bricks of the work spans
  std::vector<StepBounds> brickBounds_;  // per brick, valid where boundsKnown_
  std::vector<uint8_t> boundsKnown_;
  float idleNearBand_ = -1.f;
  int64_t idleNear_ = 0;
  int64_t lastActivated_ = 0, lastReleased_ = 0;
};

}  // namespace visopt
