// The workstation's main window: the viewport in the middle, the editors and panels in docks,
// the tools in a tool bar, sessions in the File menu. It is wiring only: every change goes to the
// EngineController as a command, and every view of the scene comes back from it.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <QMainWindow>
#include <QPointer>
#include <QString>
#include <QTimer>

#include <visopt/session.h>

#include "engine_controller.h"
#include "session_files.h"

class QAction;
class QCheckBox;
class QDoubleSpinBox;
class QActionGroup;
class QDockWidget;
class QLabel;
class QMenu;
class QProgressDialog;

namespace visopt::ws {

class ViewportWidget;
class TransferFunctionEditor;
class ImportanceEditor;
class ContextSurfacesPanel;
class OptimizationPanel;
class DeviationPanel;
class ComparisonView;
class MaskPaintTool;
class LensTool;
class WindowMaskTool;
class HotspotTool;
class HotspotPanel;
class HotspotMode;
struct Histogram;

class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  // `stateDir`: where autosave, crash marker and recent sessions live (empty: the platform's).
  explicit MainWindow(Precision precision = Precision::FP32, const QString& stateDir = {},
                      QWidget* parent = nullptr);
  ~MainWindow() override;

  // Interactive (default): errors and questions are dialogs. Tests and --screenshot runs set it
  // false: errors only go to errorShown and the status bar, questions take their default.
  void setInteractive(bool interactive) { interactive_ = interactive; }

  // Opening data. Each replaces the scene; errors are reported (dialog / errorShown).
  void openBuiltinScene(const QString& name, int resolution = 128);
  void openVolume(const QString& path);
  // A context surface from "iso:...", "mesh:FILE" or "vdb:FILE" with the representation it
  // gets by default (defaultContextSurfaceSpec), added to the scene (after any load in flight).
  void addContextSurface(const QString& source);
  // A session: false (and a report) when the file cannot be read; the current scene stays.
  bool openSession(const QString& path);
  bool saveSessionTo(const QString& path);
  // The session as it would be saved now (reads the engine on its thread).
  Session currentSession(const QString& sessionPath = {});
  bool autosaveNow();
  // Offers the autosave of a crashed run; returns true when it was restored.
  bool offerRecovery();

  void setOptimizationRunning(bool running);
  // "Skin as context, bone as importance" in one step (main_window_presets.cpp): the
  // ct-skin-bone transfer function, its bone importance, the skin isosurface as a thin-shell
  // context surface (added once), and the optimisation running. An error (dialog) instead when
  // the volume's values are not Hounsfield units.
  void useSkinAsContextBoneAsImportance();
  // Renders the comparison baselines beside ours for the current view into the Comparison dock.
  void compareMethods();
  ComparisonView* comparisonView() const { return comparisonView_; }
  const RenderSettings& renderSettings() const { return render_; }
  // Processes events until the optimisation converged (or is off) and a full-size frame of the
  // current state is shown. False on timeout.
  // False on timeout, or as soon as `giveUp` returns true (a scripted run after an error).
  bool waitForSettledFrame(int timeoutMs, const std::function<bool()>& giveUp = {});
  bool exportViewport(const QString& pngPath);

  EngineController* controller() const { return controller_.get(); }
  ViewportWidget* viewport() const { return viewport_; }
  TransferFunctionEditor* transferFunctionEditor() const { return tfEditor_; }
  ImportanceEditor* importanceEditor() const { return importanceEditor_; }
  ContextSurfacesPanel* surfacesPanel() const { return surfacesPanel_; }
  OptimizationPanel* optimizationPanel() const { return optimizationPanel_; }
  DeviationPanel* deviationPanel() const { return deviationPanel_; }
  MaskPaintTool* maskTool() const { return maskTool_; }
  LensTool* lensTool() const { return lensTool_; }
  WindowMaskTool* windowMaskTool() const { return windowTool_; }
  HotspotTool* hotspotTool() const { return hotspotTool_; }
  HotspotPanel* hotspotPanel() const { return hotspotPanel_; }
  HotspotMode* hotspotMode() const { return hotspot_; }
  const SessionFiles& sessionFiles() const { return files_; }
  const QString& sessionPath() const { return sessionPath_; }
  bool modified() const { return modified_; }
  // Answers the "where did this file go?" question without a dialog (tests): given the role
  // and the recorded path, return a new path or empty to skip.
  using LocateHook = std::function<QString(const QString& role, const QString& recordedPath)>;
  void setLocateHook(LocateHook hook) { locateHook_ = std::move(hook); }

 signals:
  void errorShown(const QString& message);
  void sessionLoaded(const QString& path);
  void sceneReady();  // a scene finished loading and the panels show it

