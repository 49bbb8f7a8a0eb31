#include "tools/mask_editor.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace visopt::ws {

MaskEditor::MaskEditor(std::shared_ptr<const Volume> volume) {
  setVolume(std::move(volume));
}

void MaskEditor::setVolume(std::shared_ptr<const Volume> volume) {
  if (stroking_) cancelStroke();
  const bool sameGrid = volume && hasGrid_ && volume->grid() == grid_;
  volume_ = std::move(volume);
  if (sameGrid) return;
  if (volume_) {
    grid_ = volume_->grid();
    hasGrid_ = true;
  } else {
    grid_ = GridSpec{};
    hasGrid_ = false;
  }
  reset();
}

void MaskEditor::setGrid(const GridSpec& grid) {
  if (stroking_) cancelStroke();
  volume_.reset();
  grid_ = grid;
  hasGrid_ = true;
  reset();
}

void MaskEditor::reset() {
  mask_ = SessionMask{};
  if (hasGrid_) {
    mask_.dims = grid_.dims;
    mask_.bits.assign((grid_.voxelCount() + 7) / 8, uint8_t(0));
  }
  stroking_ = false;
  hasLast_ = false;
  stroke_.clear();
  undo_.clear();
  redo_.clear();
  bytes_ = 0;
  ++revision_;
}

void MaskEditor::setMask(const SessionMask& mask) {
  if (!hasGrid_ || mask.dims != grid_.dims || mask.bits.size() != (grid_.voxelCount() + 7) / 8)
    throw std::invalid_argument("the mask's dimensions differ from the volume grid's");
  reset();
  mask_ = mask;
}

size_t MaskEditor::markedCount() const {
  size_t count = 0;
  for (uint8_t byte : mask_.bits) count += static_cast<size_t>(std::popcount(byte));
  return count;
}

void MaskEditor::setRadius(float radius) {
  if (std::isfinite(radius)) radius_ = std::max(radius, 0.f);
}

void MaskEditor::flip(uint64_t index) {
  mask_.set(index, !mask_.get(index));
}

void MaskEditor::flipEntry(const Entry& entry) {
  for (const Run& run : entry.runs)
    for (uint64_t i = run.start; i < run.start + run.length; ++i) flip(i);
  ++revision_;
}

bool MaskEditor::editable(size_t index) const {
  if (!valueRange_ || !volume_) return true;
  const double value = volume_->toValue(volume_->normalized.get(index));
  return value >= valueRange_->first && value <= valueRange_->second;
}

// ---- strokes ----

void MaskEditor::beginStroke() {
  if (stroking_) endStroke();
  stroking_ = true;
  strokeMode_ = mode_;
  hasLast_ = false;
  stroke_.clear();
}

size_t MaskEditor::addStrokePoint(glm::vec3 world) {
  if (!stroking_ || !hasGrid_) return 0;
  const glm::vec3 from = hasLast_ ? last_ : world;
  last_ = world;
  hasLast_ = true;
  const size_t changed = stampSegment(from, world);
  if (changed) ++revision_;
  return changed;
}

size_t MaskEditor::stampSegment(glm::vec3 a, glm::vec3 b) {
  const float r = radius_;
  // Index-space box around the capsule's world box (all 8 corners: the grid may be rotated).
  const glm::vec3 wlo = glm::min(a, b) - glm::vec3(r), whi = glm::max(a, b) + glm::vec3(r);
  glm::vec3 ilo(std::numeric_limits<float>::max()), ihi(-std::numeric_limits<float>::max());
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? whi.x : wlo.x, (c & 2) ? whi.y : wlo.y,
                           (c & 4) ? whi.z : wlo.z);
    const glm::vec3 idx = grid_.worldToIndex(corner);
    ilo = glm::min(ilo, idx);
    ihi = glm::max(ihi, idx);
  }
  glm::ivec3 lo, hi;
  for (int d = 0; d < 3; ++d) {
    const float maxIndex = static_cast<float>(grid_.dims[d] - 1);
    if (!(ihi[d] >= -1.f) || !(ilo[d] <= maxIndex + 1.f)) return 0;
    lo[d] = static_cast<int>(std::floor(std::max(ilo[d], 0.f)));
    hi[d] = static_cast<int>(std::ceil(std::min(ihi[d], maxIndex)));
  }
  const glm::vec3 ab = b - a;
  const float abLen2 = glm::dot(ab, ab);
  const float r2 = r * r;
  const bool paint = strokeMode_ == Mode::Paint;
  size_t changed = 0;
  for (int k = lo.z; k <= hi.z; ++k)
    for (int j = lo.y; j <= hi.y; ++j)
      for (int i = lo.x; i <= hi.x; ++i) {
        const glm::vec3 p = grid_.indexToWorld(
            glm::vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)));
        const float t = abLen2 > 0.f ? std::clamp(glm::dot(p - a, ab) / abLen2, 0.f, 1.f) : 0.f;
        const glm::vec3 d = p - (a + t * ab);
        if (glm::dot(d, d) > r2) continue;
        const size_t index = grid_.linearIndex(i, j, k);
        if (mask_.get(index) == paint || !editable(index)) continue;
        mask_.set(index, paint);
        stroke_.push_back(index);
        ++changed;
      }
  return changed;
}

