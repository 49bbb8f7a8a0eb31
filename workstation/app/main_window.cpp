#include "main_window.h"

#include <algorithm>

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QDateTime>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QInputDialog>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QProgressDialog>
#include <QSaveFile>
#include <QScrollArea>
#include <QShowEvent>
#include <QStatusBar>
#include <QTabBar>
#include <QToolBar>

#include <visopt/error.h>
#include <visopt/scenes.h>

#include "camera_navigation.h"
#include "hotspot_mode.h"
#include "panels/comparison_view.h"
#include "panels/context_surfaces_panel.h"
#include "panels/deviation_panel.h"
#include "panels/hotspot_panel.h"
#include "panels/optimization_panel.h"
#include "panels/status_summary.h"
#include "tools/hotspot_tool.h"
#include "tools/lens_tool.h"
#include "tools/mask_paint_tool.h"
#include "tools/window_mask_tool.h"
#include "viewport_widget.h"
#include "widgets/histogram.h"
#include "widgets/importance_editor.h"
#include "widgets/transfer_function_editor.h"

namespace visopt::ws {

namespace {

constexpr int kAutosaveIntervalMs = 3 * 60 * 1000;
// Of the remembered panel layout: raise it when the panels change, so an old layout is ignored.
constexpr int kLayoutVersion = 3;
const char* kSessionFilter = "visopt sessions (*.visopt-session *.json);;All files (*)";

QString fromStd(const std::string& s) {
  return QString::fromStdString(s);
}

}  // namespace

MainWindow::MainWindow(Precision precision, const QString& stateDir, QWidget* parent)
    : QMainWindow(parent), files_(stateDir) {
  setWindowTitle(QStringLiteral("visopt"));
  controller_ = std::make_unique<EngineController>(precision);
  viewport_ = new ViewportWidget(controller_.get(), this);
  setCentralWidget(viewport_);

  maskTool_ = new MaskPaintTool(this);
  lensTool_ = new LensTool(this);
  windowTool_ = new WindowMaskTool(this);
  hotspotTool_ = new HotspotTool(this);

  buildActions();
  buildDocks();
  buildMenus();
  buildToolBar();
  buildBrushBar();
  connectController();

  statusLabel_ = new QLabel(this);
  // No stretch: with one, the label took the whole bar and hid every temporary message
  // (errors, "Done", a reader's warning) behind it.
  statusBar()->addPermanentWidget(statusLabel_);
  statusTimer_.setInterval(500);
  connect(&statusTimer_, &QTimer::timeout, this, &MainWindow::updateStatus);
  statusTimer_.start();

  autosaveTimer_.setInterval(kAutosaveIntervalMs);
  connect(&autosaveTimer_, &QTimer::timeout, this, [this] {
    if (modified_) autosaveNow();
  });
  autosaveTimer_.start();
  files_.markRunning();
  updateRecentMenu();
  updateTitle();
  resize(1400, 900);
}

MainWindow::~MainWindow() {
  statusTimer_.stop();
  autosaveTimer_.stop();
  // The controller's worker must stop before the widgets that listen to it go.
  controller_.reset();
}

// ---- building -------------------------------------------------------------------------------

void MainWindow::buildActions() {
  toolGroup_ = new QActionGroup(this);
  toolGroup_->setExclusive(true);
  auto tool = [this](const QString& text, const QString& tip, const QKeySequence& key) {
    auto* a = new QAction(text, this);
    a->setCheckable(true);
    a->setToolTip(tip);
    a->setShortcut(key);
    toolGroup_->addAction(a);
    return a;
  };
  actNavigate_ = tool(tr("Navigate"),
                      tr("Orbit (left drag), pan (middle or Shift+drag), zoom (wheel or right "
                         "drag); R resets the view"),
                      QKeySequence(Qt::Key_N));
  actPaint_ = tool(tr("Paint mask"),
                   tr("Paint the world-space mask with a sphere brush: where it is set, surfaces "
                      "keep their shape. Ctrl+drag erases, Escape cancels a stroke"),
                   QKeySequence(Qt::Key_P));
  actLens_ = tool(tr("Lens"),
                  tr("Importance lens following the cursor: wheel changes its radius, Shift+wheel "
                     "its strength"),
                  QKeySequence(Qt::Key_L));
  actWindow_ = tool(
      tr("Window mask"),
      tr("Paint a screen-space window: only importance seen through it counts (Ctrl+drag removes)"),
      QKeySequence(Qt::Key_W));
  actHotspot_ = tool(tr("Hotspot"),
                     tr("ClearView: the view opens the context around the cursor onto the focus "
                        "behind it (Hotspot panel); wheel changes its size, drag orbits"),
                     QKeySequence(Qt::Key_H));
  actNavigate_->setChecked(true);
  connect(toolGroup_, &QActionGroup::triggered, this, &MainWindow::chooseTool);

  actUndo_ = new QAction(tr("Undo mask stroke"), this);
  actUndo_->setShortcut(QKeySequence::Undo);
  actUndo_->setEnabled(false);
  connect(actUndo_, &QAction::triggered, maskTool_, &MaskPaintTool::undo);
  actRedo_ = new QAction(tr("Redo mask stroke"), this);
  actRedo_->setShortcut(QKeySequence::Redo);
  actRedo_->setEnabled(false);
  connect(actRedo_, &QAction::triggered, maskTool_, &MaskPaintTool::redo);
  connect(maskTool_, &MaskPaintTool::historyChanged, this, [this](bool u, bool r) {
    actUndo_->setEnabled(u);
    actRedo_->setEnabled(r);
  });

  actRun_ = new QAction(tr("Optimise"), this);
  actRun_->setCheckable(true);
  actRun_->setChecked(true);
  actRun_->setShortcut(QKeySequence(Qt::Key_Space));
  actRun_->setToolTip(tr("Run or pause the visibility optimisation (it follows the camera)"));
  connect(actRun_, &QAction::toggled, this, &MainWindow::setOptimizationRunning);

  actFreeze_ = new QAction(tr("Freeze this result"), this);
  actFreeze_->setCheckable(true);
  actFreeze_->setToolTip(tr("Keep the optimised volume and surfaces when the camera moves"));
  connect(actFreeze_, &QAction::toggled, this, [this](bool on) {
    frozen_ = on;
    controller_->post(tr("Freeze"), [on](Engine& e) { e.setFrozen(on); });
    if (optimizationPanel_) optimizationPanel_->setFrozen(on);
    setModified();
  });

  actLookElsewhere_ = new QAction(tr("Look from elsewhere"), this);
  actLookElsewhere_->setCheckable(true);
  actLookElsewhere_->setToolTip(
      tr("Freeze the result and turn the camera to see it from the side (paper Fig. 7); "
         "uncheck to return"));
  connect(actLookElsewhere_, &QAction::toggled, this, &MainWindow::lookFromElsewhere);

  actMaskOverlay_ = new QAction(tr("Show mask overlay"), this);
  actMaskOverlay_->setCheckable(true);
  actMaskOverlay_->setChecked(true);
  connect(actMaskOverlay_, &QAction::toggled, this, [this](bool on) {
    render_.worldMaskOverlay = on;
    pushRenderSettings();
  });
  render_.worldMaskOverlay = true;
}

void MainWindow::buildDocks() {
  auto dock = [this](const QString& title, QWidget* w, Qt::DockWidgetArea area) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(title);
    d->setWidget(w);
    addDockWidget(area, d);
    return d;
  };
  tfEditor_ = new TransferFunctionEditor(this);
  importanceEditor_ = new ImportanceEditor(this);
  surfacesPanel_ = new ContextSurfacesPanel(this);
  optimizationPanel_ = new OptimizationPanel(this);
  deviationPanel_ = new DeviationPanel(this);
  hotspotPanel_ = new HotspotPanel(this);
  hotspot_ = new HotspotMode(hotspotTool_, hotspotPanel_, this);
  comparisonView_ = new ComparisonView(this);
  // Volumes are mostly background: a linear histogram shows one bar and nothing else.
  tfEditor_->logScaleCheckBox()->setChecked(true);
  importanceEditor_->logScaleCheckBox()->setChecked(true);

