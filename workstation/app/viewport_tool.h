// A tool that takes over the viewport's mouse and keys while it is active (mask brush, lens,
// window mask). The viewport offers each event to the active tool first and orbits, pans or
// zooms only when the tool leaves the event alone.
#pragma once

#include <memory>

#include <QObject>
#include <QSize>

#include <visopt/camera.h>

#include "scene_snapshot.h"

class QKeyEvent;
class QMouseEvent;
class QPainter;
class QWheelEvent;

namespace visopt::ws {

// What a tool needs to map the cursor into the scene. The rendered image fills `imageSize`
// (widget pixels, origin top left) with the camera's vertical field of view and the aspect
// ratio imageSize.width() / imageSize.height().
struct ViewContext {
  Camera camera;
  QSize imageSize;
  std::shared_ptr<const SceneSnapshot> scene;
};

class ViewportTool : public QObject {
  Q_OBJECT
 public:
  using QObject::QObject;
  ~ViewportTool() override = default;
  // Each returns true when it used the event.
  virtual bool mousePress(QMouseEvent*, const ViewContext&) { return false; }
  virtual bool mouseMove(QMouseEvent*, const ViewContext&) { return false; }
  virtual bool mouseRelease(QMouseEvent*, const ViewContext&) { return false; }
  virtual bool wheel(QWheelEvent*, const ViewContext&) { return false; }
  virtual bool keyPress(QKeyEvent*, const ViewContext&) { return false; }
  // Called when the tool becomes the active one (the hotspot turns ClearView on).
  virtual void activate() {}
  // Called when the tool stops being the active one (a stroke in progress is cancelled).
  virtual void deactivate() {}
  // Draws the tool's overlay (brush outline, lens circle) over the image.
  virtual void paintOverlay(QPainter&, const ViewContext&) {}

 signals:
  void overlayChanged();  // the viewport should repaint
};

}  // namespace visopt::ws
