#include "widgets/curve_editor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <QColorDialog>
#include <QKeyEvent>
#include <QLinearGradient>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <QToolTip>

namespace visopt::ws {

namespace {

constexpr double kMarginLeft = 44.0;
constexpr double kMarginRight = 12.0;
constexpr double kMarginTop = 10.0;
constexpr double kAxisHeight = 20.0;
constexpr double kStripHeight = 18.0;
constexpr double kStripGap = 4.0;
constexpr double kPointRadius = 4.5;
constexpr double kPickRadius = 7.0;

// Ticks at 1, 2 or 5 times a power of ten, about `target` of them over [lo, hi].
std::vector<double> niceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  const double span = hi - lo;
  if (!(span > 0.0) || !std::isfinite(span)) return ticks;
  const double raw = span / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * span; t += step)
    ticks.push_back(std::abs(t) < 1e-12 * span ? 0.0 : t);
  return ticks;
}

QString formatValue(double v) {
  return QString::number(v, 'g', 6);
}

QColor toQColor(const glm::vec3& c) {
  return QColor::fromRgbF(std::clamp(c.r, 0.f, 1.f), std::clamp(c.g, 0.f, 1.f),
                          std::clamp(c.b, 0.f, 1.f));
}

}  // namespace

CurveEditor::CurveEditor(QWidget* parent) : QWidget(parent) {
  setMouseTracking(true);
  setFocusPolicy(Qt::ClickFocus);
  setAttribute(Qt::WA_OpaquePaintEvent);
  points_ = {{0.0, 0.0}, {1.0, 1.0}};
  stops_ = {{0.0, glm::vec3(0.f)}, {1.0, glm::vec3(1.f)}};
}

void CurveEditor::setHistogram(std::shared_ptr<const Histogram> histogram) {
  histogram_ = std::move(histogram);
  if (histogram_) setValueRange(histogram_->valueMin, histogram_->valueMax);
  update();
}

void CurveEditor::setValueRange(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return;
  if (hi < lo) std::swap(lo, hi);
  if (!(hi > lo)) {
    const double pad = std::max(0.5, std::abs(lo) * 0.5);
    lo -= pad;
    hi += pad;
  }
  valueMin_ = lo;
  valueMax_ = hi;
  update();
}

void CurveEditor::setLogScale(bool on) {
  logScale_ = on;
  update();
}

void CurveEditor::setYName(const QString& name) {
  yName_ = name;
}

void CurveEditor::setPoints(std::vector<glm::dvec2> points) {
  std::stable_sort(points.begin(), points.end(),
                   [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x; });
  points_ = std::move(points);
  if (sel_.kind == Kind::Curve) sel_ = {};
  if (hover_.kind == Kind::Curve) hover_ = {};
  dragging_ = false;
  update();
}

void CurveEditor::setMinimumPointCount(int n) {
  minPoints_ = std::max(n, 1);
}

double CurveEditor::curveAt(double value) const {
  if (points_.empty()) return 0.0;
  if (value <= points_.front().x) return points_.front().y;
  if (value >= points_.back().x) return points_.back().y;
  for (size_t i = 1; i < points_.size(); ++i) {
    const glm::dvec2& a = points_[i - 1];
    const glm::dvec2& b = points_[i];
    if (value <= b.x) {
      if (!(b.x > a.x)) return b.y;
      return a.y + (b.y - a.y) * (value - a.x) / (b.x - a.x);
    }
  }
  return points_.back().y;
}

void CurveEditor::setColorStripEnabled(bool on) {
  colorStrip_ = on;
  updateGeometry();
  update();
}

void CurveEditor::setColorStops(std::vector<ColorStop> stops) {
  std::stable_sort(stops.begin(), stops.end(),
                   [](const ColorStop& a, const ColorStop& b) { return a.value < b.value; });
  stops_ = std::move(stops);
  if (sel_.kind == Kind::Color) sel_ = {};
  if (hover_.kind == Kind::Color) hover_ = {};
  dragging_ = false;
  update();
}

