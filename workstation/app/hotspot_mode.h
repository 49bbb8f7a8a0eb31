// The Hotspot tool's wiring (ClearView, Krüger et al. 2006): the tool, the Hotspot panel and the
// EngineController's ClearView frames, so that main_window.cpp stays wiring only.
//
// While the tool is the viewport's active one the controller renders ClearView with settings()
// and the hotspot under the cursor; otherwise the normal frames. The settings are the scene's
// defaults (defaultsFor, recomputed as the scene changes) until the user changes one in the panel
// or scales the size with the wheel; from then on they are the user's, saved in sessions
// (sessionSettings) and restored from them (applySession), until "Scene defaults".
#pragma once

#include <optional>

#include <QImage>
#include <QObject>
#include <QPointer>
#include <QString>

#include <visopt/clearview.h>

#include "engine_controller.h"
#include "scene_snapshot.h"

namespace visopt::ws {

class HotspotTool;
class HotspotPanel;

class HotspotMode : public QObject {
  Q_OBJECT
 public:
  HotspotMode(HotspotTool* tool, HotspotPanel* panel, QObject* parent = nullptr);

  // The controller whose frames these are (again after the engine was rebuilt).
  void setController(EngineController* controller);

  // The scene changed (UI snapshot): the panel's surfaces and value range, the tool's size
  // range; defaults that the user has not overridden follow the scene.
  void sceneChanged(const SceneSnapshot& scene);
  // The scene gained (or has) an importance: the default focus layer is the importance.
  void setSceneHasImportance(bool has);
  // After a scene or a session was loaded: the session's settings, or (nullopt) the scene's
  // defaults. `sceneHasImportance`: whether the scene came with an importance.
  void applySession(const std::optional<ClearViewSettings>& settings, bool sceneHasImportance);
  // What a session stores: the user's settings, nothing while they are the scene's defaults.
  std::optional<ClearViewSettings> sessionSettings() const;
  // What ClearView renders with (width, height and focusPixel are the controller's).
  const ClearViewSettings& settings() const { return settings_; }
  bool userSettings() const { return edited_; }
  bool active() const;

  // The scene's defaults, those of `visopt render --clearview` where it has them: the context is
  // context surface 0, else the data's isosurface; the focus is the importance at 0.5, else the
  // data's isosurface. An isosurface lies at the middle of [valueMin, valueMax], or, when both
  // layers are isosurfaces, the context at a third and the focus at two thirds (inside higher:
  // the focus inside the context, as bone in skin); rounded as the panel shows isovalues.
  static ClearViewSettings defaultsFor(size_t surfaces, bool hasImportance, double valueMin,
                                       double valueMax);

  // The last ClearView frame's statistics (nullopt before the first), how many have been shown,
  // and what the library said about the last refused one (empty when the last frame succeeded).
  const std::optional<ClearViewStats>& lastStats() const { return lastStats_; }
  int clearViewFrames() const { return frames_; }
  const QString& problem() const { return problem_; }
  // For the status bar while the tool is active: "ClearView · layers reused · composited in
  // 3.1 ms", or the library's complaint; empty while it is not.
  QString statusText() const;

 signals:
  void settingsEdited();  // by the user (the session changed)
  // "Optimise around the hotspot", with a last frame that has a focus point (lastStats():
  // its focusPoint and size).
  void optimiseAroundRequested();
  void problemChanged(const QString& message);

 private:
  void push();  // the settings to the controller while active
  void setUserSettings(const ClearViewSettings& settings);
  void showSettings();
  void setProblem(const QString& message);
  void onFrame(const QImage& image, const FrameInfo& info);
  ClearViewSettings sceneDefaults() const;

  HotspotTool* tool_;
  HotspotPanel* panel_;
  QPointer<EngineController> controller_;
  QMetaObject::Connection framesConnection_, failuresConnection_;
  ClearViewSettings settings_;
  bool edited_ = false;
  bool syncing_ = false;
  // The scene, for the defaults.
  size_t surfaces_ = 0;
  bool hasImportance_ = false;
  double valueMin_ = 0.0, valueMax_ = 1.0;
  std::optional<ClearViewStats> lastStats_;
  int frames_ = 0;
  QString problem_;
};

}  // namespace visopt::ws
