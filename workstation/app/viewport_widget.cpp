#include "viewport_widget.h"

#include <algorithm>
#include <cmath>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QWheelEvent>

#include "camera_navigation.h"

namespace visopt::ws {

ViewportWidget::ViewportWidget(EngineController* controller, QWidget* parent)
    : QWidget(parent), controller_(controller) {
  setFocusPolicy(Qt::StrongFocus);
  setMouseTracking(true);
  setAttribute(Qt::WA_OpaquePaintEvent);
  setMinimumSize(200, 200);
  clock_.start();
  restTimer_.setSingleShot(true);
  restTimer_.setInterval(250);
  connect(&restTimer_, &QTimer::timeout, this, [this] {
    if (drag_ == Drag::None) setCamera(camera_, false);
  });
  connect(controller, &EngineController::frameReady, this, &ViewportWidget::onFrame);
}

void ViewportWidget::setTool(ViewportTool* tool) {
  if (tool_ == tool) return;
  if (tool_) {
    tool_->deactivate();
    disconnect(tool_, nullptr, this, nullptr);
  }
  tool_ = tool;
  if (tool_) {
    connect(tool_, &ViewportTool::overlayChanged, this, qOverload<>(&QWidget::update));
    tool_->activate();
  }
  update();
}

void ViewportWidget::setCamera(const Camera& camera, bool interacting) {
  camera_ = camera;
  const uint64_t serial = controller_->setCamera(camera, interacting);
  cameraSentAt_[serial] = clock_.elapsed();
  while (cameraSentAt_.size() > 256) cameraSentAt_.erase(cameraSentAt_.begin());
  emit cameraChanged(camera_);
  update();
}

void ViewportWidget::setHomeCamera(const Camera& camera) {
  home_ = camera;
  camera_ = camera;
}

void ViewportWidget::resetView() {
  setCamera(home_, false);
}

ViewContext ViewportWidget::viewContext() const {
  return {camera_, size(), controller_ ? controller_->snapshot() : nullptr};
}

float ViewportWidget::sceneRadius() const {
  const auto snap = controller_ ? controller_->snapshot() : nullptr;
  if (!snap || !snap->volume) return 1.f;
  return std::max(0.5f * glm::length(snap->volume->grid().worldBounds().size()), 1e-3f);
}

void ViewportWidget::onFrame(const QImage& image, const FrameInfo& info) {
  frame_ = image;
  framePreview_ = info.preview;
  const qint64 now = clock_.elapsed();
  auto it = cameraSentAt_.find(info.cameraSerial);
  if (it != cameraSentAt_.end()) {
    // The first preview showing a drag: that is the latency the user feels.
    if (info.preview) {
      latencies_.push_back(double(now - it->second));
      previewRenderMs_.push_back(info.renderMs);
    }
    while (latencies_.size() > 200) latencies_.pop_front();
    while (previewRenderMs_.size() > 200) previewRenderMs_.pop_front();
    cameraSentAt_.erase(cameraSentAt_.begin(), std::next(it));
  }
  frameTimes_.push_back(now);
  while (frameTimes_.size() > 30) frameTimes_.pop_front();
  update();
  emit frameShown(info);
}

LatencyStats ViewportWidget::previewLatency() const {
  LatencyStats s;
  s.samples = int(latencies_.size());
  if (latencies_.empty()) return s;
  std::vector<double> v(latencies_.begin(), latencies_.end());
  s.lastMs = v.back();
  double sum = 0.0;
  for (double x : v) sum += x;
  s.meanMs = sum / double(v.size());
  double render = 0.0;
  for (double x : previewRenderMs_) render += x;
  s.renderMeanMs = previewRenderMs_.empty() ? 0.0 : render / double(previewRenderMs_.size());
  std::sort(v.begin(), v.end());
  s.maxMs = v.back();
  s.p95Ms = v[std::min(v.size() - 1, size_t(std::ceil(0.95 * double(v.size()))) - 1)];
  return s;
}

double ViewportWidget::framesPerSecond() const {
  if (frameTimes_.size() < 2) return 0.0;
  const double span = double(frameTimes_.back() - frameTimes_.front());
  return span > 0.0 ? 1000.0 * double(frameTimes_.size() - 1) / span : 0.0;
}

void ViewportWidget::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.fillRect(rect(), QColor(15, 17, 19));
  if (!frame_.isNull()) {
    p.setRenderHint(QPainter::SmoothPixmapTransform, true);
    p.drawImage(rect(), frame_);
  } else {
    p.setPen(QColor(170, 170, 170));
    p.drawText(rect(), Qt::AlignCenter,
               tr("Open a volume, a DICOM folder, a built-in scene or a session (File menu)"));
  }
  if (tool_) tool_->paintOverlay(p, viewContext());
}

void ViewportWidget::resizeEvent(QResizeEvent*) {
  const qreal dpr = devicePixelRatioF();
  controller_->setViewportSize(int(std::lround(width() * dpr)), int(std::lround(height() * dpr)));
}

void ViewportWidget::mousePressEvent(QMouseEvent* e) {
  setFocus();
  if (tool_ && tool_->mousePress(e, viewContext())) return;
  lastPos_ = e->position().toPoint();
  if (e->button() == Qt::LeftButton)
    drag_ = (e->modifiers() & Qt::ShiftModifier) ? Drag::Pan : Drag::Orbit;
  else if (e->button() == Qt::MiddleButton)
    drag_ = Drag::Pan;
  else if (e->button() == Qt::RightButton)
    drag_ = Drag::Zoom;
}

void ViewportWidget::mouseMoveEvent(QMouseEvent* e) {
  if (tool_ && tool_->mouseMove(e, viewContext())) return;
  if (drag_ == Drag::None) return;
  const QPoint pos = e->position().toPoint();
  const QPoint d = pos - lastPos_;
  lastPos_ = pos;
  const float h = float(std::max(1, height()));
  Camera next = camera_;
  switch (drag_) {
    case Drag::Orbit:
      next = orbitCamera(camera_, 180.f * float(d.x()) / h, 180.f * float(d.y()) / h);
      break;
    case Drag::Pan:
      next = panCamera(camera_, {float(d.x()) / h, float(d.y()) / h});
      break;
    case Drag::Zoom: {
      const float r = sceneRadius();
      next = zoomCamera(camera_, std::exp(-2.f * float(d.y()) / h), 0.05f * r, 50.f * r);
      break;
    }
    case Drag::None:
      break;
  }
  setCamera(next, true);
}

void ViewportWidget::mouseReleaseEvent(QMouseEvent* e) {
  if (tool_ && tool_->mouseRelease(e, viewContext())) return;
  if (drag_ != Drag::None) {
    drag_ = Drag::None;
    setCamera(camera_, false);  // the camera rests: full resolution
  }
}

void ViewportWidget::wheelEvent(QWheelEvent* e) {
  if (tool_ && tool_->wheel(e, viewContext())) return;
  const float steps = float(e->angleDelta().y()) / 120.f;
  const float r = sceneRadius();
  setCamera(zoomCamera(camera_, std::pow(1.1f, steps), 0.05f * r, 50.f * r), true);
  restTimer_.start();
}

void ViewportWidget::keyPressEvent(QKeyEvent* e) {
  if (tool_ && tool_->keyPress(e, viewContext())) return;
  if (e->key() == Qt::Key_R && e->modifiers() == Qt::NoModifier) {
    resetView();
    return;
  }
  QWidget::keyPressEvent(e);
}

}  // namespace visopt::ws
