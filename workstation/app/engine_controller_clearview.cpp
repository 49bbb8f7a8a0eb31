// EngineController's ClearView frames (the Hotspot tool). The UI hands over settings and a
// hotspot position; the worker renders whatever is newest when it gets to it, so a cursor that
// moves faster than the frames come costs one compositing per frame, never a queue of them.
// Only a change of the view or of the layers extracts again (the Engine decides: ClearViewStats).
#include <algorithm>
#include <chrono>

#include <visopt/error.h>

#include "clearview_frames.h"
#include "engine_controller.h"

namespace visopt::ws {

void EngineController::setClearView(std::optional<ClearViewSettings> settings) {
  {
    std::lock_guard lock(mutex_);
    clearView_ = std::move(settings);
    clearViewRefused_.reset();
    oweFrameLocked();
  }
  wake_.notify_all();
}

std::optional<ClearViewSettings> EngineController::clearView() const {
  std::lock_guard lock(mutex_);
  return clearView_;
}

void EngineController::setClearViewFocus(glm::vec2 fraction) {
  {
    std::lock_guard lock(mutex_);
    if (fraction == clearViewFocus_) return;
    clearViewFocus_ = fraction;
    if (!clearView_) return;  // kept for when ClearView comes on
    oweFrameLocked();
  }
  wake_.notify_all();
}

bool EngineController::renderClearViewFrame(Engine& engine, bool preview) {
  ClearViewSettings settings;
  glm::vec2 focus;
  FrameInfo info;
  int previewFactor = 1;
  uint64_t owedAt;
  {
    std::lock_guard lock(mutex_);
    if (!clearView_) return false;
    owedAt = owedSerial_;
    settings = *clearView_;
    focus = clearViewFocus_;
    settings.width = viewportWidth_;
    settings.height = viewportHeight_;
    previewFactor = std::max(1, render_.previewFactor);
    info.cameraSerial = renderedSerial_;
    info.camera = camera_;
  }
  if (preview) {
    settings.width = std::max(16, settings.width / previewFactor);
    settings.height = std::max(16, settings.height / previewFactor);
  }
  // The fraction of the image onto this frame's pixels: the viewport stretches the frame over
  // the widget, so the same fraction is the same place on screen whatever the frame's size.
  if (focus.x < 0.f || focus.y < 0.f) {
    settings.focusPixel = glm::vec2(-1.f);  // the image centre
  } else {
    const glm::vec2 size(float(settings.width), float(settings.height));
    settings.focusPixel = glm::clamp(focus * size, glm::vec2(0.f), size - 0.5f);
  }
  {
    // Refused before with these settings at this size, and nothing changed since (a new camera,
    // a command or new settings forget the refusal): the normal frame already shows the view,
    // and moving the hotspot changes nothing of why it was refused.
    std::lock_guard lock(mutex_);
    if (clearViewRefused_ && sameHotspotSettings(*clearViewRefused_, settings) &&
        clearViewRefused_->width == settings.width &&
        clearViewRefused_->height == settings.height) {
      if (owedSerial_ == owedAt) frameOwed_ = false;
      return true;
    }
  }
  ClearViewStats stats;
  const auto start = std::chrono::steady_clock::now();
  try {
    engine.renderClearView(settings, clearViewImage_, &stats);
  } catch (const std::exception& e) {
    // Usage: a layer the scene lacks, an isovalue outside the data, ...; anything else alike:
    // said in the panel and the status bar, and the view shown by the normal render meanwhile.
    {
      std::lock_guard lock(mutex_);
      clearViewRefused_ = settings;
    }
    const QString msg = QString::fromUtf8(e.what());
    deliver([this, msg] { emit clearViewFailed(msg); });
    return false;
  }
  const QImage image = toDisplayImage(clearViewImage_);
  info.preview = preview;
  info.renderMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  info.clearView = true;
  info.clearViewStats = stats;
  frameDone(image, info, preview, owedAt);
  return true;
}

}  // namespace visopt::ws
