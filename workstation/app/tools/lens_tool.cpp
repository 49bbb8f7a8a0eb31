#include "tools/lens_tool.h"

#include <algorithm>
#include <cmath>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QWheelEvent>

namespace visopt::ws {

QRectF lensOutline(const ImportanceLens& lens, QSize imageSize) {
  const double w = imageSize.width(), h = imageSize.height();
  const double cx = static_cast<double>(lens.x) * w, cy = static_cast<double>(lens.y) * h;
  const double rx = static_cast<double>(lens.radius) * w, ry = static_cast<double>(lens.radius) * h;
  return QRectF(cx - rx, cy - ry, 2.0 * rx, 2.0 * ry);
}

LensTool::LensTool(QObject* parent) : ViewportTool(parent) {}

ImportanceLens LensTool::lens() const {
  ImportanceLens lens;
  lens.x = x_;
  lens.y = y_;
  lens.radius = on_ ? radius_ : 0.f;
  lens.strength = strength_;
  return lens;
}

QPointF LensTool::normalisedPosition(QPointF widgetPos, QSize imageSize) {
  const double w = std::max(imageSize.width(), 1), h = std::max(imageSize.height(), 1);
  return QPointF(widgetPos.x() / w, widgetPos.y() / h);
}

void LensTool::changed() {
  emit lensChanged(lens());
  emit overlayChanged();
}

void LensTool::apply(float x, float y, float radius, float strength, bool on) {
  if (!std::isfinite(x) || !std::isfinite(y)) {
    x = x_;
    y = y_;
  }
  if (std::isfinite(radius))
    radius = std::clamp(radius, kMinRadius, kMaxRadius);
  else
    radius = radius_;
  if (std::isfinite(strength))
    strength = std::clamp(strength, 0.f, kMaxStrength);
  else
    strength = strength_;
  const ImportanceLens before = lens();
  x_ = x;
  y_ = y;
  radius_ = radius;
  strength_ = strength;
  on_ = on;
  const ImportanceLens after = lens();
  // A lens that is off does not change the optimisation wherever it is: no signal.
  if (after.x != before.x || after.y != before.y || after.radius != before.radius ||
      after.strength != before.strength) {
    if (on_ || before.radius > 0.f) changed();
  }
  emit overlayChanged();
}

void LensTool::setRadius(float radius) {
  apply(x_, y_, radius, strength_, on_);
}

void LensTool::setStrength(float strength) {
  apply(x_, y_, radius_, strength, on_);
}

void LensTool::setLensOn(bool on) {
  apply(x_, y_, radius_, strength_, on);
}

void LensTool::setCentre(QPointF normalised) {
  apply(static_cast<float>(normalised.x()), static_cast<float>(normalised.y()), radius_, strength_,
        on_);
}

bool LensTool::mousePress(QMouseEvent* event, const ViewContext& view) {
  if (event->button() != Qt::LeftButton) return false;
  const QPointF p = normalisedPosition(event->position(), view.imageSize);
  apply(static_cast<float>(p.x()), static_cast<float>(p.y()), radius_, strength_, !on_);
  return true;
}

bool LensTool::mouseMove(QMouseEvent* event, const ViewContext& view) {
  hovering_ = true;
  setCentre(normalisedPosition(event->position(), view.imageSize));
  // Orbiting with other buttons stays the viewport's; a left drag belongs to the lens.
  return (event->buttons() & Qt::LeftButton) != 0;
}

bool LensTool::wheel(QWheelEvent* event, const ViewContext& view) {
  // Some platforms turn Shift+wheel into a horizontal wheel.
  const QPoint delta = event->angleDelta();
  const double notches = (delta.y() != 0 ? delta.y() : delta.x()) / 120.0;
  if (notches == 0.0) return true;
  const QPointF p = normalisedPosition(event->position(), view.imageSize);
  float radius = radius_, strength = strength_;
  if (event->modifiers() & Qt::ShiftModifier)
    strength += static_cast<float>(notches) * kStrengthStepPerNotch;
  else
    radius *= static_cast<float>(std::pow(double(kRadiusFactorPerNotch), notches));
  apply(static_cast<float>(p.x()), static_cast<float>(p.y()), radius, strength, true);
  return true;
}

bool LensTool::keyPress(QKeyEvent* event, const ViewContext&) {
  if (event->key() == Qt::Key_Escape && on_) {
    switchOff();
    return true;
  }
  return false;
}

void LensTool::deactivate() {
  hovering_ = false;
  emit overlayChanged();
}

void LensTool::paintOverlay(QPainter& painter, const ViewContext& view) {
  if (!on_ || !hovering_) return;
  painter.save();
  painter.setRenderHint(QPainter::Antialiasing, true);
  painter.setBrush(Qt::NoBrush);
  // Boosting lenses in warm, hiding ones in cool colours.
  const QColor colour = strength_ >= 1.f ? QColor(255, 200, 60) : QColor(90, 170, 255);
  painter.setPen(QPen(colour, 1.5));
  painter.drawEllipse(lensOutline(lens(), view.imageSize));
  painter.setPen(QPen(colour, 1.0, Qt::DotLine));
  const QRectF inner = lensOutline(
      ImportanceLens{lens().x, lens().y, 0.9f * lens().radius, strength_}, view.imageSize);
  painter.drawEllipse(inner);  // the rim: weights blend over the outer 10 % of the radius
  painter.drawText(lensOutline(lens(), view.imageSize).bottomLeft() + QPointF(0.0, 14.0),
                   QString("x%1").arg(static_cast<double>(strength_), 0, 'f', 1));
  painter.restore();
}

}  // namespace visopt::ws
