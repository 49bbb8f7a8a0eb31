// The world-mask brush (Himmler & Günther 2026, §III-F, R5): left drag paints the mask where the
// cursor's ray hits the scene (pickWorldPoint), Ctrl held (or erase mode) erases, Escape cancels
// the stroke in progress. One undo entry per stroke.
#pragma once

#include <memory>
#include <optional>
#include <utility>

#include <QElapsedTimer>
#include <QPointF>
#include <QTimer>
#include <glm/glm.hpp>

#include <visopt/session.h>

#include "tools/mask_editor.h"
#include "tools/picking.h"
#include "viewport_tool.h"

namespace visopt::ws {

class MaskPaintTool : public ViewportTool {
  Q_OBJECT
 public:
  explicit MaskPaintTool(QObject* parent = nullptr);

  // The editor is rebound to the scene's volume on every event (same grid: the mask stays).
  MaskEditor& editor() { return editor_; }
  const MaskEditor& editor() const { return editor_; }
  // Binds to a volume ahead of any event (e.g. to load a session's mask with setMask).
  void setVolume(std::shared_ptr<const Volume> volume);
  // Replaces the mask and clears the history; emits maskChanged. Throws std::invalid_argument
  // when the dims differ from the volume's.
  void setMask(const SessionMask& mask);
  std::shared_ptr<const SessionMask> mask() const;

  void setRadius(float millimetres);  // brush radius in world units
  float radius() const { return editor_.radius(); }
  void setMode(MaskEditor::Mode mode);  // Ctrl held at the press inverts it for that stroke
  MaskEditor::Mode mode() const { return editor_.mode(); }
  void setValueRange(std::optional<std::pair<double, double>> range);  // data units
  void setUndoMemoryCap(size_t bytes);
  void setPickOptions(const PickOptions& options) { pickOptions_ = options; }
  // Minimum interval between maskChanged signals during a stroke.
  void setLiveUpdateInterval(int milliseconds) { liveIntervalMs_ = milliseconds; }

  bool canUndo() const { return editor_.canUndo(); }
  bool canRedo() const { return editor_.canRedo(); }
  bool stroking() const { return editor_.stroking(); }

  bool mousePress(QMouseEvent* event, const ViewContext& view) override;
  bool mouseMove(QMouseEvent* event, const ViewContext& view) override;
  bool mouseRelease(QMouseEvent* event, const ViewContext& view) override;
  bool keyPress(QKeyEvent* event, const ViewContext& view) override;
  void deactivate() override;
  void paintOverlay(QPainter& painter, const ViewContext& view) override;

 public slots:
  void undo();
  void redo();
  void cancelStroke();
  void clear();

 signals:
  // At the end of a stroke, after undo, redo, cancel, clear and setMask, and at most every
  // liveUpdateInterval during a stroke.
  void maskChanged(std::shared_ptr<const visopt::SessionMask> mask);
  void historyChanged(bool canUndo, bool canRedo);

 private:
  void bind(const ViewContext& view);
  void hover(QPointF pos, const ViewContext& view);
  void paintAt(QPointF pos, const ViewContext& view);
  void emitMask();
  void liveUpdate();

  MaskEditor editor_;
  PickOptions pickOptions_;
  int liveIntervalMs_ = 100;
  QElapsedTimer sinceEmit_;
  QTimer pending_;  // flushes a live update that the interval held back
  uint64_t emittedRevision_ = 0;
  // The brush outline: last cursor position and the picked point under it.
  std::optional<QPointF> cursor_;
  std::optional<glm::vec3> picked_;
};

}  // namespace visopt::ws