  // One column of tabbed panels on the right (tabs on top, where their titles fit), so the 3D
  // view keeps most of the window (sizePanelColumn sizes the column); a panel can be dragged
  // out beside the others, and the arrangement is remembered (saveLayout / restoreLayout).
  setTabPosition(Qt::RightDockWidgetArea, QTabWidget::North);
  setDockOptions(dockOptions() | QMainWindow::GroupedDragging);
  auto* dTf = dock(tr("Transfer function"), tfEditor_, Qt::RightDockWidgetArea);
  auto* dImp = dock(tr("Importance"), importanceEditor_, Qt::RightDockWidgetArea);
  auto* dSurf = dock(tr("Surfaces"), surfacesPanel_, Qt::RightDockWidgetArea);
  auto* dOpt = dock(tr("Optimisation"), optimizationPanel_, Qt::RightDockWidgetArea);
  auto* dDev = dock(tr("Deviation"), deviationPanel_, Qt::RightDockWidgetArea);
  // The Hotspot panel is the tallest: it scrolls rather than make the window taller than the
  // screen (or than --size asks).
  auto* hotspotScroll = new QScrollArea(this);
  hotspotScroll->setWidget(hotspotPanel_);
  hotspotScroll->setWidgetResizable(true);
  hotspotScroll->setFrameShape(QFrame::NoFrame);
  auto* dHot = dock(tr("Hotspot"), hotspotScroll, Qt::RightDockWidgetArea);
  comparisonDock_ = dock(tr("Comparison"), comparisonView_, Qt::BottomDockWidgetArea);
  comparisonDock_->hide();
  panels_ = {dTf, dImp, dSurf, dOpt, dDev, dHot};  // the Hotspot panel last (chooseTool)
  arrangePanels();

  // Editors -> engine.
  connect(tfEditor_, &TransferFunctionEditor::transferFunctionEdited, this,
          [this](const TransferFunction& tf) {
            controller_->post(tr("Transfer function"), [this, tf](Engine& e) {
              e.setTransferFunction(tf);
              controller_->refreshSnapshot(e);
            });
            setModified();
          });
  connect(tfEditor_, &TransferFunctionEditor::errorOccurred, this, &MainWindow::showError);
  connect(tfEditor_, &TransferFunctionEditor::builtinPresetApplied, this,
          &MainWindow::onBuiltinPresetApplied);
  tfEditor_->setInteractive(false);  // errors come here, shown as this window's dialogs
  connect(importanceEditor_, &ImportanceEditor::importanceCurveEdited, this,
          [this](const std::vector<glm::dvec2>& curve) {
            controller_->post(tr("Importance"),
                              [curve](Engine& e) { e.setImportanceCurve(curve); });
            importanceEditor_->setImportanceVolumeName({});
            hotspot_->setSceneHasImportance(true);
            setModified();
          });
  connect(importanceEditor_, &ImportanceEditor::importanceVolumeRequested, this,
          [this](const QString& path) {
            controller_->postLong(tr("Importance volume %1").arg(path),
                                  [p = path.toStdString()](Engine& e, const ProgressCallback&) {
                                    e.loadImportance(p);
                                  });
            importanceEditor_->setImportanceVolumeName(
                tr("the volume %1").arg(QFileInfo(path).fileName()));
            hotspot_->setSceneHasImportance(true);
            setModified();
          });
  connect(importanceEditor_, &ImportanceEditor::overlayToggled, this, [this](bool on) {
    render_.importanceOverlay = on ? 0.6f : 0.f;
    pushRenderSettings();
  });

  connect(surfacesPanel_, &ContextSurfacesPanel::addSurfaceRequested, this,
          [this](const ContextSurfaceSpec& spec) {
            addSurface(fromStd(spec.source), [spec](const Engine&) { return spec; });
          });
  connect(surfacesPanel_, &ContextSurfacesPanel::removeSurfaceRequested, this, [this](int row) {
    controller_->post(tr("Remove surface"), [this, row](Engine& e) {
      e.removeContextSurface(row);
      controller_->refreshSnapshot(e);
    });
    controller_->restartOptimization();
    setModified();
  });
  connect(surfacesPanel_, &ContextSurfacesPanel::visibilityChanged, this,
          [this](int row, bool visible) {
            controller_->post(tr("Surface visibility"), [this, row, visible](Engine& e) {
              e.setContextSurfaceVisible(row, visible);
              controller_->refreshSnapshot(e);
            });
            setModified();
          });
  connect(surfacesPanel_, &ContextSurfacesPanel::colorChanged, this,
          [this](int row, glm::vec3 rgb) {
            controller_->post(tr("Surface colour"), [this, row, rgb](Engine& e) {
              e.setContextSurfaceColor(row, rgb);
              controller_->refreshSnapshot(e);
            });
            setModified();
          });

