// The importance lens (Himmler & Günther 2026, §III-F): while the tool is active the lens follows
// the cursor; the wheel changes its radius, Shift+wheel its strength; a left click or Escape
// switches it off (radius 0), a left click or the wheel switches it on again. lensChanged is
// emitted once per change of the effective lens, not while a switched-off lens follows the cursor.
#pragma once

#include <QPointF>
#include <QRectF>
#include <QSize>

#include <visopt/optimization.h>

#include "viewport_tool.h"

namespace visopt::ws {

// The lens's outline in widget pixels, as the optimiser weighs the rays (ScreenWeights): the
// distance is taken in normalised image coordinates per axis, so the semi-axes are
// radius * width and radius * height (a circle on a square image).
QRectF lensOutline(const ImportanceLens& lens, QSize imageSize);

class LensTool : public ViewportTool {
  Q_OBJECT
 public:
  explicit LensTool(QObject* parent = nullptr);

  // The current lens (radius 0 when switched off).
  ImportanceLens lens() const;
  bool lensOn() const { return on_; }
  // Radius (fraction of the image width) and strength used while the lens is on.
  float radius() const { return radius_; }
  float strength() const { return strength_; }
  void setRadius(float radius);      // clamped to [kMinRadius, kMaxRadius]
  void setStrength(float strength);  // clamped to [0, kMaxStrength]
  // Lens centre from a widget position: (x / width, y / height), y down.
  static QPointF normalisedPosition(QPointF widgetPos, QSize imageSize);

  static constexpr float kMinRadius = 0.01f, kMaxRadius = 1.f, kMaxStrength = 8.f;
  static constexpr float kRadiusFactorPerNotch = 1.1f, kStrengthStepPerNotch = 0.1f;

  bool mousePress(QMouseEvent* event, const ViewContext& view) override;
  bool mouseMove(QMouseEvent* event, const ViewContext& view) override;
  bool wheel(QWheelEvent* event, const ViewContext& view) override;
  bool keyPress(QKeyEvent* event, const ViewContext& view) override;
  // The lens stays where it is (it stops following the cursor).
  void deactivate() override;
  void paintOverlay(QPainter& painter, const ViewContext& view) override;

 public slots:
  void setLensOn(bool on);
  void switchOff() { setLensOn(false); }
  // Moves the lens centre (normalised image coordinates, y down).
  void setCentre(QPointF normalised);

 signals:
  void lensChanged(visopt::ImportanceLens lens);

 private:
  void changed();
  // Sets the whole state and emits lensChanged once when the effective lens changed.
  void apply(float x, float y, float radius, float strength, bool on);

  float x_ = 0.5f, y_ = 0.5f;
  float radius_ = 0.15f, strength_ = ImportanceLens{}.strength;
  bool on_ = true;
  bool hovering_ = false;
};

}  // namespace visopt::ws