glm::vec3 CurveEditor::colorAt(double value) const {
  if (stops_.empty()) return glm::vec3(1.f);
  if (value <= stops_.front().value) return stops_.front().rgb;
  if (value >= stops_.back().value) return stops_.back().rgb;
  for (size_t i = 1; i < stops_.size(); ++i) {
    const ColorStop& a = stops_[i - 1];
    const ColorStop& b = stops_[i];
    if (value <= b.value) {
      if (!(b.value > a.value)) return b.rgb;
      const auto f = static_cast<float>((value - a.value) / (b.value - a.value));
      return a.rgb + (b.rgb - a.rgb) * f;
    }
  }
  return stops_.back().rgb;
}

void CurveEditor::setColorPicker(ColorPicker picker) {
  picker_ = std::move(picker);
}

// ---- geometry ----

QRectF CurveEditor::plotRect() const {
  const double w = std::max(1.0, static_cast<double>(width()) - kMarginLeft - kMarginRight);
  const double below = kAxisHeight + (colorStrip_ ? kStripHeight + kStripGap : 0.0);
  const double h = std::max(1.0, static_cast<double>(height()) - kMarginTop - below);
  return {kMarginLeft, kMarginTop, w, h};
}

QRectF CurveEditor::stripRect() const {
  if (!colorStrip_) return {};
  const QRectF plot = plotRect();
  return {plot.left(), plot.bottom() + kStripGap, plot.width(), kStripHeight};
}

QPointF CurveEditor::toWidget(double value, double y) const {
  const QRectF r = plotRect();
  const double fx = (value - valueMin_) / (valueMax_ - valueMin_);
  return {r.left() + fx * r.width(), r.bottom() - y * r.height()};
}

double CurveEditor::valueAtX(double px) const {
  const QRectF r = plotRect();
  return valueMin_ + (px - r.left()) / r.width() * (valueMax_ - valueMin_);
}

double CurveEditor::yAtY(double py) const {
  const QRectF r = plotRect();
  return (r.bottom() - py) / r.height();
}

QPointF CurveEditor::colorStopPosition(double value) const {
  const QRectF s = stripRect();
  return {toWidget(value, 0.0).x(), s.center().y()};
}

double CurveEditor::valuePerPixel() const {
  return (valueMax_ - valueMin_) / plotRect().width();
}

double CurveEditor::yPerPixel() const {
  return 1.0 / plotRect().height();
}

QSize CurveEditor::sizeHint() const {
  return {420, colorStrip_ ? 220 : 190};
}

QSize CurveEditor::minimumSizeHint() const {
  return {200, colorStrip_ ? 120 : 96};
}

// ---- interaction ----

CurveEditor::Ref CurveEditor::hitTest(QPointF pos) const {
  Ref best;
  double bestDist = kPickRadius;
  const QRectF plot = plotRect().adjusted(-kPickRadius, -kPickRadius, kPickRadius, kPickRadius);
  if (plot.contains(pos)) {
    for (size_t i = 0; i < points_.size(); ++i) {
      const QPointF c = toWidget(points_[i].x, points_[i].y);
      const double d = std::hypot(c.x() - pos.x(), c.y() - pos.y());
      if (d <= bestDist) {
        bestDist = d;
        best = {Kind::Curve, static_cast<int>(i)};
      }
    }
  }
  if (colorStrip_ && stripRect().adjusted(0, -2, 0, 2).contains(pos)) {
    for (size_t i = 0; i < stops_.size(); ++i) {
      const double d = std::abs(toWidget(stops_[i].value, 0.0).x() - pos.x());
      if (d <= bestDist) {
        bestDist = d;
        best = {Kind::Color, static_cast<int>(i)};
      }
    }
  }
  return best;
}

