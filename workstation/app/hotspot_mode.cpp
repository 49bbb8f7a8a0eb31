#include "hotspot_mode.h"

#include <cmath>

#include <glm/glm.hpp>

#include "clearview_frames.h"
#include "panels/hotspot_panel.h"
#include "tools/hotspot_tool.h"

namespace visopt::ws {

HotspotMode::HotspotMode(HotspotTool* tool, HotspotPanel* panel, QObject* parent)
    : QObject(parent), tool_(tool), panel_(panel) {
  settings_ = sceneDefaults();
  showSettings();
  connect(tool_, &HotspotTool::activeChanged, this, [this](bool on) {
    if (!controller_) return;
    if (on) {
      const QPointF f = tool_->focus();
      controller_->setClearViewFocus(glm::vec2(float(f.x()), float(f.y())));
      controller_->setClearView(settings_);
    } else {
      controller_->setClearView(std::nullopt);
      setProblem({});
    }
  });
  connect(tool_, &HotspotTool::focusChanged, this, [this](QPointF f) {
    if (controller_) controller_->setClearViewFocus(glm::vec2(float(f.x()), float(f.y())));
  });
  connect(tool_, &HotspotTool::sizeChanged, this, [this](float size) {
    if (syncing_) return;
    ClearViewSettings s = settings_;
    s.size = size;
    setUserSettings(s);
  });
  connect(panel_, &HotspotPanel::settingsEdited, this,
          [this](const ClearViewSettings& s) { setUserSettings(s); });
  connect(panel_, &HotspotPanel::optimiseAroundRequested, this, [this] {
    if (lastStats_ && lastStats_->hasFocusPoint && lastStats_->size > 0.f)
      emit optimiseAroundRequested();
  });
  connect(panel_, &HotspotPanel::resetRequested, this, [this] {
    edited_ = false;
    settings_ = sceneDefaults();
    showSettings();
    push();
    emit settingsEdited();
  });
}

void HotspotMode::setController(EngineController* controller) {
  disconnect(framesConnection_);
  disconnect(failuresConnection_);
  controller_ = controller;
  lastStats_.reset();
  if (!controller_) return;
  framesConnection_ =
      connect(controller_, &EngineController::frameReady, this, &HotspotMode::onFrame);
  failuresConnection_ =
      connect(controller_, &EngineController::clearViewFailed, this, &HotspotMode::setProblem);
  if (active()) {
    const QPointF f = tool_->focus();
    controller_->setClearViewFocus(glm::vec2(float(f.x()), float(f.y())));
    controller_->setClearView(settings_);
  }
}

bool HotspotMode::active() const {
  return tool_->active();
}

ClearViewSettings HotspotMode::defaultsFor(size_t surfaces, bool hasImportance, double valueMin,
                                           double valueMax) {
  ClearViewSettings s;
  const bool contextIso = surfaces == 0, focusIso = !hasImportance;
  const int decimals = isovalueDecimals(valueMin, valueMax);
  const double scale = std::pow(10.0, decimals);
  const auto iso = [&](double t) {
    const double v = valueMin + t * (valueMax - valueMin);
    return ClearViewLayer{ClearViewLayerKind::Isosurface, std::round(v * scale) / scale, 0};
  };
  const bool both = contextIso && focusIso;
  s.context = contextIso ? iso(both ? 1.0 / 3.0 : 0.5)
                         : ClearViewLayer{ClearViewLayerKind::ContextSurface, 0.0, 0};
  s.focus = focusIso ? iso(both ? 2.0 / 3.0 : 0.5)
                     : ClearViewLayer{ClearViewLayerKind::Importance, 0.5, 0};
  return s;
}

ClearViewSettings HotspotMode::sceneDefaults() const {
  return defaultsFor(surfaces_, hasImportance_, valueMin_, valueMax_);
}

void HotspotMode::sceneChanged(const SceneSnapshot& scene) {
  if (!scene.volume) return;
  surfaces_ = scene.surfaces.size();
  valueMin_ = scene.volume->valueMin;
  valueMax_ = scene.volume->valueMax;
  const float radius = 0.5f * glm::length(scene.volume->grid().worldBounds().size());
  tool_->setSceneRadius(radius);
  panel_->setScene(scene.surfaces, valueMin_, valueMax_, radius);
  if (edited_) return;
  const ClearViewSettings defaults = sceneDefaults();
  if (sameHotspotSettings(defaults, settings_)) return;
  settings_ = defaults;
  showSettings();
  push();
}

void HotspotMode::setSceneHasImportance(bool has) {
  if (has == hasImportance_) return;
  hasImportance_ = has;
  if (edited_) return;
  settings_ = sceneDefaults();
  showSettings();
  push();
}

void HotspotMode::applySession(const std::optional<ClearViewSettings>& settings,
                               bool sceneHasImportance) {
  hasImportance_ = sceneHasImportance;
  edited_ = settings.has_value();
  settings_ = settings ? *settings : sceneDefaults();
  showSettings();
  push();
}

std::optional<ClearViewSettings> HotspotMode::sessionSettings() const {
  if (!edited_) return std::nullopt;
  ClearViewSettings s = settings_;
  const ClearViewSettings view;  // the view's members are not the session's
  s.width = view.width;
  s.height = view.height;
  s.focusPixel = view.focusPixel;
  return s;
}

void HotspotMode::setUserSettings(const ClearViewSettings& settings) {
  if (edited_ && sameHotspotSettings(settings, settings_)) return;
  settings_ = settings;
  edited_ = true;
  showSettings();
  push();
  emit settingsEdited();
}

void HotspotMode::showSettings() {
  syncing_ = true;
  panel_->setSettings(settings_);
  tool_->setSize(settings_.size);
  syncing_ = false;
}

void HotspotMode::push() {
  if (controller_ && active()) controller_->setClearView(settings_);
}

void HotspotMode::setProblem(const QString& message) {
  if (message == problem_) return;
  problem_ = message;
  panel_->setProblem(message);
  emit problemChanged(message);
}

void HotspotMode::onFrame(const QImage&, const FrameInfo& info) {
  if (!info.clearView) return;
  lastStats_ = info.clearViewStats;
  ++frames_;
  panel_->setStats(info.clearViewStats);
  setProblem({});
}

QString HotspotMode::statusText() const {
  if (!active()) return {};
  if (!problem_.isEmpty()) return problem_;
  QString text = tr("ClearView");
  if (lastStats_) {
    text += lastStats_->extracted
                ? tr(" · layers extracted in %1 ms").arg(lastStats_->extractMs, 0, 'f', 0)
                : tr(" · layers reused");
    text += tr(" · composited in %1 ms").arg(lastStats_->compositeMs, 0, 'f', 1);
  }
  return text;
}

}  // namespace visopt::ws
