#include "tools/mask_paint_tool.h"

#include <algorithm>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>

namespace visopt::ws {

MaskPaintTool::MaskPaintTool(QObject* parent) : ViewportTool(parent) {
  pending_.setSingleShot(true);
  connect(&pending_, &QTimer::timeout, this, [this] {
    if (editor_.revision() != emittedRevision_) emitMask();
  });
  sinceEmit_.start();
}

void MaskPaintTool::setVolume(std::shared_ptr<const Volume> volume) {
  editor_.setVolume(std::move(volume));
}

void MaskPaintTool::setMask(const SessionMask& mask) {
  editor_.setMask(mask);
  emitMask();
  emit historyChanged(canUndo(), canRedo());
}

std::shared_ptr<const SessionMask> MaskPaintTool::mask() const {
  return std::make_shared<const SessionMask>(editor_.mask());
}

void MaskPaintTool::setRadius(float millimetres) {
  editor_.setRadius(millimetres);
  emit overlayChanged();
}

void MaskPaintTool::setMode(MaskEditor::Mode mode) {
  editor_.setMode(mode);
  emit overlayChanged();
}

void MaskPaintTool::setValueRange(std::optional<std::pair<double, double>> range) {
  editor_.setValueRange(range);
}

void MaskPaintTool::setUndoMemoryCap(size_t bytes) {
  editor_.setMemoryCap(bytes);
  emit historyChanged(canUndo(), canRedo());
}

void MaskPaintTool::bind(const ViewContext& view) {
  if (view.scene && view.scene->volume) {
    const uint64_t before = editor_.revision();
    const bool hadGrid = editor_.hasGrid();
    editor_.setVolume(view.scene->volume);
    // A new grid resets the mask: tell the listeners.
    if (hadGrid && editor_.revision() != before) {
      emitMask();
      emit historyChanged(canUndo(), canRedo());
    }
  }
}

void MaskPaintTool::hover(QPointF pos, const ViewContext& view) {
  cursor_ = pos;
  picked_ = pickWorldPoint(view, pos, pickOptions_);
  emit overlayChanged();
}

void MaskPaintTool::paintAt(QPointF pos, const ViewContext& view) {
  hover(pos, view);
  if (!editor_.stroking()) return;
  if (picked_)
    editor_.addStrokePoint(*picked_);
  else
    editor_.breakStroke();  // the cursor left the data: do not paint across the gap
  liveUpdate();
}

void MaskPaintTool::emitMask() {
  emittedRevision_ = editor_.revision();
  pending_.stop();
  sinceEmit_.restart();
  emit maskChanged(mask());
}

void MaskPaintTool::liveUpdate() {
  if (editor_.revision() == emittedRevision_) return;
  const qint64 elapsed = sinceEmit_.elapsed();
  if (elapsed >= liveIntervalMs_)
    emitMask();
  else if (!pending_.isActive())
    pending_.start(static_cast<int>(liveIntervalMs_ - elapsed));
}

bool MaskPaintTool::mousePress(QMouseEvent* event, const ViewContext& view) {
  if (event->button() != Qt::LeftButton) return false;
  bind(view);
  if (!editor_.hasGrid()) return false;
  const MaskEditor::Mode base = editor_.mode();
  if (event->modifiers() & Qt::ControlModifier)
    editor_.setMode(base == MaskEditor::Mode::Paint ? MaskEditor::Mode::Erase
                                                    : MaskEditor::Mode::Paint);
  editor_.beginStroke();
  editor_.setMode(base);  // the stroke keeps the mode it began with
  paintAt(event->position(), view);
  return true;
}

bool MaskPaintTool::mouseMove(QMouseEvent* event, const ViewContext& view) {
  if (editor_.stroking()) {
    paintAt(event->position(), view);
    return true;
  }
  hover(event->position(), view);
  return false;  // hovering: the viewport may use the move too
}

bool MaskPaintTool::mouseRelease(QMouseEvent* event, const ViewContext& view) {
  if (event->button() != Qt::LeftButton || !editor_.stroking()) return false;
  paintAt(event->position(), view);
  const bool changed = editor_.endStroke();
  if (changed || editor_.revision() != emittedRevision_) emitMask();
  emit historyChanged(canUndo(), canRedo());
  return true;
}

bool MaskPaintTool::keyPress(QKeyEvent* event, const ViewContext&) {
  if (event->key() == Qt::Key_Escape && editor_.stroking()) {
    cancelStroke();
    return true;
  }
  if (event->matches(QKeySequence::Undo)) {
    undo();
    return true;
  }
  if (event->matches(QKeySequence::Redo)) {
    redo();
    return true;
  }
  return false;
}

void MaskPaintTool::deactivate() {
  cancelStroke();
  cursor_.reset();
  picked_.reset();
  emit overlayChanged();
}

void MaskPaintTool::undo() {
  if (editor_.undo()) emitMask();
  emit historyChanged(canUndo(), canRedo());
}

void MaskPaintTool::redo() {
  if (editor_.redo()) emitMask();
  emit historyChanged(canUndo(), canRedo());
}

void MaskPaintTool::cancelStroke() {
  if (!editor_.stroking()) return;
  // Listeners that saw a live update must see the restored mask.
  if (editor_.cancelStroke()) emitMask();
  emit overlayChanged();
}

void MaskPaintTool::clear() {
  if (editor_.clear()) emitMask();
  emit historyChanged(canUndo(), canRedo());
}

void MaskPaintTool::paintOverlay(QPainter& painter, const ViewContext& view) {
  if (!cursor_) return;
  const bool erase =
      (editor_.stroking() ? editor_.strokeMode() : editor_.mode()) == MaskEditor::Mode::Erase;
  const QColor colour = erase ? QColor(255, 90, 90) : QColor(90, 255, 140);
  painter.save();
  painter.setRenderHint(QPainter::Antialiasing, true);
  painter.setBrush(Qt::NoBrush);
  double radiusPx = 0.0;
  if (picked_) {
    // The sphere's silhouette at the picked depth, approximated by its projected radius.
    radiusPx = static_cast<double>(editor_.radius()) * pixelsPerWorldUnit(view, *picked_);
    painter.setPen(QPen(colour, 1.5));
  } else {
    // Nothing under the cursor: a dashed fixed-size circle.
    radiusPx = 12.0;
    QPen pen(colour, 1.0, Qt::DashLine);
    painter.setPen(pen);
  }
  radiusPx = std::max(radiusPx, 2.0);
  painter.drawEllipse(*cursor_, radiusPx, radiusPx);
  painter.drawPoint(*cursor_);
  painter.restore();
}

}  // namespace visopt::ws