  connect(optimizationPanel_, &OptimizationPanel::settingsEdited, this,
          [this](const ExtinctionSettings& ext, const LevelSetSettings& ls) {
            controller_->post(tr("Optimisation settings"), [ext, ls](Engine& e) {
              e.setExtinctionSettings(ext);
              e.setLevelSetSettings(ls);
            });
            setModified();
          });
  connect(optimizationPanel_, &OptimizationPanel::runToggled, actRun_, &QAction::setChecked);
  connect(optimizationPanel_, &OptimizationPanel::freezeToggled, actFreeze_, &QAction::setChecked);
  connect(optimizationPanel_, &OptimizationPanel::restartRequested, this,
          [this] { controller_->restartOptimization(); });
  connect(optimizationPanel_, &OptimizationPanel::precisionChangeRequested, this,
          &MainWindow::rebuildEngine);

  connect(deviationPanel_, &DeviationPanel::deviationSettingsChanged, this,
          [this](bool enabled, Colormap colormap, float maxVoxels) {
            render_.deviationView = enabled;
            render_.deviationColormap = colormap;
            render_.deviationMaxVoxels = maxVoxels;
            pushRenderSettings();
          });
  connect(comparisonView_, &ComparisonView::saveRequested, this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, tr("Save comparison"), {}, tr("PNG images (*.png)"));
    if (path.isEmpty()) return;
    const QImage all = comparisonView_->composite();
    QSaveFile f(path);
    if (!f.open(QIODevice::WriteOnly) || !all.save(&f, "PNG") || !f.commit())
      showError(tr("%1: could not write the image").arg(path));
  });

  // Tools -> engine.
  connect(maskTool_, &MaskPaintTool::maskChanged, this,
          [this](std::shared_ptr<const SessionMask> mask) {
            controller_->post(tr("World mask"), [mask](Engine& e) {
              if (mask) e.setWorldMask(*mask);
            });
            setModified();
          });
  connect(lensTool_, &LensTool::lensChanged, this, [this](ImportanceLens lens) {
    controller_->post(tr("Lens"), [lens](Engine& e) { e.setLens(lens); });
    setModified();
  });
  connect(windowTool_, &WindowMaskTool::windowMaskChanged, this,
          [this](std::vector<float> weights, int w, int h) {
            controller_->post(tr("Window mask"),
                              [weights, w, h](Engine& e) { e.setScreenMask(weights, w, h); });
          });
  connect(windowTool_, &WindowMaskTool::windowMaskCleared, this,
          [this] { controller_->post(tr("Window mask"), [](Engine& e) { e.clearScreenMask(); }); });
  connect(hotspot_, &HotspotMode::settingsEdited, this, [this] { setModified(); });
  // The hotspot drives the optimisation: its ball becomes the importance, the view returns to
  // the normal render (ClearView pauses the optimisation) and the optimisation runs.
  connect(hotspot_, &HotspotMode::optimiseAroundRequested, this, [this] {
    const glm::vec3 centre = hotspot_->lastStats()->focusPoint;
    const float radius = hotspot_->lastStats()->size;
    controller_->post(tr("Importance: the hotspot"),
                      [centre, radius](Engine& e) { e.setImportanceHotspot(centre, radius); });
    importanceEditor_->setImportanceVolumeName(tr("the hotspot: a ball of %1 about (%2, %3, %4)")
                                                   .arg(double(radius), 0, 'f', 1)
                                                   .arg(double(centre.x), 0, 'f', 1)
                                                   .arg(double(centre.y), 0, 'f', 1)
                                                   .arg(double(centre.z), 0, 'f', 1));
    actNavigate_->trigger();
    controller_->restartOptimization();
    actRun_->setChecked(true);
    setModified();
  });
  connect(hotspot_, &HotspotMode::problemChanged, this, [this](const QString& message) {
    if (!message.isEmpty()) statusBar()->showMessage(message, 15000);
  });
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(tr("Open &volume…"), QKeySequence::Open, this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Open volume"), {},
        tr("Volumes (*.nii *.nii.gz *.mha *.mhd *.vti *.vtk *.nrrd *.nhdr *.json *.inr *.plt);;"
           "All files (*)"));
    if (!path.isEmpty()) openVolume(path);
  });
  file->addAction(tr("Open &DICOM folder…"), this, [this] {
    const QString dir = QFileDialog::getExistingDirectory(this, tr("Open DICOM folder"));
    if (!dir.isEmpty()) openVolume(dir);
  });
  QMenu* scenes = file->addMenu(tr("Open &built-in scene"));
  for (const auto& scene : builtinScenes()) {
    const QString n = fromStd(scene.name);
    QAction* a = scenes->addAction(n, this, [this, n] {
      if (maybeSave()) openBuiltinScene(n);
    });
    a->setToolTip(fromStd(scene.description));
  }
  file->addSeparator();
  file->addAction(tr("Add context &surface…"), this,
                  [this] { surfacesPanel_->requestAdd(SurfaceSourceFields::Kind::Iso); });
  file->addSeparator();
  file->addAction(tr("Open &session…"), this, [this] {
    if (!maybeSave()) return;
    const QString path =
        QFileDialog::getOpenFileName(this, tr("Open session"), {}, tr(kSessionFilter));
    if (!path.isEmpty()) openSession(path);
  });
  recentMenu_ = file->addMenu(tr("&Recent sessions"));
  file->addAction(tr("&Save session"), QKeySequence::Save, this, [this] {
    QString path = sessionPath_;
    if (path.isEmpty())
      path = QFileDialog::getSaveFileName(this, tr("Save session"), {}, tr(kSessionFilter));
    if (!path.isEmpty()) saveSessionTo(path);
  });
  file->addAction(tr("Save session &as…"), QKeySequence::SaveAs, this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, tr("Save session"), {}, tr(kSessionFilter));
    if (!path.isEmpty()) saveSessionTo(path);
  });
  file->addSeparator();
  file->addAction(tr("&Export viewport to PNG…"), this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, tr("Export viewport"), {}, tr("PNG images (*.png)"));
    if (!path.isEmpty()) exportViewport(path);
  });
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);

  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  edit->addAction(actUndo_);
  edit->addAction(actRedo_);
  edit->addAction(tr("Clear world mask"), maskTool_, &MaskPaintTool::clear);
  edit->addAction(tr("Clear window mask"), windowTool_, &WindowMaskTool::clear);
  edit->addAction(tr("Lens off"), lensTool_, &LensTool::switchOff);

  QMenu* view = menuBar()->addMenu(tr("&View"));
  view->addAction(tr("&Reset view"), QKeySequence(Qt::Key_R), viewport_,
                  &ViewportWidget::resetView);
  view->addAction(actMaskOverlay_);
  view->addAction(tr("Light from the camera"), this, [this] {
    const Camera cam = viewport_->camera();
    controller_->post(tr("Light"), [cam](Engine& e) {
      e.setLight(PointLight::keyLightFor(cam, e.volume().grid().worldBounds()));
    });
    controller_->requestFrame();
    setModified();
  });
  view->addAction(tr("&Compare methods"), QKeySequence(Qt::Key_C), this,
                  &MainWindow::compareMethods);
  view->addSeparator();
  for (QDockWidget* d : findChildren<QDockWidget*>()) view->addAction(d->toggleViewAction());
  view->addAction(tr("&Reset panel layout"), this, &MainWindow::resetLayout)
      ->setToolTip(tr("All panels back in one tabbed column on the right"));

  QMenu* opt = menuBar()->addMenu(tr("&Optimisation"));
  opt->addAction(actRun_);
  opt->addAction(actFreeze_);
  opt->addAction(actLookElsewhere_);
  QAction* follow = opt->addAction(tr("Follow the camera while dragging"));
  follow->setCheckable(true);
  follow->setChecked(controller_->followWhileDragging());
  follow->setToolTip(
      tr("While the camera is dragged, optimise on the coarsest grid between previews so the "
         "openings move with it (on by default); off: only previews until the camera rests"));
  connect(follow, &QAction::toggled, controller_.get(), &EngineController::setFollowWhileDragging);
  opt->addAction(tr("Restart from the transfer function"), this,
                 [this] { controller_->restartOptimization(); });
  opt->addSeparator();
  QAction* skinBone = opt->addAction(tr("CT: skin as context, bone as importance"), this,
                                     &MainWindow::useSkinAsContextBoneAsImportance);
  skinBone->setToolTip(
      tr("The ct-skin-bone transfer function, bone (200-300 HU and above) as importance and the "
         "skin isosurface at -400 HU as a thin-shell context surface, then optimise"));
}

