// visopt-workstation: the Qt application. Without arguments it opens the built-in default scene
// (or offers to recover a crashed session); files on the command line open as a user expects
// (command_line_files.h). Scripting options open a scene, a volume or a
// session, export a screenshot after the first converged frame and quit, or measure the latency
// from a camera drag to the preview on screen while the optimisation runs.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCommandLineParser>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QTimer>

#include <visopt/scenes.h>

#include "camera_navigation.h"
#include "command_line_files.h"
#include "main_window.h"
#include "panels/deviation_panel.h"
#include "viewport_widget.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

// Drags the camera while the optimisation runs and reports the time from each camera change to
// the frame that shows it. Each drag is a press, a small orbit and a release, followed by a
// pause in which the optimisation resumes, so every drag meets an iteration in flight. Then one
// continuous 3-second drag (previews on screen per second) and its release (the time to the first
// full-resolution frame of the resting view, and until that view has converged).
// With `framesDir`, the continuous drag's first preview, one a second after it and the first full
// frame of the resting view are saved there as drag-preview-N.png and rest-full.png, to be looked
// at.
int runLatencyProbe(MainWindow& window, int steps, const QString& framesDir) {
  ViewportWidget* view = window.viewport();
  const auto pump = [](int ms) {
    QElapsedTimer t;
    t.start();
    while (t.elapsed() < ms) QApplication::processEvents(QEventLoop::AllEvents, 5);
  };
  for (int i = 0; i < steps; ++i) {
    const int before = view->previewLatency().samples;
    view->setCamera(orbitCamera(view->camera(), 3.f, 0.f), true);
    QElapsedTimer t;
    t.start();
    while (view->previewLatency().samples == before && t.elapsed() < 30000)
      QApplication::processEvents(QEventLoop::AllEvents, 1);
    view->setCamera(view->camera(), false);
    pump(1500);  // the optimisation follows the new view meanwhile
  }
  window.waitForSettledFrame(60000);
  const LatencyStats s = view->previewLatency();

  // A continuous drag, as a hand does it: a small orbit every 16 ms (a 60 Hz mouse) for 3 s;
  // how many previews reach the screen per second.
  int previews = 0;
  const QMetaObject::Connection counting =
      QObject::connect(view, &ViewportWidget::frameShown, [&](const FrameInfo& info) {
        if (!info.preview) return;
        if (!framesDir.isEmpty() && (previews == 0 || previews == 10))
          view->frame().save(framesDir + QStringLiteral("/drag-preview-%1.png").arg(previews));
        ++previews;
      });
  const int followedBefore = window.controller()->followIterations();
  QElapsedTimer drag;
  drag.start();
  while (drag.elapsed() < 3000) {
    view->setCamera(orbitCamera(view->camera(), 0.4f, 0.f), true);
    pump(16);
  }
  const double previewsPerSecond = double(previews) * 1000.0 / double(drag.elapsed());
  QObject::disconnect(counting);
  const int followedDuringDrag = window.controller()->followIterations() - followedBefore;
  // The release: the time until the optimisation has converged for the resting view and a full
  // frame shows it.
  view->setCamera(view->camera(), false);
  QElapsedTimer rest;
  rest.start();
  double restToFullFrameMs = -1.0;  // the first full-resolution frame of the resting view
  const QMetaObject::Connection full =
      QObject::connect(view, &ViewportWidget::frameShown, [&](const FrameInfo& info) {
        if (!info.preview && restToFullFrameMs < 0.0) {
          restToFullFrameMs = double(rest.elapsed());
          if (!framesDir.isEmpty())
            view->frame().save(framesDir + QStringLiteral("/rest-full.png"));
        }
      });
  // What the resting view shows of the important structures: V_occ (visibility through
  // occluders) as the first finest iteration after the release measures it, before its own step
  // (the state the drag left), and as the last one before convergence.
  double restVisibility = -1.0, convergedVisibility = -1.0;
  const QMetaObject::Connection visibility =
      QObject::connect(window.controller(), &EngineController::iterationDone,
                       [&](const IterationStats& st, qulonglong) {
                         if (st.following) return;  // a coarse iteration, not the resting view's
                         if (restVisibility < 0.0) restVisibility = st.visibilityViewOccluders;
                         convergedVisibility = st.visibilityViewOccluders;
                       });
  const bool settled = window.waitForSettledFrame(300000);
  QObject::disconnect(full);
  QObject::disconnect(visibility);
  const double restToConvergedMs = settled ? double(rest.elapsed()) : -1.0;

  std::printf(
      "{\"latencyProbe\": {\"drags\": %d, \"framesMatched\": %d, \"meanMs\": %.1f, "
      "\"p95Ms\": %.1f, \"maxMs\": %.1f, \"previewRenderMeanMs\": %.1f, "
      "\"previewsPerSecondDuringDrag\": %.1f, \"restToFullFrameMs\": %.0f, "
      "\"restToConvergedMs\": %.0f, \"followIterationsDuringDrag\": %d, "
      "\"restVisibilityThroughOccluders\": %.3f, \"convergedVisibilityThroughOccluders\": %.3f}}\n",
      steps, s.samples, s.meanMs, s.p95Ms, s.maxMs, s.renderMeanMs, previewsPerSecond,
      restToFullFrameMs, restToConvergedMs, followedDuringDrag, restVisibility,
      convergedVisibility);
  return s.samples > 0 && settled ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // QGuiApplication takes "-session NAME" (X11 session management) out of argv before our parser
  // sees it, so "--session FILE" would open nothing: it reaches the parser as --open-session.
  std::vector<std::string> args(argv, argv + argc);
  for (size_t i = 1; i < args.size(); ++i) {
    if (args[i] == "--") break;
    for (const char* name : {"--session", "-session"})
      if (args[i] == name || args[i].rfind(std::string(name) + "=", 0) == 0)
        args[i] = "--open-session" + args[i].substr(std::strlen(name));
  }
  std::vector<char*> argvRenamed;
  for (std::string& a : args) argvRenamed.push_back(a.data());
  argvRenamed.push_back(nullptr);
  argc = int(args.size());
  argv = argvRenamed.data();
  QApplication app(argc, argv);
  QApplication::setApplicationName(QStringLiteral("visopt"));
  QApplication::setOrganizationName(QStringLiteral("visopt"));

  QCommandLineParser parser;
  parser.setApplicationDescription(
      QStringLiteral("visopt workstation: see what matters inside a volume"));
  parser.addHelpOption();
  QCommandLineOption scene(QStringLiteral("scene"), QStringLiteral("Open builtin:NAME."),
                           QStringLiteral("builtin:NAME"));
  QCommandLineOption volume(QStringLiteral("volume"),
                            QStringLiteral("Open a volume file or DICOM folder."),
                            QStringLiteral("FILE"));
  QCommandLineOption session(QStringList{QStringLiteral("session"), QStringLiteral("open-session")},
                             QStringLiteral("Open a session."), QStringLiteral("FILE"));
  QCommandLineOption resolution(QStringLiteral("resolution"),
                                QStringLiteral("Built-in scene resolution (default 128)."),
                                QStringLiteral("N"), QStringLiteral("128"));
  QCommandLineOption screenshot(
      QStringLiteral("screenshot"),
      QStringLiteral("Save the viewport after the first converged frame and quit."),
      QStringLiteral("PNG"));
  QCommandLineOption windowShot(
      QStringLiteral("window-screenshot"),
      QStringLiteral("Save the whole window after the first converged frame and quit."),
      QStringLiteral("PNG"));
  QCommandLineOption size(QStringLiteral("size"), QStringLiteral("Window size WxH."),
                          QStringLiteral("WxH"));
  QCommandLineOption noOptimize(QStringLiteral("no-optimize"),
                                QStringLiteral("Start with the optimisation paused."));
  QCommandLineOption latency(QStringLiteral("latency-probe"),
                             QStringLiteral("Drag the camera N times while optimising, print "
                                            "the drag-to-preview latency as JSON and quit."),
                             QStringLiteral("N"));
  QCommandLineOption probeFrames(QStringLiteral("probe-frames"),
                                 QStringLiteral("With --latency-probe: save frames of the drag and "
                                                "of the resting view in DIR."),
                                 QStringLiteral("DIR"));
  QCommandLineOption noFollow(QStringLiteral("no-drag-following"),
                              QStringLiteral("Do not optimise on the coarsest level while the "
                                             "camera is dragged (default: follow)."));
  QCommandLineOption stateDir(QStringLiteral("state-dir"),
                              QStringLiteral("Folder for autosave and recent sessions."),
                              QStringLiteral("DIR"));
  QCommandLineOption timeout(QStringLiteral("timeout"),
                             QStringLiteral("Seconds to wait for convergence (default 300)."),
                             QStringLiteral("S"), QStringLiteral("300"));
  QCommandLineOption saveTo(QStringLiteral("save-session"),
                            QStringLiteral("Save the session after the first converged frame "
                                           "and quit."),
                            QStringLiteral("FILE"));
  QCommandLineOption deviation(QStringLiteral("deviation-view"),
                               QStringLiteral("Start with the deviation view on."));
  QCommandLineOption tab(QStringLiteral("show-panel"),
                         QStringLiteral("Bring the dock panel with this title to the front."),
                         QStringLiteral("TITLE"));
  QCommandLineOption tool(QStringLiteral("tool"),
                          QStringLiteral("Start with the tool of this name (its tool bar text: "
                                         "Navigate, Paint mask, Lens, Window mask, Hotspot)."),
                          QStringLiteral("NAME"));
  parser.addOptions({scene, volume, session, resolution, screenshot, windowShot, size, noOptimize,
                     latency, probeFrames, noFollow, stateDir, timeout, saveTo, deviation, tab,
                     tool});
  parser.addPositionalArgument(
      QStringLiteral("files"),
      QStringLiteral("A volume file or DICOM folder, or a session (.visopt-session, .json), to "
                     "open; meshes (.ply .obj .off .stl) and level sets (.vdb) to add as "
                     "context surfaces."),
      QStringLiteral("[FILE...]"));
  parser.process(app);

  CommandLineFiles files = sortCommandLineFiles(parser.positionalArguments());
  addSceneOptions(files, {parser.value(volume), parser.value(session), parser.value(scene)});
  if (!files.error.isEmpty()) {
    std::fprintf(stderr, "visopt-workstation: %s\n", files.error.toUtf8().constData());
    return 2;
  }
  const QString volumePath = files.volume;
  const QString sessionPath = files.session;

  const bool scripted = parser.isSet(screenshot) || parser.isSet(windowShot) ||
                        parser.isSet(latency) || parser.isSet(saveTo);
  MainWindow window(Precision::FP32, parser.value(stateDir));
  window.setInteractive(!scripted);
  if (parser.isSet(size)) {
    const QStringList wh = parser.value(size).split('x');
    if (wh.size() == 2) window.resize(wh[0].toInt(), wh[1].toInt());
  }
  window.show();
  window.setOptimizationRunning(!parser.isSet(noOptimize));
  window.controller()->setFollowWhileDragging(!parser.isSet(noFollow));

  int failures = 0;
  QObject::connect(&window, &MainWindow::errorShown, [&](const QString& message) {
    std::fprintf(stderr, "visopt-workstation: %s\n", message.toUtf8().constData());
    ++failures;
  });

  const bool recovered =
      !scripted && sessionPath.isEmpty() && volumePath.isEmpty() && window.offerRecovery();
  if (!sessionPath.isEmpty()) {
    if (!window.openSession(sessionPath) && scripted) return 1;
  } else if (!volumePath.isEmpty()) {
    window.openVolume(volumePath);
  } else if (!recovered) {
    QString name = files.scene;
    if (name.startsWith(QStringLiteral("builtin:"))) name = name.mid(8);
    if (name.isEmpty()) name = QString::fromStdString(defaultSceneName());
    window.openBuiltinScene(name, parser.value(resolution).toInt());
  }

  for (const QString& source : files.surfaces) window.addContextSurface(source);

  if (parser.isSet(deviation)) {
    window.deviationPanel()->setDeviationSettings(true, Colormap::Viridis, 4.f);
    emit window.deviationPanel()->deviationSettingsChanged(true, Colormap::Viridis, 4.f);
  }
  for (const QString& title : parser.values(tab))
    for (QDockWidget* dock : window.findChildren<QDockWidget*>())
      if (dock->windowTitle().compare(title, Qt::CaseInsensitive) == 0) {
        dock->show();
        dock->raise();
      }

  if (parser.isSet(tool)) {
    QAction* chosen = nullptr;
    for (QAction* a : window.findChildren<QAction*>())
      if (a->isCheckable() && a->actionGroup() &&
          a->text().remove(QLatin1Char('&')).compare(parser.value(tool), Qt::CaseInsensitive) == 0)
        chosen = a;
    if (!chosen) {
      std::fprintf(stderr, "visopt-workstation: --tool: no tool named '%s'\n",
                   parser.value(tool).toUtf8().constData());
      return 2;
    }
    chosen->trigger();
  }

  if (!scripted) return app.exec();

  const int timeoutMs = parser.value(timeout).toInt() * 1000;
  // An error (a file that cannot be read, ...) ends a scripted run at once, with its message
  // already printed, rather than waiting for a frame that will not come.
  if (!window.waitForSettledFrame(timeoutMs, [&] { return failures > 0; })) {
    if (failures == 0)
      std::fprintf(stderr, "visopt-workstation: no converged frame within %d s\n",
                   timeoutMs / 1000);
    return 1;
  }
  if (failures > 0) return 1;
  int rc = 0;
  if (parser.isSet(latency))
    rc = runLatencyProbe(window, parser.value(latency).toInt(), parser.value(probeFrames));
  if (parser.isSet(screenshot) && !window.exportViewport(parser.value(screenshot))) rc = 1;
  if (parser.isSet(windowShot)) {
    QApplication::processEvents();
    if (!window.grab().save(parser.value(windowShot), "PNG")) rc = 1;
  }
  if (parser.isSet(saveTo) && !window.saveSessionTo(parser.value(saveTo))) rc = 1;
  window.close();
  return rc;
}
