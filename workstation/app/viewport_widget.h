// The viewport: shows the engine's latest frame scaled to the widget, navigates the camera with
// the mouse (left drag orbit, middle or Shift+left drag pan, right drag or wheel zoom, R resets
// the view) and hands events to the active tool first. It measures the latency from each
// camera change to the frame that shows it.
#pragma once

#include <deque>
#include <map>

#include <QElapsedTimer>
#include <QImage>
#include <QPointer>
#include <QTimer>
#include <QWidget>

#include "engine_controller.h"
#include "viewport_tool.h"

namespace visopt::ws {

struct LatencyStats {
  int samples = 0;
  double lastMs = 0.0, meanMs = 0.0, maxMs = 0.0, p95Ms = 0.0;
  double renderMeanMs = 0.0;  // of those previews' renders: the rest of the latency is waiting
};

class ViewportWidget : public QWidget {
  Q_OBJECT
 public:
  explicit ViewportWidget(EngineController* controller, QWidget* parent = nullptr);

  void setTool(ViewportTool* tool);  // nullptr: navigation only
  ViewportTool* tool() const { return tool_; }
  // The camera the UI holds (the engine follows it).
  const Camera& camera() const { return camera_; }
  void setCamera(const Camera& camera, bool interacting = false);
  // The view a newly loaded scene came with; "reset view" returns to it.
  void setHomeCamera(const Camera& camera);
  void resetView();
  ViewContext viewContext() const;
  const QImage& frame() const { return frame_; }
  bool framePreview() const { return framePreview_; }
  LatencyStats previewLatency() const;  // drag -> preview frame on screen
  double framesPerSecond() const;
  QSize sizeHint() const override { return {640, 640}; }

 signals:
  void frameShown(const visopt::ws::FrameInfo& info);
  void cameraChanged(const visopt::Camera& camera);

 protected:
  void paintEvent(QPaintEvent*) override;
  void resizeEvent(QResizeEvent*) override;
  void mousePressEvent(QMouseEvent*) override;
  void mouseMoveEvent(QMouseEvent*) override;
  void mouseReleaseEvent(QMouseEvent*) override;
  void wheelEvent(QWheelEvent*) override;
  void keyPressEvent(QKeyEvent*) override;

 private:
  void onFrame(const QImage& image, const FrameInfo& info);
  float sceneRadius() const;

  QPointer<EngineController> controller_;
  QPointer<ViewportTool> tool_;
  Camera camera_, home_;
  QImage frame_;
  bool framePreview_ = false;
  enum class Drag { None, Orbit, Pan, Zoom } drag_ = Drag::None;
  QPoint lastPos_;
  QElapsedTimer clock_;
  QTimer restTimer_;  // after wheel zooming: full resolution once the wheel stops
  std::map<uint64_t, qint64> cameraSentAt_;  // serial -> ms, for latency
  std::deque<double> latencies_;             // ms, most recent last
  std::deque<double> previewRenderMs_;       // the matched previews' render times
  std::deque<qint64> frameTimes_;            // ms of recent frames
};

}  // namespace visopt::ws