double CurveEditor::clampValueForIndex(double value, Kind kind, int index) const {
  value = std::clamp(value, valueMin_, valueMax_);
  const auto i = static_cast<size_t>(index);
  const size_t n = kind == Kind::Curve ? points_.size() : stops_.size();
  const auto at = [&](size_t k) { return kind == Kind::Curve ? points_[k].x : stops_[k].value; };
  if (i > 0) value = std::max(value, at(i - 1));
  if (i + 1 < n) value = std::min(value, at(i + 1));
  return value;
}

void CurveEditor::moveSelectedTo(QPointF pos) {
  if (sel_.kind == Kind::Curve) {
    glm::dvec2& p = points_[static_cast<size_t>(sel_.index)];
    p.x = clampValueForIndex(valueAtX(pos.x()), Kind::Curve, sel_.index);
    p.y = std::clamp(yAtY(pos.y()), 0.0, 1.0);
  } else if (sel_.kind == Kind::Color) {
    ColorStop& s = stops_[static_cast<size_t>(sel_.index)];
    s.value = clampValueForIndex(valueAtX(pos.x()), Kind::Color, sel_.index);
  }
}

void CurveEditor::emitFor(Kind kind) {
  if (kind == Kind::Curve) emit pointsEdited();
  if (kind == Kind::Color) emit colorStopsEdited();
}

bool CurveEditor::deleteSelected() {
  if (sel_.kind == Kind::Curve && points_.size() > static_cast<size_t>(minPoints_)) {
    points_.erase(points_.begin() + sel_.index);
  } else if (sel_.kind == Kind::Color && stops_.size() > 1) {
    stops_.erase(stops_.begin() + sel_.index);
  } else {
    return false;
  }
  const Kind kind = sel_.kind;
  sel_ = {};
  hover_ = {};
  dragging_ = false;
  update();
  emitFor(kind);
  return true;
}

void CurveEditor::mousePressEvent(QMouseEvent* event) {
  const QPointF pos = event->position();
  const Ref hit = hitTest(pos);
  if (event->button() == Qt::RightButton) {
    if (hit.kind != Kind::None) {
      sel_ = hit;
      deleteSelected();
    }
    event->accept();
    return;
  }
  if (event->button() != Qt::LeftButton) return QWidget::mousePressEvent(event);
  event->accept();
  if (hit.kind != Kind::None) {
    sel_ = hit;
    dragging_ = true;
    const QPointF c = hit.kind == Kind::Curve
                          ? toWidget(points_[static_cast<size_t>(hit.index)].x,
                                     points_[static_cast<size_t>(hit.index)].y)
                          : colorStopPosition(stops_[static_cast<size_t>(hit.index)].value);
    grabOffset_ = c - pos;
    if (hit.kind == Kind::Color) grabOffset_.setY(0.0);
    update();
    return;
  }
  grabOffset_ = QPointF(0.0, 0.0);
  if (plotRect().contains(pos)) {
    const glm::dvec2 p(std::clamp(valueAtX(pos.x()), valueMin_, valueMax_),
                       std::clamp(yAtY(pos.y()), 0.0, 1.0));
    const auto it = std::upper_bound(points_.begin(), points_.end(), p.x,
                                     [](double v, const glm::dvec2& q) { return v < q.x; });
    const auto index = static_cast<int>(it - points_.begin());
    points_.insert(it, p);
    sel_ = {Kind::Curve, index};
    hover_ = sel_;
    dragging_ = true;
    update();
    emit pointsEdited();
  } else if (colorStrip_ && stripRect().contains(pos)) {
    const double v = std::clamp(valueAtX(pos.x()), valueMin_, valueMax_);
    const ColorStop s{v, colorAt(v)};
    const auto it = std::upper_bound(stops_.begin(), stops_.end(), v,
                                     [](double x, const ColorStop& q) { return x < q.value; });
    const auto index = static_cast<int>(it - stops_.begin());
    stops_.insert(it, s);
    sel_ = {Kind::Color, index};
    hover_ = sel_;
    dragging_ = true;
    update();
    emit colorStopsEdited();
  } else {
    sel_ = {};
    update();
  }
}

