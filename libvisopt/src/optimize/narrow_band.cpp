#include "optimize/narrow_band.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "core/field_view.h"
#include "visopt/field.h"

namespace visopt {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr uint8_t kActiveBrick = 1, kFixedBrick = 3;  // flags_ values (0: inactive)

size_t brickIndex(glm::ivec3 b, glm::ivec3 nb) {
  return size_t(b.x) + size_t(nb.x) * (size_t(b.y) + size_t(nb.y) * size_t(b.z));
}
glm::ivec3 brickCoords(size_t index, glm::ivec3 nb) {
  return {int(index % size_t(nb.x)), int((index / size_t(nb.x)) % size_t(nb.y)),
          int(index / (size_t(nb.x) * size_t(nb.y)))};
}

// The band distance of one voxel: min(|phi|, |phi0|), 0 where the two differ in sign.
float bandDistance(float a, float b) {
  return (a < 0.f) != (b < 0.f) ? 0.f : std::min(std::fabs(a), std::fabs(b));
}

// Faces of a brick: 2 axis + side (0 low, 1 high).
struct BrickScan {
  float distance = kInf;  // smallest band distance over the brick's voxels
  float face[6] = {kInf, kInf, kInf, kInf, kInf, kInf};  // smallest |phi| on each face
};

BrickScan scanBrick(const FieldView& phi, const FieldView& phi0, glm::ivec3 b, glm::ivec3 d) {
  BrickScan s;
  const glm::ivec3 lo = b * kBrick, hi = glm::min(lo + kBrick, d);
  for (int k = lo.z; k < hi.z; ++k)
    for (int j = lo.y; j < hi.y; ++j) {
      const size_t row = size_t(d.x) * (size_t(j) + size_t(d.y) * size_t(k));
      float rowMin = kInf;
      for (int i = lo.x; i < hi.x; ++i) {
        const float a = phi.load(row + size_t(i));
        const float base = phi0.valid() ? phi0.load(row + size_t(i)) : a;
        s.distance = std::min(s.distance, bandDistance(a, base));
        rowMin = std::min(rowMin, std::fabs(a));
      }
      s.face[0] = std::min(s.face[0], std::fabs(phi.load(row + size_t(lo.x))));
      s.face[1] = std::min(s.face[1], std::fabs(phi.load(row + size_t(hi.x - 1))));
      if (j == lo.y) s.face[2] = std::min(s.face[2], rowMin);
      if (j == hi.y - 1) s.face[3] = std::min(s.face[3], rowMin);
      if (k == lo.z) s.face[4] = std::min(s.face[4], rowMin);
      if (k == hi.z - 1) s.face[5] = std::min(s.face[5], rowMin);
    }
  return s;
}

// Bounds the values of brick `b` by the distances on the face of its neighbour `from` that they
// share: |phi(y)| <= |phi(x)| + |y - x| for x the face voxel on y's line across the face.
void boundFromFace(const FieldView& phi, glm::ivec3 b, glm::ivec3 from, glm::ivec3 d,
                   glm::vec3 spacing) {
  const glm::ivec3 lo = b * kBrick, hi = glm::min(lo + kBrick, d);
  const glm::ivec3 step = b - from;  // one axis is +-1
  const int axis = step.x != 0 ? 0 : (step.y != 0 ? 1 : 2);
  const int face = step[axis] > 0 ? lo[axis] - 1 : hi[axis];  // the claimant's face voxel
  for (int k = lo.z; k < hi.z; ++k)
    for (int j = lo.y; j < hi.y; ++j)
      for (int i = lo.x; i < hi.x; ++i) {
        glm::ivec3 x(i, j, k);
        const float reach = float(std::abs(x[axis] - face)) * spacing[axis];
        x[axis] = face;
        const float bound = std::fabs(phi.at(x.x, x.y, x.z)) + reach;
        const size_t v = phi.index(i, j, k);
        const float value = phi.load(v);
        if (std::fabs(value) > bound) phi.store(v, value < 0.f ? -bound : bound);
      }
}

// True when ghat is 0 on brick b and one voxel around it (its central differences read that far)
// and phi equals phi0 on it: a fixed point of the step and of redistancing (narrow_band.h).
bool brickIsFixed(const FieldView& phi, const FieldView& phi0, const FieldView& ghat, glm::ivec3 b,
                  glm::ivec3 d) {
  const glm::ivec3 lo = b * kBrick, hi = glm::min(lo + kBrick, d);
  const glm::ivec3 glo = glm::max(lo - 1, glm::ivec3(0)), ghi = glm::min(hi + 1, d);
  for (int k = glo.z; k < ghi.z; ++k)
    for (int j = glo.y; j < ghi.y; ++j)
      for (int i = glo.x; i < ghi.x; ++i)
        if (ghat.load(ghat.index(i, j, k)) != 0.f) return false;
  for (int k = lo.z; k < hi.z; ++k)
    for (int j = lo.y; j < hi.y; ++j)
      for (int i = lo.x; i < hi.x; ++i) {
        const size_t v = phi.index(i, j, k);
        if (!(phi.load(v) == phi0.load(v))) return false;
      }
  return true;
}

void appendSpans(const std::vector<uint8_t>& flags, glm::ivec3 nb, glm::ivec3 d, SpanList& out) {
  out.spans.clear();
  out.voxels = 0;
  for (int bz = 0; bz < nb.z; ++bz)
    for (int by = 0; by < nb.y; ++by) {
      const size_t brickRow = brickIndex({0, by, bz}, nb);
      for (int bx = 0; bx < nb.x;) {
        if (!flags[brickRow + size_t(bx)]) {
          ++bx;
          continue;
        }
        int end = bx + 1;
        while (end < nb.x && flags[brickRow + size_t(end)]) ++end;
        const int x0 = bx * kBrick, x1 = std::min(d.x, end * kBrick);
        for (int k = bz * kBrick; k < std::min(d.z, (bz + 1) * kBrick); ++k)
          for (int j = by * kBrick; j < std::min(d.y, (by + 1) * kBrick); ++j) {
            out.spans.push_back({int64_t(j) + int64_t(d.y) * k, x0, x1});
            out.voxels += x1 - x0;
          }
        bx = end;
      }
    }
}

}  // namespace