void MainWindow::buildToolBar() {
  QToolBar* bar = addToolBar(tr("Tools"));
  bar->setObjectName(QStringLiteral("tools"));
  bar->addActions(toolGroup_->actions());
  bar->addSeparator();
  bar->addAction(actUndo_);
  bar->addAction(actRedo_);
  bar->addSeparator();
  bar->addAction(actRun_);
  bar->addAction(actFreeze_);
  bar->addAction(actLookElsewhere_);
}

void MainWindow::buildBrushBar() {
  QToolBar* bar = addToolBar(tr("Brush"));
  bar->setObjectName(QStringLiteral("brush"));
  bar->addWidget(new QLabel(tr(" Brush radius "), bar));
  brushRadius_ = new QDoubleSpinBox(bar);
  brushRadius_->setSuffix(tr(" mm"));
  brushRadius_->setRange(0.1, 1000.0);
  brushRadius_->setDecimals(1);
  brushRadius_->setValue(double(maskTool_->radius()));
  brushRadius_->setToolTip(tr("Radius of the sphere brush in world units (mm for medical data)"));
  bar->addWidget(brushRadius_);
  connect(brushRadius_, &QDoubleSpinBox::valueChanged, this,
          [this](double r) { maskTool_->setRadius(float(r)); });
  brushErase_ = new QCheckBox(tr("Erase"), bar);
  brushErase_->setToolTip(tr("Strokes erase the mask (Ctrl while pressing does the opposite)"));
  bar->addWidget(brushErase_);
  connect(brushErase_, &QCheckBox::toggled, this, [this](bool erase) {
    maskTool_->setMode(erase ? MaskEditor::Mode::Erase : MaskEditor::Mode::Paint);
  });
  rangeOn_ = new QCheckBox(tr("Only values in"), bar);
  rangeOn_->setToolTip(tr("Strokes change only voxels whose data value lies in this range"));
  bar->addWidget(rangeOn_);
  rangeLo_ = new QDoubleSpinBox(bar);
  rangeHi_ = new QDoubleSpinBox(bar);
  for (QDoubleSpinBox* box : {rangeLo_, rangeHi_}) {
    box->setRange(-1e9, 1e9);
    box->setDecimals(2);
    box->setEnabled(false);
    bar->addWidget(box);
    connect(box, &QDoubleSpinBox::valueChanged, this, &MainWindow::updateBrushRange);
  }
  connect(rangeOn_, &QCheckBox::toggled, this, [this](bool on) {
    rangeLo_->setEnabled(on);
    rangeHi_->setEnabled(on);
    updateBrushRange();
  });
}

void MainWindow::updateBrushRange() {
  if (rangeOn_->isChecked())
    maskTool_->setValueRange(std::make_pair(rangeLo_->value(), rangeHi_->value()));
  else
    maskTool_->setValueRange(std::nullopt);
}

void MainWindow::connectController() {
  EngineController* c = controller_.get();
  connect(c, &EngineController::iterationDone, this,
          [this](const IterationStats& st, qulonglong bytes) {
            lastStats_ = st;
            ledgerBytes_ = bytes;
          });
  connect(c, &EngineController::sceneChanged, this, &MainWindow::onSceneChanged);
  connect(c, &EngineController::errorOccurred, this, &MainWindow::showError);
  connect(c, &EngineController::longWorkStarted, this, &MainWindow::onLongWorkStarted);
  connect(c, &EngineController::progressChanged, this, &MainWindow::onProgress);
  connect(c, &EngineController::longWorkFinished, this, &MainWindow::onLongWorkFinished);
  hotspot_->setController(c);
}