void CurveEditor::mouseMoveEvent(QMouseEvent* event) {
  const QPointF pos = event->position();
  if (dragging_ && sel_.kind != Kind::None) {  // dragging_ ends on the left release
    moveSelectedTo(pos + grabOffset_);
    hover_ = sel_;
    update();
    emitFor(sel_.kind);
  } else {
    const Ref h = hitTest(pos);
    if (!(h == hover_)) {
      hover_ = h;
      update();
    }
  }
  const QString tip = toolTipTextAt(pos);
  if (tip.isEmpty())
    QToolTip::hideText();
  else
    QToolTip::showText(event->globalPosition().toPoint(), tip, this);
}

void CurveEditor::mouseReleaseEvent(QMouseEvent* event) {
  if (event->button() == Qt::LeftButton) dragging_ = false;
  event->accept();
}

void CurveEditor::mouseDoubleClickEvent(QMouseEvent* event) {
  // The first press of a double click already added or selected; the second does not add again.
  event->accept();
  if (event->button() != Qt::LeftButton) return;
  const Ref hit = hitTest(event->position());
  if (hit.kind != Kind::Color) return;
  dragging_ = false;
  sel_ = hit;
  ColorStop& stop = stops_[static_cast<size_t>(hit.index)];
  const QColor current = toQColor(stop.rgb);
  std::optional<QColor> chosen;
  if (picker_) {
    chosen = picker_(current, this);
  } else {
    const QColor c = QColorDialog::getColor(current, this, tr("Colour at %1").arg(stop.value));
    if (c.isValid()) chosen = c;
  }
  // The stop may have gone while a modal dialog ran: look it up again.
  if (!chosen || !chosen->isValid() || hit.index >= static_cast<int>(stops_.size())) return;
  ColorStop& s = stops_[static_cast<size_t>(hit.index)];
  s.rgb = glm::vec3(static_cast<float>(chosen->redF()), static_cast<float>(chosen->greenF()),
                    static_cast<float>(chosen->blueF()));
  update();
  emit colorStopsEdited();
}

void CurveEditor::keyPressEvent(QKeyEvent* event) {
  if (event->key() == Qt::Key_Delete || event->key() == Qt::Key_Backspace) {
    deleteSelected();
    event->accept();
  } else if (event->key() == Qt::Key_Escape) {
    sel_ = {};
    update();
    event->accept();
  } else {
    QWidget::keyPressEvent(event);
  }
}

void CurveEditor::leaveEvent(QEvent* event) {
  hover_ = {};
  update();
  QWidget::leaveEvent(event);
}

QString CurveEditor::toolTipTextAt(QPointF pos) const {
  const Ref h = (dragging_ && sel_.kind != Kind::None) ? sel_ : hitTest(pos);
  if (h.kind == Kind::Curve) {
    const glm::dvec2& p = points_[static_cast<size_t>(h.index)];
    return tr("value %1\n%2 %3").arg(formatValue(p.x), yName_, formatValue(p.y));
  }
  if (h.kind == Kind::Color) {
    const ColorStop& s = stops_[static_cast<size_t>(h.index)];
    return tr("value %1\nrgb %2, %3, %4")
        .arg(formatValue(s.value), formatValue(s.rgb.r), formatValue(s.rgb.g),
             formatValue(s.rgb.b));
  }
  if (plotRect().contains(pos)) {
    const double v = valueAtX(pos.x());
    QString text = tr("value %1").arg(formatValue(v));
    if (histogram_ && histogram_->bins() > 0 && histogram_->binWidth() > 0.0) {
      const auto b =
          static_cast<int>(std::floor((v - histogram_->valueMin) / histogram_->binWidth()));
      if (b >= 0 && b < histogram_->bins())
        text += tr("\ncount %1").arg(histogram_->counts[static_cast<size_t>(b)], 0, 'f', 0);
    }
    return text;
  }
  return {};
}