SpanList spansOfBricks(const std::vector<uint8_t>& flags, glm::ivec3 dims) {
  SpanList out;
  appendSpans(flags, (dims + (kBrick - 1)) / kBrick, dims, out);
  return out;
}

void NarrowBand::build(const Field3D& phi, const Field3D* phi0, float halfWidthVoxels) {
  clear();
  dims_ = phi.grid().dims;
  nb_ = (dims_ + glm::ivec3(kBrick - 1)) / kBrick;
  phiData_ = phi.raw();
  phi0_ = phi0;
  halfWidthVoxels_ = halfWidthVoxels;
  h_ = phi.grid().minSpacing();
  const float limit = halfWidthVoxels * h_;
  flags_.assign(size_t(nb_.x) * size_t(nb_.y) * size_t(nb_.z), 0);
  const FieldView p(phi);
  const FieldView base = phi0 ? FieldView(*phi0) : FieldView();
  const glm::ivec3 d = dims_, nb = nb_;
  uint8_t* flags = flags_.data();
  tbb::parallel_for(size_t(0), flags_.size(), [&](size_t b) {
    flags[b] = scanBrick(p, base, brickCoords(b, nb), d).distance <= limit;
  });
  for (size_t b = 0; b < flags_.size(); ++b)
    if (flags_[b]) active_.push_back(int32_t(b));
  rebuildSpans();
}

bool NarrowBand::builtFor(const Field3D& phi, float halfWidthVoxels) const {
  return !flags_.empty() && phi.raw() == phiData_ && phi.grid().dims == dims_ &&
         halfWidthVoxels == halfWidthVoxels_;
}

void NarrowBand::ensure(Field3D& phi, const Field3D* phi0, float halfWidthVoxels) {
  if (builtFor(phi, halfWidthVoxels)) return;
  build(phi, phi0, halfWidthVoxels);
  refresh(phi);
}