// ---- state and status -----------------------------------------------------------------------

void MainWindow::showError(const QString& message) {
  statusBar()->showMessage(message, 15000);
  emit errorShown(message);
  if (interactive_) {
    auto* box = new QMessageBox(QMessageBox::Warning, tr("visopt"), message, QMessageBox::Ok, this);
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->open();  // not exec(): the viewport keeps updating behind it
  }
}

void MainWindow::setModified(bool modified) {
  if (suppressModified_) return;
  modified_ = modified;
  updateTitle();
}

void MainWindow::updateTitle() {
  const QString name = sessionPath_.isEmpty() ? tr("untitled") : QFileInfo(sessionPath_).fileName();
  setWindowTitle(QStringLiteral("%1%2 — visopt").arg(name, modified_ ? QStringLiteral("*") : ""));
}

void MainWindow::updateStatus() {
  // The optimisation waits while ClearView shows (EngineController::setClearView): "paused".
  QString text = formatStatus(lastStats_ ? &*lastStats_ : nullptr, viewport_->framesPerSecond(),
                              size_t(ledgerBytes_), frozen_,
                              controller_->optimizationRunning() && !hotspot_->active());
  if (const QString hotspot = hotspot_->statusText(); !hotspot.isEmpty())
    text += QStringLiteral(" · ") + hotspot;
  statusLabel_->setText(text);
}

void MainWindow::updateRecentMenu() {
  recentMenu_->clear();
  const QStringList recent = files_.recentSessions();
  for (const QString& path : recent)
    recentMenu_->addAction(path, this, [this, path] {
      if (maybeSave()) openSession(path);
    });
  recentMenu_->setEnabled(!recent.isEmpty());
}

void MainWindow::pushRenderSettings() {
  controller_->setRenderSettings(render_);
  setModified();
}

void MainWindow::setOptimizationRunning(bool running) {
  if (actRun_->isChecked() != running) actRun_->setChecked(running);
  controller_->setOptimizationRunning(running);
  if (optimizationPanel_) optimizationPanel_->setRunning(running);
}

bool MainWindow::waitForSettledFrame(int timeoutMs, const std::function<bool()>& giveUp) {
  QElapsedTimer clock;
  clock.start();
  while (clock.elapsed() < timeoutMs) {
    QApplication::processEvents(QEventLoop::AllEvents, 50);
    if (giveUp && giveUp()) return false;
    const bool settled = !sceneLoading_ && controller_->waitIdle(20);
    if (settled) {
      // Deliver the frames and signals queued by the worker before it went idle.
      QApplication::processEvents(QEventLoop::AllEvents, 50);
      if (!viewport_->frame().isNull() && !viewport_->framePreview() && controller_->waitIdle(0))
        return true;
    }
  }
  return false;
}

bool MainWindow::exportViewport(const QString& pngPath) {
  const QImage image = viewport_->frame();
  QSaveFile f(pngPath);
  if (image.isNull() || !f.open(QIODevice::WriteOnly) || !image.save(&f, "PNG") || !f.commit()) {
    showError(tr("%1: could not write the viewport image").arg(pngPath));
    return false;
  }
  return true;
}

// ---- opening data ---------------------------------------------------------------------------

void MainWindow::openBuiltinScene(const QString& name, int resolution) {
  const std::string n = name.toStdString();
  replaceScene(tr("Scene builtin:%1").arg(name),
               [n, resolution](Engine& e, const ProgressCallback&) {
                 e.loadBuiltinScene(n, resolution, true);
               });
}

void MainWindow::openVolume(const QString& path) {
  const std::string p = path.toStdString();
  replaceScene(tr("Volume %1").arg(path), [p](Engine& e, const ProgressCallback& progress) {
    e.loadVolume(p, progress);
    // The content hash a saved session records, computed now with progress (and
    // cached), so that saving later reads nothing; cancelling it only defers it.
    try {
      makeDataReference(p, {}, progress);
    } catch (const Error& err) {
      if (err.kind() != ErrorKind::Cancelled) throw;
    }
  });
}

void MainWindow::replaceScene(const QString& title,
                              std::function<void(Engine&, const ProgressCallback&)> load) {
  sceneLoading_ = true;
  controller_->postLong(title, [this, load](Engine& e, const ProgressCallback& progress) {
    load(e, progress);
    e.resetOptimization();
    controller_->refreshSnapshot(e, true);
    // Accepted with a caveat (DICOM spacing jitter, ...): say so.
    QStringList warnings;
    for (const std::string& w : e.volume().warnings) warnings << QString::fromStdString(w);
    if (!warnings.isEmpty())
      QMetaObject::invokeMethod(
          this,
          // Shown when the long work ends, in place of its "Done".
          [this, warnings] { loadWarning_ = warnings.join(QStringLiteral("; ")); },
          Qt::QueuedConnection);
  });
  controller_->restartOptimization();
  sessionPath_.clear();
  syncPanelsFromEngine();
  setModified(false);
}

void MainWindow::syncPanelsFromEngine() {
  // Runs after the commands already queued; the captured state comes back to the UI thread.
  controller_->post(tr("Read scene"), [this](Engine& e) {
    if (!e.hasVolume()) {
      QMetaObject::invokeMethod(
          this, [this] { sceneLoading_ = false; }, Qt::QueuedConnection);
      return;
    }
    auto session = std::make_shared<Session>(captureSession(e, controller_->renderSettings()));
    QMetaObject::invokeMethod(
        this,
        [this, session] {
          applySessionToPanels(*session);
          sceneLoading_ = false;
          emit sceneReady();
        },
        Qt::QueuedConnection);
  });
}

