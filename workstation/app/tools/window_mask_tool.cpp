#include "tools/window_mask_tool.h"

#include <algorithm>
#include <cmath>

#include <QImage>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>

namespace visopt::ws {

WindowMaskTool::WindowMaskTool(QObject* parent) : ViewportTool(parent) {
  coverage_.assign(static_cast<size_t>(width_) * static_cast<size_t>(height_), 0.f);
  pending_.setSingleShot(true);
  connect(&pending_, &QTimer::timeout, this, [this] {
    if (dirty_) publish();
  });
  sinceEmit_.start();
}

void WindowMaskTool::setRasterSize(int width, int height) {
  width = std::max(width, 1);
  height = std::max(height, 1);
  if (width == width_ && height == height_) return;
  cancelStroke();
  width_ = width;
  height_ = height;
  coverage_.assign(static_cast<size_t>(width_) * static_cast<size_t>(height_), 0.f);
  publish();
  emit overlayChanged();
}

void WindowMaskTool::setSemantics(Semantics semantics) {
  if (semantics == semantics_) return;
  semantics_ = semantics;
  if (!empty()) publish();
  emit overlayChanged();
}

bool WindowMaskTool::empty() const {
  return std::all_of(coverage_.begin(), coverage_.end(), [](float c) { return c <= 0.f; });
}

std::vector<float> WindowMaskTool::weights() const {
  std::vector<float> w(coverage_.size());
  for (size_t i = 0; i < w.size(); ++i)
    w[i] = semantics_ == Semantics::PaintMasks ? 1.f - coverage_[i] : coverage_[i];
  return w;
}

void WindowMaskTool::dab(QPointF widgetPos, QSize imageSize, bool add) {
  if (imageSize.isEmpty()) return;
  // Work in widget pixels; cell (i, j) has its centre at ((i + 0.5) W / w, (j + 0.5) H / h).
  const double cellW = double(imageSize.width()) / width_;
  const double cellH = double(imageSize.height()) / height_;
  const double r = brushRadius_, inner = r * (1.0 - softness_);
  const int i0 = std::max(0, static_cast<int>(std::floor((widgetPos.x() - r) / cellW)));
  const int i1 = std::min(width_ - 1, static_cast<int>(std::ceil((widgetPos.x() + r) / cellW)));
  const int j0 = std::max(0, static_cast<int>(std::floor((widgetPos.y() - r) / cellH)));
  const int j1 = std::min(height_ - 1, static_cast<int>(std::ceil((widgetPos.y() + r) / cellH)));
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const double dx = (i + 0.5) * cellW - widgetPos.x(), dy = (j + 0.5) * cellH - widgetPos.y();
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d >= r) continue;
      const double f = d <= inner ? 1.0 : (r - d) / std::max(r - inner, 1e-9);
      const float s = static_cast<float>(f * f * (3.0 - 2.0 * f));  // smoothstep fall-off
      float& c =
          coverage_[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i)];
      // Max/min blending: going over the same place again does not accumulate.
      c = add ? std::max(c, s) : std::min(c, 1.f - s);
    }
  dirty_ = true;
}

void WindowMaskTool::fillRect(QRectF widgetRect, QSize imageSize, bool add) {
  if (imageSize.isEmpty()) return;
  const QRectF r = widgetRect.normalized();
  const double cellW = double(imageSize.width()) / width_;
  const double cellH = double(imageSize.height()) / height_;
  for (int j = 0; j < height_; ++j)
    for (int i = 0; i < width_; ++i) {
      const QPointF centre((i + 0.5) * cellW, (j + 0.5) * cellH);
      if (centre.x() < r.left() || centre.x() > r.right() || centre.y() < r.top() ||
          centre.y() > r.bottom())
        continue;
      coverage_[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i)] =
          add ? 1.f : 0.f;
    }
  dirty_ = true;
}

void WindowMaskTool::segment(QPointF from, QPointF to, QSize imageSize, bool add) {
  // Dabs a quarter of the radius apart: no gaps however fast the drag.
  const QPointF d = to - from;
  const double length = std::hypot(d.x(), d.y());
  const int steps = std::max(1, static_cast<int>(std::ceil(length / (0.25 * brushRadius_))));
  for (int s = 1; s <= steps; ++s) dab(from + d * (double(s) / steps), imageSize, add);
}

void WindowMaskTool::publish() {
  dirty_ = false;
  pending_.stop();
  sinceEmit_.restart();
  if (empty()) {
    if (!wasEmpty_) emit windowMaskCleared();
    wasEmpty_ = true;
    return;
  }
  wasEmpty_ = false;
  emit windowMaskChanged(weights(), width_, height_);
}