void NarrowBand::refresh(Field3D& phi) {
  lastActivated_ = lastReleased_ = 0;
  if (flags_.empty()) return;
  const FieldView p(phi);
  const FieldView base = phi0_ ? FieldView(*phi0_) : FieldView();
  const glm::ivec3 d = dims_, nb = nb_;
  const glm::vec3 spacing = phi.grid().spacing;
  const float limit = halfWidthVoxels_ * h_;
  const float release = (halfWidthVoxels_ + kReleaseMarginVoxels) * h_;

  // The active bricks' distances and face minima (only they can have changed).
  std::vector<BrickScan> scans(active_.size());
  tbb::parallel_for(size_t(0), active_.size(), [&](size_t a) {
    scans[a] = scanBrick(p, base, brickCoords(size_t(active_[a]), nb), d);
  });

  // Claims across faces whose voxels lie within limit + one voxel of the surface.
  std::vector<uint8_t> claimed(flags_.size(), 0);
  struct Claim {
    int32_t brick, from;
  };
  std::vector<Claim> newcomers;
  for (size_t a = 0; a < active_.size(); ++a) {
    const glm::ivec3 b = brickCoords(size_t(active_[a]), nb);
    for (int f = 0; f < 6; ++f) {
      const int axis = f / 2;
      glm::ivec3 n = b;
      n[axis] += (f % 2) ? 1 : -1;
      if (n[axis] < 0 || n[axis] >= nb[axis]) continue;
      if (scans[a].face[f] - spacing[axis] > limit) continue;
      const size_t ni = brickIndex(n, nb);
      claimed[ni] = 1;
      if (!flags_[ni]) newcomers.push_back({int32_t(ni), active_[a]});
    }
  }
  for (size_t a = 0; a < active_.size(); ++a) {
    const size_t b = size_t(active_[a]);
    if (scans[a].distance > release && !claimed[b]) {
      flags_[b] = 0;
      ++lastReleased_;
    }
  }
  // Newcomers: values bounded by their claimants' faces (serial: a few bricks per refresh).
  for (const Claim& c : newcomers) {
    boundFromFace(p, brickCoords(size_t(c.brick), nb), brickCoords(size_t(c.from), nb), d, spacing);
    if (!flags_[size_t(c.brick)]) ++lastActivated_;
    flags_[size_t(c.brick)] = 1;
  }
  if (lastActivated_ == 0 && lastReleased_ == 0) return;
  active_.clear();
  for (size_t b = 0; b < flags_.size(); ++b)
    if (flags_[b]) active_.push_back(int32_t(b));
  rebuildSpans();
}

namespace {
// The bricks flagged in `from` and their 26 neighbours.
std::vector<uint8_t> dilated(const std::vector<uint8_t>& from, glm::ivec3 nb) {
  std::vector<uint8_t> near(from.size(), 0);
  for (size_t a = 0; a < from.size(); ++a) {
    if (!from[a]) continue;
    const glm::ivec3 b = brickCoords(a, nb);
    for (int z = std::max(b.z - 1, 0); z <= std::min(b.z + 1, nb.z - 1); ++z)
      for (int y = std::max(b.y - 1, 0); y <= std::min(b.y + 1, nb.y - 1); ++y)
        for (int x = std::max(b.x - 1, 0); x <= std::min(b.x + 1, nb.x - 1); ++x)
          near[brickIndex({x, y, z}, nb)] = 1;
  }
  return near;
}
}  // namespace

void NarrowBand::rebuildSpans() {
  appendSpans(flags_, nb_, dims_, band_);
  appendSpans(dilated(flags_, nb_), nb_, dims_, halo_);
  fixedBricks_ = 0;
  idle_.clear();
  workBricks_.clear();
  idleNearBand_ = -1.f;
  for (const int32_t a : active_) fixedBricks_ += flags_[size_t(a)] == kFixedBrick;
  if (fixedBricks_ == 0) return;
  // Work: the active bricks that can change, and a fixed one between two of them along x.
  std::vector<uint8_t> work(flags_.size(), 0);
  for (const int32_t a : active_) work[size_t(a)] = flags_[size_t(a)] == kActiveBrick;
  for (const int32_t a : active_) {
    const glm::ivec3 b = brickCoords(size_t(a), nb_);
    if (flags_[size_t(a)] == kFixedBrick && b.x > 0 && b.x + 1 < nb_.x &&
        flags_[size_t(a) - 1] == kActiveBrick && flags_[size_t(a) + 1] == kActiveBrick)
      work[size_t(a)] = 1;
  }
  for (const int32_t a : active_) (work[size_t(a)] ? workBricks_ : idle_).push_back(a);
  appendSpans(work, nb_, dims_, work_);
  appendSpans(dilated(work, nb_), nb_, dims_, workHalo_);
}