void MainWindow::applySessionToPanels(const Session& s) {
  suppressModified_ = true;
  if (s.transferFunction) tfEditor_->setTransferFunction(*s.transferFunction);
  if (s.importance.kind == SessionImportance::Kind::Curve) {
    importanceEditor_->setCurve(s.importance.curve);
    importanceEditor_->setImportanceVolumeName({});
  } else if (s.importance.kind == SessionImportance::Kind::Volume) {
    importanceEditor_->setImportanceVolumeName(
        tr("the volume %1").arg(QFileInfo(fromStd(s.importance.volume.absolutePath)).fileName()));
  } else if (s.importance.kind == SessionImportance::Kind::Scene) {
    importanceEditor_->setImportanceVolumeName(tr("the scene's definition"));
  }
  std::vector<ContextSurfaceSpec> specs;
  for (const auto& surface : s.contextSurfaces) specs.push_back(surface.spec);
  surfacesPanel_->setSurfaces(specs);
  optimizationPanel_->setSettings(s.extinction, s.levelSet, controller_->precision());
  frozen_ = s.frozen;
  {
    QSignalBlocker block(actFreeze_);
    actFreeze_->setChecked(s.frozen);
  }
  optimizationPanel_->setFrozen(s.frozen);
  render_ = s.render;
  deviationPanel_->setDeviationSettings(render_.deviationView, render_.deviationColormap,
                                        render_.deviationMaxVoxels);
  {
    QSignalBlocker block(actMaskOverlay_);
    actMaskOverlay_->setChecked(render_.worldMaskOverlay);
  }
  importanceEditor_->setOverlayChecked(render_.importanceOverlay > 0.f);
  hotspot_->applySession(s.clearView, s.importance.kind != SessionImportance::Kind::None);
  controller_->setRenderSettings(render_);
  if (s.camera) {
    viewport_->setHomeCamera(*s.camera);
    viewport_->setCamera(*s.camera, false);
  }
  lensTool_->setLensOn(s.lens.radius > 0.f);
  if (s.lens.radius > 0.f) {
    lensTool_->setRadius(s.lens.radius);
    lensTool_->setStrength(s.lens.strength);
    lensTool_->setCentre(QPointF(double(s.lens.x), double(s.lens.y)));
  }
  maskTool_->setVolume(nullptr);  // forget the previous scene's mask
  if (const auto snap = controller_->snapshot(); snap && snap->volume) {
    maskTool_->setVolume(snap->volume);
    if (s.worldMask && s.worldMask->dims == snap->volume->grid().dims)
      maskTool_->setMask(*s.worldMask);
  }
  suppressModified_ = false;
}

void MainWindow::onSceneChanged() {
  const auto snap = controller_->snapshot();
  if (!snap || !snap->volume) return;
  if (histogramVolume_ != snap->volume->normalized.raw() || !histogram_) {
    // Once per volume: the editors draw it at every edit.
    histogram_ = std::make_shared<const Histogram>(computeHistogram(*snap->volume));
    tfEditor_->setHistogram(histogram_);
    importanceEditor_->setHistogram(histogram_);
    hotspotPanel_->setHistogram(histogram_);
    histogramVolume_ = snap->volume->normalized.raw();
  }
  surfacesPanel_->setValueRange(snap->volume->valueMin, snap->volume->valueMax);
  surfacesPanel_->setSurfaces(snap->surfaces);
  hotspot_->sceneChanged(*snap);
  deviationPanel_->setVoxelSize(snap->volume->grid().minSpacing());
  if (snap->volume.get() != brushVolume_) {
    // A new volume: a brush of 4 % of its size, the value range spanning its data.
    brushVolume_ = snap->volume.get();
    const glm::vec3 extent = snap->volume->grid().worldBounds().size();
    brushRadius_->setValue(double(0.04f * std::max(extent.x, std::max(extent.y, extent.z))));
    QSignalBlocker lo(rangeLo_), hi(rangeHi_);
    rangeLo_->setValue(snap->volume->valueMin);
    rangeHi_->setValue(snap->volume->valueMax);
    updateBrushRange();
  }
  maskTool_->setVolume(snap->volume);
}

void MainWindow::onLongWorkStarted(const QString& what) {
  if (!interactive_) return;
  if (!progress_) {
    progress_ = new QProgressDialog(what, tr("Cancel"), 0, 1000, this);
    progress_->setWindowModality(Qt::WindowModal);
    progress_->setMinimumDuration(400);
    connect(progress_, &QProgressDialog::canceled, this, [this] { controller_->cancelLongWork(); });
  }
  progress_->setLabelText(what);
  progress_->setValue(0);
}

void MainWindow::onProgress(const QString& stage, double fraction) {
  statusBar()->showMessage(tr("%1… %2 %").arg(stage).arg(int(fraction * 100.0)));
  if (progress_) {
    progress_->setLabelText(stage);
    progress_->setValue(int(fraction * 1000.0));
  }
}

void MainWindow::onLongWorkFinished(bool ok) {
  if (progress_) {
    progress_->reset();
    progress_->deleteLater();
  }
  if (ok && !loadWarning_.isEmpty()) {
    statusBar()->showMessage(loadWarning_, 30000);
    loadWarning_.clear();
    return;
  }
  statusBar()->showMessage(ok ? tr("Done") : tr("Stopped"), 3000);
}

// ---- sessions -------------------------------------------------------------------------------

Session MainWindow::currentSession(const QString& sessionPath) {
  Session session;
  const RenderSettings render = render_;
  const Camera camera = viewport_->camera();
  const std::string path = sessionPath.toStdString();
  controller_->call([&](Engine& e) {
    session = captureSession(e, render, path);
    session.camera = camera;  // the UI's camera, which the worker may not have picked up yet
  });
  session.clearView = hotspot_->sessionSettings();
  return session;
}

bool MainWindow::saveSessionTo(const QString& path) {
  try {
    const Session session = currentSession(path);
    saveSession(session, path.toStdString());
  } catch (const std::exception& e) {
    showError(QString::fromUtf8(e.what()));
    return false;
  }
  sessionPath_ = QFileInfo(path).absoluteFilePath();
  files_.addRecentSession(sessionPath_);
  updateRecentMenu();
  setModified(false);
  statusBar()->showMessage(tr("Saved %1").arg(sessionPath_), 5000);
  return true;
}

bool MainWindow::autosaveNow() {
  try {
    const Session session = currentSession(files_.autosavePath());
    saveSession(session, files_.autosavePath().toStdString());
    return true;
  } catch (const std::exception& e) {
    statusBar()->showMessage(tr("Autosave failed: %1").arg(QString::fromUtf8(e.what())), 10000);
    return false;
  }
}