// ---- drawing ----

void CurveEditor::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.fillRect(rect(), palette().color(QPalette::Window));
  const QRectF plot = plotRect();
  p.fillRect(plot, palette().color(QPalette::Base));
  drawHistogram(p);
  drawAxes(p);
  drawStrip(p);
  drawCurve(p);
  p.setPen(QPen(palette().color(QPalette::Mid), 1.0));
  p.setBrush(Qt::NoBrush);
  p.drawRect(plot);
  if (hasFocus()) {
    p.setPen(QPen(palette().color(QPalette::Highlight), 1.0, Qt::DotLine));
    p.drawRect(plot.adjusted(-1, -1, 1, 1));
  }
}

void CurveEditor::drawHistogram(QPainter& p) const {
  if (!histogram_ || histogram_->counts.empty()) return;
  const double maxCount = histogram_->maxCount();
  if (!(maxCount > 0.0)) return;
  const QRectF plot = plotRect();
  const double norm = logScale_ ? std::log1p(maxCount) : maxCount;
  QColor bar = palette().color(QPalette::Text);
  bar.setAlpha(60);
  p.save();
  p.setClipRect(plot);
  p.setPen(Qt::NoPen);
  p.setBrush(bar);
  const double w = histogram_->binWidth();
  for (size_t i = 0; i < histogram_->counts.size(); ++i) {
    const double c = histogram_->counts[i];
    if (!(c > 0.0)) continue;
    const double h = (logScale_ ? std::log1p(c) : c) / norm;
    const double lo = histogram_->valueMin + static_cast<double>(i) * w;
    const QPointF a = toWidget(lo, h);
    const QPointF b = toWidget(lo + w, 0.0);
    // At least a pixel wide so dense histograms stay visible.
    p.drawRect(QRectF(a, b).normalized().adjusted(0, 0, b.x() - a.x() < 1.0 ? 1.0 : 0.0, 0));
  }
  p.restore();
}

void CurveEditor::drawAxes(QPainter& p) const {
  const QRectF plot = plotRect();
  const QFontMetricsF fm(font());
  QColor grid = palette().color(QPalette::Mid);
  grid.setAlpha(90);
  const QColor text = palette().color(QPalette::WindowText);
  const double labelTop = colorStrip_ ? stripRect().bottom() : plot.bottom();
  const int target = std::max(2, static_cast<int>(plot.width() / 80.0));
  for (double t : niceTicks(valueMin_, valueMax_, target)) {
    const double x = toWidget(t, 0.0).x();
    p.setPen(QPen(grid, 1.0, Qt::DotLine));
    p.drawLine(QPointF(x, plot.top()), QPointF(x, plot.bottom()));
    p.setPen(text);
    const QString label = formatValue(t);
    const double lw = fm.horizontalAdvance(label);
    const double lx = std::clamp(x - lw / 2.0, 0.0, static_cast<double>(width()) - lw);
    p.drawText(QPointF(lx, labelTop + 2.0 + fm.ascent()), label);
  }
  for (double y : {0.0, 0.5, 1.0}) {
    const double py = toWidget(valueMin_, y).y();
    p.setPen(QPen(grid, 1.0, Qt::DotLine));
    p.drawLine(QPointF(plot.left(), py), QPointF(plot.right(), py));
    p.setPen(text);
    const QString label = formatValue(y);
    const double lw = fm.horizontalAdvance(label);
    const double ly = std::clamp(py + fm.ascent() / 2.0 - 1.0, fm.ascent(), plot.bottom());
    p.drawText(QPointF(plot.left() - 4.0 - lw, ly), label);
  }
}