std::vector<uint8_t> NarrowBand::workBrickFlags(bool skipFixed) const {
  std::vector<uint8_t> work(flags_.size(), 0);
  for (const int32_t a : active_)
    work[size_t(a)] = !skipFixed || flags_[size_t(a)] == kActiveBrick ? 1 : 0;
  return work;
}

void NarrowBand::markFixed(const Field3D& phi, const Field3D& ghat) {
  fixedGhat_ = ghat.raw();
  boundsKnown_.assign(flags_.size(), 0);
  brickBounds_.resize(flags_.size());
  if (flags_.empty()) return;
  for (const int32_t a : active_) flags_[size_t(a)] = kActiveBrick;
  if (phi0_ && phi.grid().dims == dims_ && ghat.grid().dims == dims_ &&
      phi0_->grid().dims == dims_) {
    const FieldView p(phi), base(*phi0_), g(ghat);
    const glm::ivec3 d = dims_, nb = nb_;
    std::vector<uint8_t> fixed(active_.size(), 0);
    tbb::parallel_for(size_t(0), active_.size(), [&](size_t a) {
      fixed[a] = brickIsFixed(p, base, g, brickCoords(size_t(active_[a]), nb), d);
    });
    for (size_t a = 0; a < active_.size(); ++a)
      if (fixed[a]) flags_[size_t(active_[a])] = kFixedBrick;
  }
  rebuildSpans();
}

StepBounds NarrowBand::workBounds(const Field3D& ghat) {
  const std::vector<int32_t>& bricks = fixedBricks_ > 0 ? workBricks_ : active_;
  StepBounds total;
  if (!fixedFor(ghat) || boundsKnown_.size() != flags_.size()) return total;
  std::vector<int32_t> missing;
  for (const int32_t b : bricks)
    if (!boundsKnown_[size_t(b)]) missing.push_back(b);
  const GridSpec& g = ghat.grid();
  const StepBoundsKernel k{FieldView(ghat), g.dims, g.spacing};
  const glm::ivec3 d = dims_, nb = nb_;
  StepBounds* out = brickBounds_.data();
  tbb::parallel_for(size_t(0), missing.size(), [&](size_t m) {
    const glm::ivec3 lo = brickCoords(size_t(missing[m]), nb) * kBrick,
                     hi = glm::min(lo + kBrick, d);
    StepBounds b;
    for (int z = lo.z; z < hi.z; ++z)
      for (int y = lo.y; y < hi.y; ++y) {
        const int64_t row = int64_t(d.x) * (int64_t(y) + int64_t(d.y) * z);
        for (int x = lo.x; x < hi.x; ++x) b = b + k(row + x);
      }
    out[missing[m]] = b;
  });
  for (const int32_t b : missing) boundsKnown_[size_t(b)] = 1;
  for (const int32_t b : bricks) total = total + brickBounds_[size_t(b)];
  // The idle (fixed) bricks are not stepped but hold ghat = 0, which sets the smallest ghat and
  // so the relaxation's bound lambda - min ghat, as it would over the whole band.
  if (fixedBricks_ > 0 && !idle_.empty()) total = total + StepBounds{0.f, 0.f, 0.f};
  return total;
}

int64_t NarrowBand::idleNearVoxels(const Field3D& phi, float nearBand) {
  if (idle_.empty()) return 0;
  if (nearBand == idleNearBand_) return idleNear_;
  const FieldView p(phi);
  int64_t count = 0;
  for (const int32_t a : idle_) {
    const glm::ivec3 lo = brickCoords(size_t(a), nb_) * kBrick, hi = glm::min(lo + kBrick, dims_);
    for (int k = lo.z; k < hi.z; ++k)
      for (int j = lo.y; j < hi.y; ++j)
        for (int i = lo.x; i < hi.x; ++i) count += std::fabs(p.load(p.index(i, j, k))) <= nearBand;
  }
  idleNearBand_ = nearBand;
  idleNear_ = count;
  return count;
}

}  // namespace visopt