bool MainWindow::openSession(const QString& path) {
  Session session;
  const std::string p = path.toStdString();
  try {
    session = loadSession(p);
  } catch (const std::exception& e) {
    showError(QString::fromUtf8(e.what()));
    return false;
  }
  // Data that moved or vanished: ask where it is before anything is replaced. Only sizes are
  // compared here (no file is read on the interface's thread); the content is hashed once the
  // scene shows.
  for (const SessionDataReport& r : checkSessionData(session, p, DataCheck::Size)) {
    if (r.status == DataStatus::Ok || r.status == DataStatus::Moved) continue;
    const QString role = fromStd(r.role);
    const QString recorded = fromStd(r.reference.absolutePath);
    QString found;
    if (locateHook_) {
      found = locateHook_(role, recorded);
    } else if (interactive_) {
      const auto answer = QMessageBox::question(
          this, tr("Data file not found"), tr("%1\n\nPoint to the file?").arg(fromStd(describe(r))),
          QMessageBox::Yes | QMessageBox::No, QMessageBox::Yes);
      if (answer == QMessageBox::Yes)
        found = QFileDialog::getOpenFileName(this, tr("Where is %1?").arg(role),
                                             QFileInfo(recorded).path());
    }
    if (!found.isEmpty()) {
      relocate(session, r.role, found.toStdString());
    } else {
      showError(fromStd(describe(r)));
      if (r.role == "volume") return false;  // nothing to show: keep the current scene
    }
  }
  sceneLoading_ = true;
  auto shared = std::make_shared<Session>(std::move(session));
  controller_->postLong(tr("Session %1").arg(QFileInfo(path).fileName()),
                        [this, shared, p](Engine& e, const ProgressCallback& progress) {
                          SessionApplyOptions options;
                          options.check = DataCheck::Size;
                          SessionLoadReport report = applySession(e, *shared, p, progress, options);
                          e.resetOptimization();
                          controller_->refreshSnapshot(e, true);
                          QStringList problems;
                          try {
                            verifySessionData(report.data, progress);
                          } catch (const Error& err) {
                            if (err.kind() != ErrorKind::Cancelled) throw;
                            problems << tr("The data files' content was not checked (cancelled).");
                          }
                          for (const auto& d : report.data)
                            if (d.status != DataStatus::Ok && d.status != DataStatus::Moved)
                              problems << fromStd(describe(d));
                          for (const auto& w : report.warnings) problems << fromStd(w);
                          if (!problems.isEmpty())
                            QMetaObject::invokeMethod(
                                this, [this, problems] { showError(problems.join('\n')); },
                                Qt::QueuedConnection);
                        });
  controller_->restartOptimization();
  // The panels show what was applied, including the mask and lens that the engine holds.
  const std::shared_ptr<const Session> applied = shared;
  controller_->post(tr("Read session"), [this, applied](Engine&) {
    QMetaObject::invokeMethod(
        this,
        [this, applied] {
          applySessionToPanels(*applied);
          sceneLoading_ = false;
          emit sceneReady();
        },
        Qt::QueuedConnection);
  });
  sessionPath_ = QFileInfo(path).absoluteFilePath();
  if (!sessionPath_.startsWith(QFileInfo(files_.stateDir()).absoluteFilePath())) {
    files_.addRecentSession(sessionPath_);  // not the autosave or a precision switch
    updateRecentMenu();
  }
  setModified(false);
  emit sessionLoaded(sessionPath_);
  return true;
}

bool MainWindow::offerRecovery() {
  if (!files_.previousRunCrashed()) return false;
  if (interactive_) {
    const auto answer = QMessageBox::question(
        this, tr("Recover work"),
        tr("visopt did not exit cleanly last time. Restore the automatically saved session "
           "from %1?")
            .arg(QFileInfo(files_.autosavePath()).lastModified().toString()),
        QMessageBox::Yes | QMessageBox::No, QMessageBox::Yes);
    if (answer != QMessageBox::Yes) return false;
  }
  if (!openSession(files_.autosavePath())) return false;
  sessionPath_.clear();  // a recovered session is saved under a name the user picks
  setModified(true);
  return true;
}

bool MainWindow::maybeSave() {
  if (!modified_ || !interactive_) return true;
  const auto answer = QMessageBox::question(
      this, tr("Unsaved changes"), tr("Save the current session first?"),
      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, QMessageBox::Save);
  if (answer == QMessageBox::Cancel) return false;
  if (answer == QMessageBox::Discard) return true;
  QString path = sessionPath_;
  if (path.isEmpty())
    path = QFileDialog::getSaveFileName(this, tr("Save session"), {}, tr(kSessionFilter));
  return !path.isEmpty() && saveSessionTo(path);
}

void MainWindow::closeEvent(QCloseEvent* event) {
  if (!maybeSave()) {
    event->ignore();
    return;
  }
  saveLayout();
  files_.markCleanExit();
  event->accept();
}

void MainWindow::addContextSurface(const QString& source) {
  addSurface(source, [source](const Engine& e) {
    return defaultContextSurfaceSpec(source.toStdString(), e.volume().grid());
  });
}

void MainWindow::addSurface(const QString& source,
                            std::function<ContextSurfaceSpec(const Engine&)> specFor) {
  controller_->postLong(tr("Context surface %1").arg(source),
                        [this, specFor](Engine& e, const ProgressCallback& progress) {
                          e.addContextSurface(specFor(e), progress);
                          controller_->refreshSnapshot(e);
                        });
  controller_->restartOptimization();
  setModified();
}

// ---- the panel layout -------------------------------------------------------------------------

void MainWindow::arrangePanels() {
  for (QDockWidget* d : panels_) {
    d->setFloating(false);
    addDockWidget(Qt::RightDockWidgetArea, d);
    d->show();
  }
  for (size_t i = 1; i < panels_.size(); ++i) tabifyDockWidget(panels_[i - 1], panels_[i]);
  panels_.front()->raise();
  showWholeTabTitles();
}

void MainWindow::showWholeTabTitles() {
  // Qt elides the titles of tabbed panels to fit ("Transfer fun..."); whole titles and scroll
  // arrows where a narrow column cannot hold them all read better. The main window makes its
  // tab bars as panels are tabbed, so this runs after each arrangement.
  for (QTabBar* bar : findChildren<QTabBar*>(Qt::FindDirectChildrenOnly)) {
    bar->setElideMode(Qt::ElideNone);
    bar->setUsesScrollButtons(true);
  }
}