void CurveEditor::drawCurve(QPainter& p) const {
  if (points_.empty()) return;
  const QRectF plot = plotRect();
  p.save();
  p.setRenderHint(QPainter::Antialiasing, true);
  p.setClipRect(
      plot.adjusted(-kPointRadius - 2, -kPointRadius - 2, kPointRadius + 2, kPointRadius + 2));
  QPainterPath line;
  line.moveTo(QPointF(plot.left(), toWidget(valueMin_, points_.front().y).y()));
  for (const glm::dvec2& q : points_) line.lineTo(toWidget(q.x, q.y));
  line.lineTo(QPointF(plot.right(), toWidget(valueMin_, points_.back().y).y()));
  // Fill under the curve: with the colour stops when there are some, else a plain tint.
  QPainterPath area = line;
  area.lineTo(plot.bottomRight());
  area.lineTo(plot.bottomLeft());
  area.closeSubpath();
  QBrush fill;
  if (colorStrip_ && !stops_.empty()) {
    QLinearGradient g(plot.topLeft(), plot.topRight());
    constexpr int kSamples = 64;
    for (int i = 0; i <= kSamples; ++i) {
      const double f = static_cast<double>(i) / kSamples;
      QColor c = toQColor(colorAt(valueMin_ + f * (valueMax_ - valueMin_)));
      c.setAlpha(120);
      g.setColorAt(f, c);
    }
    fill = QBrush(g);
  } else {
    QColor c = palette().color(QPalette::Highlight);
    c.setAlpha(50);
    fill = QBrush(c);
  }
  {
    p.save();
    p.setClipRect(plot);
    p.fillPath(area, fill);
    p.restore();
  }
  p.setPen(QPen(palette().color(QPalette::Text), 1.5));
  p.setBrush(Qt::NoBrush);
  p.drawPath(line);
  const QColor highlight = palette().color(QPalette::Highlight);
  for (size_t i = 0; i < points_.size(); ++i) {
    const Ref me{Kind::Curve, static_cast<int>(i)};
    const bool selected = sel_ == me;
    const bool hovered = hover_ == me;
    const double r = selected || hovered ? kPointRadius + 1.5 : kPointRadius;
    p.setPen(QPen(hovered || selected ? highlight : palette().color(QPalette::Text), 1.5));
    p.setBrush(selected ? QBrush(highlight) : QBrush(palette().color(QPalette::Base)));
    p.drawEllipse(toWidget(points_[i].x, points_[i].y), r, r);
  }
  p.restore();
}

void CurveEditor::drawStrip(QPainter& p) const {
  if (!colorStrip_) return;
  const QRectF s = stripRect();
  QLinearGradient g(s.topLeft(), s.topRight());
  constexpr int kSamples = 128;
  for (int i = 0; i <= kSamples; ++i) {
    const double f = static_cast<double>(i) / kSamples;
    g.setColorAt(f, toQColor(colorAt(valueMin_ + f * (valueMax_ - valueMin_))));
  }
  p.fillRect(s, QBrush(g));
  p.setPen(QPen(palette().color(QPalette::Mid), 1.0));
  p.setBrush(Qt::NoBrush);
  p.drawRect(s);
  p.save();
  p.setRenderHint(QPainter::Antialiasing, true);
  p.setClipRect(s.adjusted(-6, -2, 6, 2));
  const QColor highlight = palette().color(QPalette::Highlight);
  for (size_t i = 0; i < stops_.size(); ++i) {
    const Ref me{Kind::Color, static_cast<int>(i)};
    const bool selected = sel_ == me;
    const bool hovered = hover_ == me;
    const double x = toWidget(stops_[i].value, 0.0).x();
    const double hw = selected || hovered ? 5.0 : 4.0;
    const QRectF marker(x - hw, s.top() + 1.0, 2.0 * hw, s.height() - 2.0);
    p.setBrush(toQColor(stops_[i].rgb));
    p.setPen(QPen(selected || hovered ? highlight : palette().color(QPalette::Text),
                  selected ? 2.5 : 1.2));
    p.drawRect(marker);
  }
  p.restore();
}

}  // namespace visopt::ws
