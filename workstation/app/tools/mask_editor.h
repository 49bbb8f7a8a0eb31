// Editing logic of the world-space mask (Himmler & Günther 2026, §III-F, R5): a bit mask on the
// volume grid painted with a sphere brush in world units, in strokes that can be cancelled, undone
// and redone. No widgets: MaskPaintTool drives it from the mouse, tests drive it with world points.
// The mask goes to the engine as it is (Engine::setWorldMask takes the bit mask).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <visopt/grid.h>
#include <visopt/session.h>
#include <visopt/volume.h>

namespace visopt::ws {

class MaskEditor {
 public:
  enum class Mode { Paint, Erase };

  MaskEditor() = default;
  // An empty mask on the volume's grid; the scalars serve the editable-value range.
  explicit MaskEditor(std::shared_ptr<const Volume> volume);

  // Rebinds to a volume. On the same grid the mask and the history stay (only the scalars the
  // value range reads change); on another grid they are reset to an empty mask.
  void setVolume(std::shared_ptr<const Volume> volume);
  // An empty mask on `grid` without scalars (the value range is then ignored); resets history.
  void setGrid(const GridSpec& grid);
  const GridSpec& grid() const { return grid_; }
  bool hasGrid() const { return hasGrid_; }

  // Replaces the mask (e.g. from a session) and clears the history. Throws
  // std::invalid_argument when its dims differ from the grid's.
  void setMask(const SessionMask& mask);
  const SessionMask& mask() const { return mask_; }
  size_t markedCount() const;

  // Brush: a sphere of `radius` world units (mm): a voxel is inside when the world position of
  // its centre (spacing and direction matrix honoured) is within the radius.
  void setRadius(float radius);
  float radius() const { return radius_; }
  void setMode(Mode mode) { mode_ = mode; }
  Mode mode() const { return mode_; }
  // Only voxels whose scalar (data units: Volume::toValue) lies in [lo, hi] change; empty: all.
  void setValueRange(std::optional<std::pair<double, double>> range) { valueRange_ = range; }
  std::optional<std::pair<double, double>> valueRange() const { return valueRange_; }

  // ---- strokes ----
  // A stroke uses the mode it began with. Successive points are joined: every voxel within the
  // radius of the segment between them is painted (a capsule), so fast drags leave no gaps.
  // beginStroke during a stroke ends the previous one first.
  void beginStroke();
  // Returns the number of voxels this point changed.
  size_t addStrokePoint(glm::vec3 world);
  // The next point starts afresh instead of joining the last one (e.g. the cursor left the data).
  void breakStroke() { hasLast_ = false; }
  // Ends the stroke; one undo entry when it changed anything. Returns whether it did.
  bool endStroke();
  // Restores the state from before the stroke exactly; no history entry. Returns whether the
  // mask changed back.
  bool cancelStroke();
  bool stroking() const { return stroking_; }
  Mode strokeMode() const { return strokeMode_; }  // the mode of the stroke in progress
  size_t strokeChangedCount() const { return stroke_.size(); }

  // ---- history: one entry per stroke (or clear), storing only the changed voxels ----
  // Undo during a stroke only cancels the stroke; redo and clear cancel it first.
  bool canUndo() const { return !undo_.empty(); }
  bool canRedo() const { return !redo_.empty(); }
  bool undo();
  bool redo();
  // Unsets every voxel, as one undoable entry. Returns whether anything was set.
  bool clear();
  // History memory cap: after each new entry the oldest entries (undo first, then the redo
  // entries furthest away) are dropped until bytesUsed() <= cap; an entry larger than the cap is
  // not kept at all.
  void setMemoryCap(size_t bytes);
  size_t memoryCap() const { return cap_; }
  size_t bytesUsed() const { return bytes_; }
  size_t undoCount() const { return undo_.size(); }
  size_t redoCount() const { return redo_.size(); }
  // Counts every change of the mask (stroke points, undo, redo, clear, cancel, setMask).
  uint64_t revision() const { return revision_; }

 private:
  // Changed voxels as runs of consecutive linear indices (a brush covers runs along x).
  struct Run {
    uint64_t start = 0;
    uint32_t length = 0;
  };
  struct Entry {
    std::vector<Run> runs;
    size_t voxels = 0;
    size_t bytes() const { return sizeof(Entry) + runs.size() * sizeof(Run); }
  };

  void reset();
  void flip(uint64_t index);
  void flipEntry(const Entry& entry);
  Entry makeEntry(std::vector<uint64_t> indices) const;
  void push(Entry entry);
  void enforceCap();
  size_t stampSegment(glm::vec3 a, glm::vec3 b);
  bool editable(size_t index) const;

  GridSpec grid_;
  bool hasGrid_ = false;
  std::shared_ptr<const Volume> volume_;
  SessionMask mask_;
  float radius_ = 5.f;
  Mode mode_ = Mode::Paint;
  std::optional<std::pair<double, double>> valueRange_;

  bool stroking_ = false;
  Mode strokeMode_ = Mode::Paint;
  bool hasLast_ = false;
  glm::vec3 last_{0.f};
  std::vector<uint64_t> stroke_;  // voxels flipped by the current stroke, each once

  std::deque<Entry> undo_, redo_;  // back: the most recent
  size_t bytes_ = 0;
  size_t cap_ = size_t(64) << 20;
  uint64_t revision_ = 0;
};

}  // namespace visopt::ws