void MainWindow::sizePanelColumn() {
  // About a third of the window, within what the panels' forms need and what leaves the 3D view
  // at least 60 % of a 1280-pixel window.
  const int width = std::clamp(int(0.38 * double(this->width())), 340, 520);
  resizeDocks({panels_.front()}, {width}, Qt::Horizontal);
}

void MainWindow::resetLayout() {
  comparisonDock_->hide();
  arrangePanels();
  sizePanelColumn();
}

void MainWindow::showEvent(QShowEvent* event) {
  QMainWindow::showEvent(event);
  if (layoutPlaced_) return;
  layoutPlaced_ = true;
  if (!restoreLayout()) sizePanelColumn();
  showWholeTabTitles();
}

bool MainWindow::restoreLayout() {
  QFile f(files_.layoutPath());
  if (!f.open(QIODevice::ReadOnly)) return false;
  // A layout of another version or a damaged file is ignored: the default layout stands.
  return restoreState(f.read(1 << 20), kLayoutVersion);
}

void MainWindow::saveLayout() {
  if (!layoutPlaced_) return;  // never shown: nothing arranged by the user
  QSaveFile f(files_.layoutPath());
  if (f.open(QIODevice::WriteOnly)) {
    f.write(saveState(kLayoutVersion));
    f.commit();
  }
}

// ---- views ----------------------------------------------------------------------------------

void MainWindow::chooseTool(QAction* action) {
  if (action == actPaint_)
    viewport_->setTool(maskTool_);
  else if (action == actLens_)
    viewport_->setTool(lensTool_);
  else if (action == actWindow_)
    viewport_->setTool(windowTool_);
  else if (action == actHotspot_) {
    viewport_->setTool(hotspotTool_);
    panels_.back()->raise();  // the Hotspot panel: its settings are what the view now shows
  } else
    viewport_->setTool(nullptr);
  if (action == actLens_) lensTool_->setLensOn(true);
}

void MainWindow::lookFromElsewhere(bool on) {
  if (on) {
    cameraBeforeLooking_ = viewport_->camera();
    actFreeze_->setChecked(true);
    viewport_->setCamera(orbitCamera(viewport_->camera(), 70.f, 20.f), false);
  } else {
    if (cameraBeforeLooking_) viewport_->setCamera(*cameraBeforeLooking_, false);
    cameraBeforeLooking_.reset();
    actFreeze_->setChecked(false);
  }
}

void MainWindow::compareMethods() {
  comparisonDock_->show();
  comparisonDock_->raise();
  comparisonView_->setBusy(true);
  RenderSettings base = render_;
  base.width = std::max(64, viewport_->width() / 2);
  base.height = std::max(64, viewport_->height() / 2);
  const Camera camera = viewport_->camera();
  controller_->postLong(
      tr("Compare methods"), [this, base, camera](Engine& e, const ProgressCallback& progress) {
        e.setCamera(camera);
        std::vector<std::pair<QString, QImage>> images;
        const std::pair<RenderMethod, QString> methods[] = {
            {RenderMethod::MaxImportanceProjection, tr("Max. importance projection")},
            {RenderMethod::CutAway, tr("Cut-away")},
            {RenderMethod::TransparencyModulation, tr("Transparency modulation")},
            {RenderMethod::Optimized, tr("Optimised (ours)")}};
        try {
          // Cut-away and transparency modulation draw the extinction optimised as in [9] (the
          // surfaces held): its run shows progress and can be cancelled.
          bool cancelled = false;
          if (e.hasImportance()) {
            const ExtinctionSettings& xs = e.extinctionSettings();
            const double total = double(std::max(1, xs.levels * xs.maxIterationsPerLevel));
            int done = 0;
            e.optimizeBaseline(
                [&](const IterationStats&) {
                  cancelled = !progress(float(std::min(1.0, ++done / total)),
                                        "baselines' volume (the optimisation of [9])");
                  return !cancelled;
                },
                [&] { return cancelled; });
          }
          if (cancelled) {
            QMetaObject::invokeMethod(
                this, [this] { comparisonView_->setBusy(false); }, Qt::QueuedConnection);
            return;
          }
          for (const auto& [method, label] : methods) {
            RenderSettings s = base;
            s.method = method;
            const Image img = e.render(s);
            const auto rgba = img.toSrgb8();
            QImage q(rgba.data(), img.width, img.height, QImage::Format_RGBA8888);
            images.emplace_back(label, q.copy());
          }
        } catch (const std::exception& error) {
          const QString msg = tr("Compare methods: %1").arg(QString::fromUtf8(error.what()));
          QMetaObject::invokeMethod(
              this,
              [this, msg] {
                comparisonView_->setBusy(false);
                showError(msg);
              },
              Qt::QueuedConnection);
          return;
        }
        QMetaObject::invokeMethod(
            this,
            [this, images] {
              comparisonView_->setImages(images);
              comparisonView_->setBusy(false);
            },
            Qt::QueuedConnection);
      });
}

void MainWindow::rebuildEngine(Precision precision) {
  if (precision == controller_->precision()) return;
  // The engine's precision is fixed at construction: carry the scene over through a session.
  const QString tmp = files_.stateDir() + QStringLiteral("/precision-switch.visopt-session");
  const bool haveScene = controller_->snapshot() && controller_->snapshot()->volume;
  if (haveScene) {
    try {
      saveSession(currentSession(tmp), tmp.toStdString());
    } catch (const std::exception& e) {
      showError(QString::fromUtf8(e.what()));
      return;
    }
  }
  const QString keepPath = sessionPath_;
  controller_ = std::make_unique<EngineController>(precision);
  auto* old = viewport_;
  ViewportTool* activeTool = old->tool();
  viewport_ = new ViewportWidget(controller_.get(), this);
  setCentralWidget(viewport_);
  old->deleteLater();
  connectController();
  controller_->setRenderSettings(render_);
  controller_->setOptimizationRunning(actRun_->isChecked());
  viewport_->setTool(activeTool);  // the active tool carries over
  if (haveScene) {
    openSession(tmp);
    QFile::remove(tmp);
  }
  sessionPath_ = keepPath;
  setModified(true);
  updateTitle();
}

}  // namespace visopt::ws