bool MaskEditor::endStroke() {
  if (!stroking_) return false;
  stroking_ = false;
  hasLast_ = false;
  if (stroke_.empty()) return false;
  push(makeEntry(std::move(stroke_)));
  stroke_.clear();
  return true;
}

bool MaskEditor::cancelStroke() {
  if (!stroking_) return false;
  stroking_ = false;
  hasLast_ = false;
  const bool changed = !stroke_.empty();
  for (uint64_t i : stroke_) flip(i);
  stroke_.clear();
  if (changed) ++revision_;
  return changed;
}

// ---- history ----

MaskEditor::Entry MaskEditor::makeEntry(std::vector<uint64_t> indices) const {
  std::sort(indices.begin(), indices.end());
  Entry entry;
  entry.voxels = indices.size();
  for (uint64_t i : indices) {
    if (!entry.runs.empty()) {
      Run& last = entry.runs.back();
      if (last.start + last.length == i && last.length < std::numeric_limits<uint32_t>::max()) {
        ++last.length;
        continue;
      }
    }
    entry.runs.push_back(Run{i, 1});
  }
  entry.runs.shrink_to_fit();
  return entry;
}

void MaskEditor::push(Entry entry) {
  for (const Entry& e : redo_) bytes_ -= e.bytes();
  redo_.clear();
  bytes_ += entry.bytes();
  undo_.push_back(std::move(entry));
  enforceCap();
}

void MaskEditor::enforceCap() {
  while (bytes_ > cap_ && !undo_.empty()) {
    bytes_ -= undo_.front().bytes();
    undo_.pop_front();
  }
  while (bytes_ > cap_ && !redo_.empty()) {
    bytes_ -= redo_.front().bytes();  // front: the entry furthest from the current state
    redo_.pop_front();
  }
}

void MaskEditor::setMemoryCap(size_t bytes) {
  cap_ = bytes;
  enforceCap();
}

bool MaskEditor::undo() {
  if (stroking_) return cancelStroke();  // undoing a stroke in progress is cancelling it
  if (undo_.empty()) return false;
  Entry entry = std::move(undo_.back());
  undo_.pop_back();
  flipEntry(entry);
  redo_.push_back(std::move(entry));
  return true;
}

bool MaskEditor::redo() {
  if (stroking_) cancelStroke();
  if (redo_.empty()) return false;
  Entry entry = std::move(redo_.back());
  redo_.pop_back();
  flipEntry(entry);
  undo_.push_back(std::move(entry));
  return true;
}

bool MaskEditor::clear() {
  if (stroking_) cancelStroke();
  std::vector<uint64_t> set;
  const size_t n = mask_.voxelCount();
  for (size_t byte = 0; byte < mask_.bits.size(); ++byte) {
    if (!mask_.bits[byte]) continue;
    for (size_t i = byte * 8; i < std::min(n, byte * 8 + 8); ++i)
      if (mask_.get(i)) set.push_back(i);
  }
  if (set.empty()) return false;
  Entry entry = makeEntry(std::move(set));
  flipEntry(entry);
  push(std::move(entry));
  return true;
}

}  // namespace visopt::ws