void WindowMaskTool::liveUpdate() {
  emit overlayChanged();
  if (!dirty_) return;
  const qint64 elapsed = sinceEmit_.elapsed();
  if (elapsed >= 100)
    publish();
  else if (!pending_.isActive())
    pending_.start(static_cast<int>(100 - elapsed));
}

bool WindowMaskTool::mousePress(QMouseEvent* event, const ViewContext& view) {
  if (event->button() != Qt::LeftButton) return false;
  before_ = coverage_;
  adding_ = !(event->modifiers() & Qt::ControlModifier);
  start_ = last_ = event->position();
  cursor_ = event->position();
  if (event->modifiers() & Qt::ShiftModifier) {
    drag_ = Drag::Rect;
    emit overlayChanged();
  } else {
    drag_ = Drag::Brush;
    dab(start_, view.imageSize, adding_);
    liveUpdate();
  }
  return true;
}

bool WindowMaskTool::mouseMove(QMouseEvent* event, const ViewContext& view) {
  cursor_ = event->position();
  if (drag_ == Drag::Brush) {
    segment(last_, event->position(), view.imageSize, adding_);
    last_ = event->position();
    liveUpdate();
    return true;
  }
  last_ = event->position();
  emit overlayChanged();
  return drag_ == Drag::Rect;
}

bool WindowMaskTool::mouseRelease(QMouseEvent* event, const ViewContext& view) {
  if (event->button() != Qt::LeftButton || drag_ == Drag::None) return false;
  if (drag_ == Drag::Brush) {
    segment(last_, event->position(), view.imageSize, adding_);
  } else {
    fillRect(QRectF(start_, event->position()), view.imageSize, adding_);
  }
  drag_ = Drag::None;
  before_.clear();
  publish();
  emit overlayChanged();
  return true;
}

bool WindowMaskTool::keyPress(QKeyEvent* event, const ViewContext&) {
  if (event->key() == Qt::Key_Escape && drag_ != Drag::None) {
    cancelStroke();
    return true;
  }
  return false;
}

void WindowMaskTool::cancelStroke() {
  if (drag_ == Drag::None) return;
  drag_ = Drag::None;
  if (before_.size() == coverage_.size()) coverage_ = before_;
  before_.clear();
  // Listeners may have seen a live update of the cancelled stroke.
  publish();
  emit overlayChanged();
}

void WindowMaskTool::deactivate() {
  cancelStroke();
  cursor_.reset();
  emit overlayChanged();
}

void WindowMaskTool::clear() {
  cancelStroke();
  std::fill(coverage_.begin(), coverage_.end(), 0.f);
  publish();
  emit overlayChanged();
}

void WindowMaskTool::paintOverlay(QPainter& painter, const ViewContext& view) {
  if (view.imageSize.isEmpty()) return;
  painter.save();
  if (!empty()) {
    // Masked pixels tinted blue (what keeps its context), at most half opaque.
    QImage image(width_, height_, QImage::Format_ARGB32_Premultiplied);
    for (int j = 0; j < height_; ++j) {
      auto* line = reinterpret_cast<QRgb*>(image.scanLine(j));
      for (int i = 0; i < width_; ++i) {
        const float c = coverage_[static_cast<size_t>(j) * static_cast<size_t>(width_) +
                                  static_cast<size_t>(i)];
        const float masked = semantics_ == Semantics::PaintMasks ? c : 1.f - c;
        const int a = static_cast<int>(std::lround(120.0 * static_cast<double>(masked)));
        line[i] = qPremultiply(qRgba(60, 140, 255, a));
      }
    }
    painter.setRenderHint(QPainter::SmoothPixmapTransform, true);
    painter.drawImage(QRectF(QPointF(0, 0), QSizeF(view.imageSize)), image);
  }
  painter.setRenderHint(QPainter::Antialiasing, true);
  painter.setBrush(Qt::NoBrush);
  const QColor colour = adding_ || drag_ == Drag::None ? QColor(60, 140, 255) : QColor(255, 90, 90);
  painter.setPen(QPen(colour, 1.5));
  if (drag_ == Drag::Rect) {
    painter.drawRect(QRectF(start_, last_).normalized());
  } else if (cursor_) {
    painter.drawEllipse(*cursor_, brushRadius_, brushRadius_);
  }
  painter.restore();
}

}  // namespace visopt::ws
