// A piecewise-linear curve editor drawn over a histogram: points (value in data units, y in
// [0, 1]), with an optional colour strip below for colour stops (value, rgb).
//
// Mouse, in the plot: a left click on empty space adds a point there (and keeps dragging it); a
// left drag on a point moves it (x clamped between its neighbours and to the visible range, y to
// [0, 1]); a right click on a point deletes it. In the colour strip the same gestures add, move
// (x only) and delete colour stops, and a double click on a stop picks its colour (QColorDialog
// unless a colour picker hook is set). Delete/Backspace deletes the selected point or stop,
// Escape clears the selection.
//
// Deleting never leaves fewer than minimumPointCount() curve points (default 1) or fewer than one
// colour stop: the library refuses empty point lists, and a single point is a constant curve.
//
// Outside the first/last point the curve is constant (the way TransferFunction::opacityAt and
// the importance curve extrapolate). Colours are shown as stored (no transfer to sRGB).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <QColor>
#include <QString>
#include <QWidget>
#include <glm/glm.hpp>

#include "widgets/histogram.h"

namespace visopt::ws {

struct ColorStop {
  double value = 0.0;
  glm::vec3 rgb{1.f};  // [0, 1]
};

class CurveEditor : public QWidget {
  Q_OBJECT

 public:
  // Returns the chosen colour, or nothing when cancelled.
  using ColorPicker = std::function<std::optional<QColor>(const QColor& current, QWidget* parent)>;

  explicit CurveEditor(QWidget* parent = nullptr);

  // The histogram behind the curve; it also sets the visible value range. Null clears it.
  void setHistogram(std::shared_ptr<const Histogram> histogram);
  const std::shared_ptr<const Histogram>& histogram() const { return histogram_; }
  // The visible value range when there is no histogram (a degenerate range is widened).
  void setValueRange(double lo, double hi);
  double valueMin() const { return valueMin_; }
  double valueMax() const { return valueMax_; }
  void setLogScale(bool on);
  bool logScale() const { return logScale_; }
  void setYName(const QString& name);  // "opacity", "importance": used in tooltips
  const QString& yName() const { return yName_; }

  // Curve points (x: value, y in [0, 1]); sorted by value on the way in. Do not emit.
  void setPoints(std::vector<glm::dvec2> points);
  const std::vector<glm::dvec2>& points() const { return points_; }
  void setMinimumPointCount(int n);
  int minimumPointCount() const { return minPoints_; }
  // Curve value at `value` (constant outside the points).
  double curveAt(double value) const;

  void setColorStripEnabled(bool on);
  bool colorStripEnabled() const { return colorStrip_; }
  void setColorStops(std::vector<ColorStop> stops);
  const std::vector<ColorStop>& colorStops() const { return stops_; }
  glm::vec3 colorAt(double value) const;
  void setColorPicker(ColorPicker picker);

  // Geometry, for drawing and for tests that click at computed positions.
  QRectF plotRect() const;
  QRectF stripRect() const;  // empty without the colour strip
  QPointF toWidget(double value, double y) const;
  double valueAtX(double px) const;
  double yAtY(double py) const;
  QPointF colorStopPosition(double value) const;  // centre of the strip at `value`
  // One pixel's worth in data units along x and in y.
  double valuePerPixel() const;
  double yPerPixel() const;

  // Selection: at most one curve point or colour stop; -1 when none.
  int selectedPoint() const { return sel_.kind == Kind::Curve ? sel_.index : -1; }
  int selectedColorStop() const { return sel_.kind == Kind::Color ? sel_.index : -1; }
  int hoveredPoint() const { return hover_.kind == Kind::Curve ? hover_.index : -1; }
  int hoveredColorStop() const { return hover_.kind == Kind::Color ? hover_.index : -1; }
  // The tooltip text shown at widget position `pos` (empty when none).
  QString toolTipTextAt(QPointF pos) const;

  QSize sizeHint() const override;
  QSize minimumSizeHint() const override;

 public slots:
  // Deletes the selected point or stop (respecting the minimum counts); true when one went.
  bool deleteSelected();

 signals:
  void pointsEdited();      // the user changed the curve points
  void colorStopsEdited();  // the user changed the colour stops

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;
  void leaveEvent(QEvent* event) override;

 private:
  enum class Kind { None, Curve, Color };
  struct Ref {
    Kind kind = Kind::None;
    int index = -1;
    bool operator==(const Ref&) const = default;
  };
  Ref hitTest(QPointF pos) const;
  void moveSelectedTo(QPointF pos);
  void emitFor(Kind kind);
  double clampValueForIndex(double value, Kind kind, int index) const;
  void drawHistogram(QPainter& p) const;
  void drawAxes(QPainter& p) const;
  void drawCurve(QPainter& p) const;
  void drawStrip(QPainter& p) const;

  std::shared_ptr<const Histogram> histogram_;
  double valueMin_ = 0.0;
  double valueMax_ = 1.0;
  bool logScale_ = false;
  QString yName_ = QStringLiteral("y");
  std::vector<glm::dvec2> points_;
  int minPoints_ = 1;
  bool colorStrip_ = false;
  std::vector<ColorStop> stops_;
  ColorPicker picker_;
  Ref sel_;
  Ref hover_;
  bool dragging_ = false;
  QPointF grabOffset_;  // point centre minus the press position, so a grabbed point never jumps
};

}  // namespace visopt::ws
