#include "tools/hotspot_tool.h"

#include <algorithm>
#include <cmath>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QWheelEvent>

namespace visopt::ws {

HotspotTool::HotspotTool(QObject* parent) : ViewportTool(parent) {}

QPointF HotspotTool::fractionOf(QPointF widgetPos, QSize widgetSize) {
  const double w = std::max(widgetSize.width(), 1), h = std::max(widgetSize.height(), 1);
  return {std::clamp(widgetPos.x() / w, 0.0, 1.0), std::clamp(widgetPos.y() / h, 0.0, 1.0)};
}

void HotspotTool::setSceneRadius(float radius) {
  if (std::isfinite(radius) && radius > 0.f) radius_ = radius;
}

void HotspotTool::setFocus(QPointF fraction) {
  if (!std::isfinite(fraction.x()) || !std::isfinite(fraction.y()) || fraction == focus_) return;
  focus_ = fraction;
  emit focusChanged(focus_);
  emit overlayChanged();
}

void HotspotTool::setSize(float size) {
  if (!std::isfinite(size) || size < 0.f) size = 0.f;
  if (size == size_) return;
  size_ = size;
  emit sizeChanged(size_);
  emit overlayChanged();
}

bool HotspotTool::mouseMove(QMouseEvent* event, const ViewContext& view) {
  hovering_ = true;
  // A drag belongs to the camera: the hotspot stays where the drag began.
  if (event->buttons() == Qt::NoButton) setFocus(fractionOf(event->position(), view.imageSize));
  return false;
}

bool HotspotTool::wheel(QWheelEvent* event, const ViewContext&) {
  const QPoint delta = event->angleDelta();
  const double notches = (delta.y() != 0 ? delta.y() : delta.x()) / 120.0;
  if (notches == 0.0) return true;
  const float from = size_ > 0.f ? size_ : sizeStart();
  const float next = from * static_cast<float>(std::pow(double(kFactorPerNotch), notches));
  setSize(std::clamp(next, minSize(), maxSize()));
  return true;
}

bool HotspotTool::keyPress(QKeyEvent* event, const ViewContext&) {
  if (event->key() == Qt::Key_Escape && size_ > 0.f) {
    setSize(0.f);
    return true;
  }
  return false;
}

void HotspotTool::activate() {
  active_ = true;
  emit activeChanged(true);
}

void HotspotTool::deactivate() {
  hovering_ = false;
  active_ = false;
  emit activeChanged(false);
  emit overlayChanged();
}

void HotspotTool::paintOverlay(QPainter& painter, const ViewContext& view) {
  if (!hovering_ || focus_.x() < 0.0) return;
  // A small cross where the hotspot is (the image itself shows the opening) and its size.
  const QPointF c(focus_.x() * view.imageSize.width(), focus_.y() * view.imageSize.height());
  painter.save();
  painter.setRenderHint(QPainter::Antialiasing, true);
  painter.setPen(QPen(QColor(255, 214, 90, 200), 1.2));
  painter.drawLine(c + QPointF(-7, 0), c + QPointF(-3, 0));
  painter.drawLine(c + QPointF(3, 0), c + QPointF(7, 0));
  painter.drawLine(c + QPointF(0, -7), c + QPointF(0, -3));
  painter.drawLine(c + QPointF(0, 3), c + QPointF(0, 7));
  const QString label =
      size_ > 0.f ? QString::number(double(size_), 'g', 3) : QStringLiteral("auto");
  painter.drawText(c + QPointF(9.0, 16.0), label);
  painter.restore();
}

}  // namespace visopt::ws
