// The ClearView hotspot (Krüger, Schneider, Westermann 2006; visopt/clearview.h): while the tool
// is active the view shows ClearView's image, whose context opens around the point under the
// cursor. The hotspot follows the cursor while no button is held (a drag orbits, pans or zooms
// the camera as in the other tools, and the hotspot stays where it was); the wheel scales its
// size by kFactorPerNotch per notch; Escape returns to the automatic size.
//
// The size is in world units; 0 means automatic (the library's choice from the focus point's
// depth). The first wheel notch from automatic starts at sizeStart(): half the scene's bounding
// radius (setSceneRadius), the size the library itself falls back to where it cannot measure the
// depth (a quarter of the radius does not reach the default scene's skull from the tumours under
// it, so the wheel's first notches would change nothing). The wheel keeps the size within
// [radius / 200, 4 radius].
#pragma once

#include <QPointF>

#include "viewport_tool.h"

namespace visopt::ws {

class HotspotTool : public ViewportTool {
  Q_OBJECT
 public:
  explicit HotspotTool(QObject* parent = nullptr);

  // Where the hotspot is, as a fraction of the image (x right, y down, in [0, 1]); (-1, -1)
  // before the cursor was over the view: the image centre.
  QPointF focus() const { return focus_; }
  // Hotspot radius in world units; 0: automatic.
  float size() const { return size_; }
  // The scene's bounding radius (world units): where the wheel starts and what it keeps to.
  void setSceneRadius(float radius);
  float sizeStart() const { return 0.5f * radius_; }
  float minSize() const { return 0.005f * radius_; }
  float maxSize() const { return 4.f * radius_; }
  bool active() const { return active_; }

  static constexpr float kFactorPerNotch = 1.1f;
  // A fraction of the widget (the viewport stretches the frame over all of it).
  static QPointF fractionOf(QPointF widgetPos, QSize widgetSize);

  bool mouseMove(QMouseEvent* event, const ViewContext& view) override;
  bool wheel(QWheelEvent* event, const ViewContext& view) override;
  bool keyPress(QKeyEvent* event, const ViewContext& view) override;
  void activate() override;
  void deactivate() override;
  void paintOverlay(QPainter& painter, const ViewContext& view) override;

 public slots:
  // Each emits its signal when the value changes.
  void setFocus(QPointF fraction);
  void setSize(float size);  // < 0 or not finite: 0 (automatic)

 signals:
  void focusChanged(QPointF fraction);
  void sizeChanged(float size);
  // The tool became the viewport's active tool (true) or stopped being it (false).
  void activeChanged(bool active);

 private:
  QPointF focus_{-1.0, -1.0};
  float size_ = 0.f;
  float radius_ = 1.f;
  bool active_ = false;
  bool hovering_ = false;
};

}  // namespace visopt::ws