 protected:
  void closeEvent(QCloseEvent* event) override;
  void showEvent(QShowEvent* event) override;

 private:
  void buildActions();
  void buildMenus();
  void buildDocks();
  // The panel layout: every panel tabbed in one column on the right, about a third of the
  // window wide; remembered in the state folder between runs.
  void addSurface(const QString& source, std::function<ContextSurfaceSpec(const Engine&)> specFor);
  // The one path that replaces the scene (a built-in scene, a volume): `load` runs on the
  // engine's thread as long work, then the optimisation restarts and the panels follow.
  void replaceScene(const QString& title,
                    std::function<void(Engine&, const ProgressCallback&)> load);
  void arrangePanels();
  void showWholeTabTitles();
  void sizePanelColumn();
  void resetLayout();
  bool restoreLayout();
  void saveLayout();
  void buildToolBar();
  void buildBrushBar();
  void updateBrushRange();
  void connectController();
  void showError(const QString& message);
  void setModified(bool modified = true);
  void updateTitle();
  void updateStatus();
  void updateRecentMenu();
  // After a load: read the engine's state into every panel (through a captured session).
  void syncPanelsFromEngine();
  void applySessionToPanels(const Session& session);
  void onSceneChanged();
  void onLongWorkStarted(const QString& what);
  void onProgress(const QString& stage, double fraction);
  void onLongWorkFinished(bool ok);
  void pushRenderSettings();
  void lookFromElsewhere(bool on);
  void chooseTool(QAction* action);
  bool maybeSave();
  void rebuildEngine(Precision precision);
  // A built-in transfer-function preset was chosen: when the scene has no importance yet, the
  // one the preset is made for (bone for the CT presets) becomes it.
  void onBuiltinPresetApplied(const QString& name);
  // Sets an importance curve in the engine and the importance editor alike.
  void applyImportanceCurve(const std::vector<glm::dvec2>& curve, const std::string& origin);

  // UI-side state (the worker has its own copy).
  RenderSettings render_;
  bool interactive_ = true;
  bool modified_ = false;
  bool suppressModified_ = false;
  QString sessionPath_;
  SessionFiles files_;
  std::unique_ptr<EngineController> controller_;
  std::shared_ptr<const Histogram> histogram_;
  const void* histogramVolume_ = nullptr;
  const void* brushVolume_ = nullptr;
  std::optional<IterationStats> lastStats_;
  qulonglong ledgerBytes_ = 0;
  bool frozen_ = false;
  std::optional<Camera> cameraBeforeLooking_;
  LocateHook locateHook_;
  bool sceneLoading_ = false;
  QString loadWarning_;  // a reader's warning for the volume being opened, shown when it is

  ViewportWidget* viewport_ = nullptr;
  TransferFunctionEditor* tfEditor_ = nullptr;
  ImportanceEditor* importanceEditor_ = nullptr;
  ContextSurfacesPanel* surfacesPanel_ = nullptr;
  OptimizationPanel* optimizationPanel_ = nullptr;
  DeviationPanel* deviationPanel_ = nullptr;
  ComparisonView* comparisonView_ = nullptr;
  QDockWidget* comparisonDock_ = nullptr;
  std::vector<QDockWidget*> panels_;  // the side panels, in tab order
  bool layoutPlaced_ = false;         // the first show sized or restored the panel layout
  MaskPaintTool* maskTool_ = nullptr;
  LensTool* lensTool_ = nullptr;
  WindowMaskTool* windowTool_ = nullptr;
  HotspotTool* hotspotTool_ = nullptr;
  HotspotPanel* hotspotPanel_ = nullptr;
  HotspotMode* hotspot_ = nullptr;  // hotspot_mode.h: the tool, the panel and ClearView frames
  QLabel* statusLabel_ = nullptr;
  QPointer<QProgressDialog> progress_;
  QTimer autosaveTimer_;
  QTimer statusTimer_;

  QMenu* recentMenu_ = nullptr;
  QActionGroup* toolGroup_ = nullptr;
  QAction *actNavigate_ = nullptr, *actPaint_ = nullptr, *actLens_ = nullptr, *actWindow_ = nullptr;
  QAction* actHotspot_ = nullptr;
  QAction *actUndo_ = nullptr, *actRedo_ = nullptr;
  QAction *actRun_ = nullptr, *actFreeze_ = nullptr, *actLookElsewhere_ = nullptr;
  QAction* actMaskOverlay_ = nullptr;
  // Brush options (tool bar): radius in mm, erase, editable value range.
  QDoubleSpinBox *brushRadius_ = nullptr, *rangeLo_ = nullptr, *rangeHi_ = nullptr;
  QCheckBox *brushErase_ = nullptr, *rangeOn_ = nullptr;
};

}  // namespace visopt::ws
