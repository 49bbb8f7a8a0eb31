// Sessions in the workstation, end to end through MainWindow: a saved session reopens to the same
// scene (same session JSON, same rendered image, and the painted mask, the lens, the transfer
// function edit and the camera each come back), an older format version loads through the
// migration, corrupt and truncated files are reported without harming the open scene, a data
// file that moved with its session is found through the relative path and a missing one is
// reported and can be pointed to, a crash in the middle of a save leaves the previous file
// intact, and the autosave is offered after a crash (only then).
//
// Rendered images are compared with the optimisation paused in both windows (so the engines hold
// the same state: mu_bar from the transfer function, no optimised extinction), rendered through
// EngineController::call with fixed render settings (jitter on, fixed seed): bit-identical.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <QByteArray>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QProcess>
#include <QProcessEnvironment>
#include <QSignalSpy>
#include <QTest>

#include <visopt/camera.h>
#include <visopt/engine.h>
#include <visopt/image.h>
#include <visopt/scenes.h>
#include <visopt/session.h>
#include <visopt/volume_io.h>

#include "camera_navigation.h"
#include "main_window.h"
#include "panels/optimization_panel.h"
#include "tools/lens_tool.h"
#include "tools/mask_paint_tool.h"
#include "viewport_widget.h"
#include "widgets/curve_editor.h"
#include "widgets/transfer_function_editor.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

constexpr int kSettleMs = 240000;  // generous: the machine is shared

QString testRoot() {
  return QStringLiteral(VISOPT_TEST_TMP) + QStringLiteral("/workstation-sessions");
}

// An empty folder for one test.
QString freshDir(const QString& name) {
  const QString dir = testRoot() + QLatin1Char('/') + name;
  QDir(dir).removeRecursively();
  QDir().mkpath(dir);
  return dir;
}

std::unique_ptr<MainWindow> makeWindow(const QString& stateDir) {
  auto w = std::make_unique<MainWindow>(Precision::FP32, stateDir);
  w->setInteractive(false);
  w->setOptimizationRunning(false);
  // The window is never shown: keep the controller's own frames small.
  w->controller()->setViewportSize(96, 96);
  return w;
}

bool near(const Camera& a, const Camera& b, float tol = 1e-4f) {
  return glm::length(a.eye - b.eye) <= tol && glm::length(a.target - b.target) <= tol &&
         glm::length(a.up - b.up) <= tol && std::abs(a.fovYDegrees - b.fovYDegrees) <= tol;
}

QString describeCamera(const Camera& c) {
  return QStringLiteral("eye (%1 %2 %3) target (%4 %5 %6) fovY %7")
      .arg(double(c.eye.x))
      .arg(double(c.eye.y))
      .arg(double(c.eye.z))
      .arg(double(c.target.x))
      .arg(double(c.target.y))
      .arg(double(c.target.z))
      .arg(double(c.fovYDegrees));
}

Camera engineCamera(MainWindow& w) {
  Camera c;
  w.controller()->call([&](Engine& e) { c = e.camera(); });
  return c;
}

// The scene rendered with fixed settings (the session's own render settings, fixed size and
// seed), optionally after a fresh optimisation run of the engine's current settings.
Image renderFixed(MainWindow& w, const RenderSettings& sessionRender, bool optimize) {
  RenderSettings s = sessionRender;
  s.width = 80;
  s.height = 72;
  s.preview = false;
  s.jitter = true;
  s.seed = 7;
  Image image;
  w.controller()->call([&](Engine& e) {
    if (optimize) {
      e.setViewportSize(s.width, s.height);
      e.resetOptimization();
      e.optimize();
    }
    image = e.render(s);
  });
  return image;
}

size_t differingPixels(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) return size_t(-1);
  size_t n = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    if (a.pixels[i] != b.pixels[i]) ++n;
  return n;
}

std::string sessionJson(MainWindow& w, const QString& path) {
  return sessionToJson(w.currentSession(path), path.toStdString());
}

// QCOMPARE of two session JSON texts that shows where they differ.
bool sameJson(const std::string& actual, const std::string& expected, QByteArray* why) {
  if (actual == expected) return true;
  size_t i = 0;
  while (i < actual.size() && i < expected.size() && actual[i] == expected[i]) ++i;
  const size_t from = i > 60 ? i - 60 : 0;
  *why = "session JSON differs at " + QByteArray::number(qulonglong(i)) +
         ":\n  actual:   " + QByteArray::fromStdString(actual.substr(from, 160)) +
         "\n  expected: " + QByteArray::fromStdString(expected.substr(from, 160));
  return false;
}
#define COMPARE_JSON(actual, expected)                                 \
  do {                                                                 \
    QByteArray why_;                                                   \
    QVERIFY2(sameJson((actual), (expected), &why_), why_.constData()); \
  } while (false)

QByteArray readAll(const QString& path) {
  QFile f(path);
  if (!f.open(QIODevice::ReadOnly)) return {};
  return f.readAll();
}

bool writeAll(const QString& path, const QByteArray& bytes) {
  QFile f(path);
  if (!f.open(QIODevice::WriteOnly | QIODevice::Truncate)) return false;
  return f.write(bytes) == bytes.size();
}

// Runs the workstation executable (offscreen); returns its exit code, -1 when it crashed or
// did not finish.
int runWorkstation(const QStringList& args, const QProcessEnvironment& env, QString* log) {
  QProcess p;
  p.setProgram(QStringLiteral(VISOPT_WORKSTATION));
  p.setArguments(args);
  p.setProcessEnvironment(env);
  p.setProcessChannelMode(QProcess::MergedChannels);
  p.start();
  if (!p.waitForStarted(30000)) return -1;
  const bool finished = p.waitForFinished(300000);
  if (log) *log = QString::fromUtf8(p.readAll());
  if (!finished) {
    p.kill();
    p.waitForFinished(10000);
    return -1;
  }
  return p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1;
}

}  // namespace

class TestWorkstationSessions : public QObject {
  Q_OBJECT

 private slots:
  void initTestCase();
  void saveAndReopenGivesTheSameScene();
  void olderFormatVersionLoadsThroughTheMigration();
  void corruptAndTruncatedSessionsAreReportedAndTheSceneStays();
  void movedDataIsFoundAndMissingDataCanBeLocated();
  void crashDuringSaveLeavesThePreviousFileIntact();
  void autosaveIsOfferedAfterACrashOnly();
  void recentSessionsListTheSavedPathFirst();
  void sessionWithoutAMaskLeavesNoMaskInTheBrush();
  // Last: with the bug it reports, it ends the process (an exception out of an event handler).
  void maskOfOtherDimensionsIsReportedNotFatal();
};

void TestWorkstationSessions::initTestCase() {
  QDir(testRoot()).removeRecursively();
  QVERIFY(QDir().mkpath(testRoot()));
}

void TestWorkstationSessions::saveAndReopenGivesTheSameScene() {
  const QString dir = freshDir(QStringLiteral("roundtrip"));
  auto w1 = makeWindow(dir + QStringLiteral("/state1"));
  QSignalSpy errors1(w1.get(), &MainWindow::errorShown);
  w1->openBuiltinScene(QStringLiteral("shepp-logan"), 32);
  QVERIFY(w1->waitForSettledFrame(kSettleMs));
  const Session original = w1->currentSession();

  // A small optimisation budget (it goes into the session; the optimised comparison uses it).
  ExtinctionSettings ext = original.extinction;
  ext.levels = 1;
  ext.maxIterationsPerLevel = 6;
  ext.minIterationsPerLevel = 2;
  emit w1->optimizationPanel()->settingsEdited(ext, original.levelSet);

  // Camera.
  const Camera camera = orbitCamera(w1->viewport()->camera(), 35.f, 20.f);
  w1->viewport()->setCamera(camera, false);

  // Let the worker take the camera, so the mask brush picks along the same view.
  QVERIFY(w1->waitForSettledFrame(kSettleMs));

  // World mask: a stroke with the brush through the viewport's mouse events.
  MaskPaintTool* brush = w1->maskTool();
  w1->viewport()->setTool(brush);
  brush->setLiveUpdateInterval(1000000);
  const auto snap = w1->controller()->snapshot();
  QVERIFY(snap && snap->volume);
  const glm::vec3 extent =
      snap->volume->grid().worldBounds().hi - snap->volume->grid().worldBounds().lo;
  brush->setRadius(0.12f * std::max({extent.x, extent.y, extent.z}));
  PickOptions pick;
  pick.opacityThreshold = 0.02f;  // any visible tissue
  brush->setPickOptions(pick);
  QSignalSpy maskSpy(brush, &MaskPaintTool::maskChanged);
  ViewportWidget* view = w1->viewport();
  const QPoint c = view->rect().center();
  QTest::mousePress(view, Qt::LeftButton, {}, c);
  QTest::mouseMove(view, c + QPoint(view->width() / 10, 0));
  QTest::mouseMove(view, c + QPoint(view->width() / 10, view->height() / 12));
  QTest::mouseRelease(view, Qt::LeftButton, {},
                      c + QPoint(view->width() / 10, view->height() / 12));
  QVERIFY(maskSpy.count() >= 1);
  const auto painted = brush->mask();
  QVERIFY(painted);
  QVERIFY2(painted->count() > 20,
           qPrintable(QStringLiteral("%1 voxels painted").arg(painted->count())));
  w1->viewport()->setTool(nullptr);
  QVERIFY(w1->waitForSettledFrame(kSettleMs));
  QVERIFY(w1->modified());

  // Transfer function: through the curve editor, as a drag would, then flushed.
  TransferFunctionEditor* tfEditor = w1->transferFunctionEditor();
  CurveEditor* curve = tfEditor->curveEditor();
  std::vector<glm::dvec2> points = curve->points();
  QVERIFY(points.size() >= 2);
  for (glm::dvec2& p : points) p.y = 0.5 * p.y + 0.05;
  curve->setPoints(points);
  emit curve->pointsEdited();
  QVERIFY(tfEditor->editPending());
  tfEditor->flushPendingEdit();
  const TransferFunction editedTf = tfEditor->transferFunction();

  // Lens.
  LensTool* lens = w1->lensTool();
  lens->setLensOn(true);
  lens->setRadius(0.23f);
  lens->setStrength(3.5f);
  lens->setCentre(QPointF(0.375, 0.625));
  const ImportanceLens lensSet = lens->lens();
  QCOMPARE(lensSet.radius, 0.23f);

  QVERIFY(w1->waitForSettledFrame(kSettleMs));
  QVERIFY(w1->modified());

  // What the engine holds now.
  const Session before = w1->currentSession();
  QVERIFY(before.camera && near(*before.camera, camera));
  QCOMPARE(before.lens.radius, lensSet.radius);
  QCOMPARE(before.lens.strength, lensSet.strength);
  QCOMPARE(before.lens.x, lensSet.x);
  QVERIFY(before.worldMask && *before.worldMask == *painted);
  QVERIFY(before.transferFunction);
  QCOMPARE(before.transferFunction->opacity.size(), editedTf.opacity.size());
  for (size_t i = 0; i < editedTf.opacity.size(); ++i)
    QCOMPARE(before.transferFunction->opacity[i].opacity, editedTf.opacity[i].opacity);
  QCOMPARE(before.extinction.maxIterationsPerLevel, 6);
  // Each edit changed the session (otherwise the round trip would prove little).
  QVERIFY(!original.worldMask || !(*original.worldMask == *painted));
  QVERIFY(original.lens.radius != lensSet.radius);
  QVERIFY(original.camera && !near(*original.camera, camera));
  QVERIFY(original.transferFunction->opacity[0].opacity != editedTf.opacity[0].opacity);

  const QString path = dir + QStringLiteral("/saved/scene.visopt-session");
  QVERIFY(QDir().mkpath(QFileInfo(path).path()));
  QVERIFY(w1->saveSessionTo(path));
  QVERIFY(!w1->modified());
  QCOMPARE(w1->sessionPath(), QFileInfo(path).absoluteFilePath());
  const std::string jsonBefore = sessionJson(*w1, path);
  // The file holds exactly what the window holds.
  COMPARE_JSON(sessionToJson(loadSession(path.toStdString()), path.toStdString()), jsonBefore);
  const Image imageBefore = renderFixed(*w1, before.render, false);
  const Image optimizedBefore = renderFixed(*w1, before.render, true);
  QCOMPARE(errors1.count(), 0);

  // Reopen in a fresh window.
  auto w2 = makeWindow(dir + QStringLiteral("/state2"));
  QSignalSpy errors2(w2.get(), &MainWindow::errorShown);
  QSignalSpy loaded(w2.get(), &MainWindow::sessionLoaded);
  QVERIFY(w2->openSession(path));
  QVERIFY(w2->waitForSettledFrame(kSettleMs));
  QCOMPARE(loaded.count(), 1);
  QVERIFY2(errors2.isEmpty(),
           errors2.isEmpty() ? "" : qPrintable(errors2.first().first().toString()));
  QVERIFY(!w2->modified());

  const std::string jsonAfter = sessionJson(*w2, path);
  COMPARE_JSON(jsonAfter, jsonBefore);

  // Each edit came back, in the engine and in the tools and editors that show it.
  const Session after = w2->currentSession(path);
  QVERIFY(after.camera);
  QVERIFY2(near(*after.camera, camera), qPrintable(describeCamera(*after.camera)));
  QVERIFY2(near(w2->viewport()->camera(), camera),
           qPrintable(describeCamera(w2->viewport()->camera())));
  QVERIFY2(near(engineCamera(*w2), camera), qPrintable(describeCamera(engineCamera(*w2))));
  QVERIFY(after.worldMask && *after.worldMask == *painted);
  QVERIFY(w2->maskTool()->mask() && *w2->maskTool()->mask() == *painted);
  size_t engineMaskCount = 0;
  w2->controller()->call(
      [&](Engine& e) { engineMaskCount = e.worldMask() ? e.worldMask()->count() : 0; });
  QCOMPARE(engineMaskCount, painted->count());
  const ImportanceLens lensAfter = w2->lensTool()->lens();
  QCOMPARE(lensAfter.radius, lensSet.radius);
  QCOMPARE(lensAfter.strength, lensSet.strength);
  QCOMPARE(lensAfter.x, lensSet.x);
  QCOMPARE(lensAfter.y, lensSet.y);
  QCOMPARE(after.lens.radius, lensSet.radius);
  const TransferFunction tfAfter = w2->transferFunctionEditor()->transferFunction();
  QCOMPARE(tfAfter.opacity.size(), editedTf.opacity.size());
  for (size_t i = 0; i < editedTf.opacity.size(); ++i) {
    QCOMPARE(tfAfter.opacity[i].value, editedTf.opacity[i].value);
    QCOMPARE(tfAfter.opacity[i].opacity, editedTf.opacity[i].opacity);
  }
  QCOMPARE(after.extinction.maxIterationsPerLevel, 6);

  // The same image: with mu_bar (both engines unoptimised) and after the same optimisation.
  const Image imageAfter = renderFixed(*w2, after.render, false);
  QCOMPARE(differingPixels(imageBefore, imageAfter), size_t(0));
  const Image optimizedAfter = renderFixed(*w2, after.render, true);
  const double db = psnr(optimizedBefore, optimizedAfter);
  qInfo("optimised after save and reopen: %zu of %zu pixels differ (PSNR %.1f dB)",
        differingPixels(optimizedBefore, optimizedAfter), optimizedAfter.pixels.size(), db);
  QVERIFY2(differingPixels(optimizedBefore, optimizedAfter) == 0 || db >= 45.0,
           qPrintable(QStringLiteral("optimised images differ: PSNR %1 dB").arg(db)));
  // The comparison can see a difference: the mask overlay and the lens change the image.
  QVERIFY(differingPixels(imageAfter, optimizedAfter) > 0);
  QCOMPARE(errors2.count(), 0);
}

void TestWorkstationSessions::olderFormatVersionLoadsThroughTheMigration() {
  const QString dir = freshDir(QStringLiteral("migration"));
  // Version 1: the camera as an orbit, the transfer function under "tf".
  const QString path = dir + QStringLiteral("/old.visopt-session");
  const QByteArray v1 = R"({"format": "visopt-session", "version": 1,
    "data": {"builtin": "shepp-logan", "resolution": 24},
    "tf": {"format": "visopt-transfer-function", "version": 1, "name": "from-v1",
           "unitDistance": 0, "opacity": [[0, 0], [0.3, 0.02], [1, 0.4]],
           "color": [[0, 1, 1, 1], [1, 1, 0.5, 0.2]]},
    "camera": {"target": [0.01, 0.02, 0.03], "azimuth": 40, "elevation": 25, "distance": 4.5,
               "fovY": 28}})";
  QVERIFY(writeAll(path, v1));
  const Camera expected = [] {
    Camera c = Camera::orbit(glm::vec3(0.01f, 0.02f, 0.03f), 40.f, 25.f, 4.5f);
    c.fovYDegrees = 28.f;
    return c;
  }();

  auto w = makeWindow(dir + QStringLiteral("/state"));
  QSignalSpy errors(w.get(), &MainWindow::errorShown);
  QVERIFY(w->openSession(path));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY2(errors.isEmpty(), errors.isEmpty() ? "" : qPrintable(errors.first().first().toString()));
  QVERIFY2(near(w->viewport()->camera(), expected),
           qPrintable(describeCamera(w->viewport()->camera())));
  QVERIFY2(near(engineCamera(*w), expected), qPrintable(describeCamera(engineCamera(*w))));
  const Session s = w->currentSession(path);
  QCOMPARE(s.builtinScene, std::string("shepp-logan"));
  QCOMPARE(s.builtinResolution, 24);
  QVERIFY(s.transferFunction);
  QCOMPARE(s.transferFunction->name, std::string("from-v1"));
  QCOMPARE(s.transferFunction->opacity.size(), size_t(3));
  QCOMPARE(w->transferFunctionEditor()->transferFunction().opacity.size(), size_t(3));
  // Saving writes the current version.
  const QString resaved = dir + QStringLiteral("/resaved.visopt-session");
  QVERIFY(w->saveSessionTo(resaved));
  QCOMPARE(loadSession(resaved.toStdString()).version, kSessionFormatVersion);
}

void TestWorkstationSessions::corruptAndTruncatedSessionsAreReportedAndTheSceneStays() {
  const QString dir = freshDir(QStringLiteral("corrupt"));
  auto w = makeWindow(dir + QStringLiteral("/state"));
  w->openBuiltinScene(QStringLiteral("shepp-logan"), 24);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const Camera camera = orbitCamera(w->viewport()->camera(), -50.f, 10.f);
  w->viewport()->setCamera(camera, false);
  const QString good = dir + QStringLiteral("/good.visopt-session");
  QVERIFY(w->saveSessionTo(good));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const QByteArray bytes = readAll(good);
  QVERIFY(bytes.size() > 100);
  const std::string jsonBefore = sessionJson(*w, good);

  QByteArray corrupt = bytes;
  corrupt.replace(corrupt.size() / 3, 12, QByteArray("\x01#!@ garbage"));
  struct Bad {
    QString name;
    QByteArray content;
  };
  const std::vector<Bad> bad = {
      {QStringLiteral("corrupted.visopt-session"), corrupt},
      {QStringLiteral("truncated.visopt-session"), bytes.left(bytes.size() / 2)},
      {QStringLiteral("empty.visopt-session"), QByteArray()},
      {QStringLiteral("newer.visopt-session"),
       QByteArray(R"({"format": "visopt-session", "version": 99})")},
  };
  for (const Bad& b : bad) {
    const QString path = dir + QLatin1Char('/') + b.name;
    QVERIFY(writeAll(path, b.content));
    QSignalSpy errors(w.get(), &MainWindow::errorShown);
    QSignalSpy loaded(w.get(), &MainWindow::sessionLoaded);
    QVERIFY2(!w->openSession(path), qPrintable(b.name));
    QCOMPARE(errors.count(), 1);
    const QString message = errors.first().first().toString();
    QVERIFY2(message.contains(b.name), qPrintable(message));
    QCOMPARE(loaded.count(), 0);
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    QCOMPARE(errors.count(), 1);
    // The previous scene is still there, untouched.
    QCOMPARE(w->sessionPath(), QFileInfo(good).absoluteFilePath());
    QVERIFY(near(w->viewport()->camera(), camera));
    COMPARE_JSON(sessionJson(*w, good), jsonBefore);
  }
  // The recent list only holds sessions that opened.
  for (const QString& recent : w->sessionFiles().recentSessions())
    QVERIFY2(recent == QFileInfo(good).absoluteFilePath(), qPrintable(recent));

  // And the application goes on working.
  QSignalSpy errors(w.get(), &MainWindow::errorShown);
  w->openBuiltinScene(QStringLiteral("marschner-lobb"), 20);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QCOMPARE(errors.count(), 0);
  QCOMPARE(w->currentSession().builtinScene, std::string("marschner-lobb"));
  QVERIFY(!w->viewport()->frame().isNull());
  QVERIFY(w->openSession(good));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  COMPARE_JSON(sessionJson(*w, good), jsonBefore);
  QCOMPARE(errors.count(), 0);
}

void TestWorkstationSessions::movedDataIsFoundAndMissingDataCanBeLocated() {
  const QString root = freshDir(QStringLiteral("moved"));
  const QString dirA = root + QStringLiteral("/A");
  const QString dirB = root + QStringLiteral("/B");
  QVERIFY(QDir().mkpath(dirA + QStringLiteral("/data")));
  QVERIFY(QDir().mkpath(dirA + QStringLiteral("/sessions")));
  {
    const BuiltinScene scene = makeBuiltinScene("shepp-logan", 20, Precision::FP32);
    writeVolume(scene.volume, (dirA + QStringLiteral("/data/blob.nii")).toStdString());
  }
  const QString sessionA = dirA + QStringLiteral("/sessions/s.visopt-session");
  const QString sessionB = dirB + QStringLiteral("/sessions/s.visopt-session");

  Camera camera;
  std::string jsonA;
  {
    auto w = makeWindow(root + QStringLiteral("/state1"));
    QSignalSpy errors(w.get(), &MainWindow::errorShown);
    w->openVolume(dirA + QStringLiteral("/data/blob.nii"));
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    camera = orbitCamera(w->viewport()->camera(), 60.f, -15.f);
    w->viewport()->setCamera(camera, false);
    QVERIFY(w->saveSessionTo(sessionA));
    QCOMPARE(errors.count(), 0);
    jsonA = sessionJson(*w, sessionA);
  }
  const Session saved = loadSession(sessionA.toStdString());
  QVERIFY(saved.builtinScene.empty());
  QCOMPARE(QString::fromStdString(saved.volume.relativePath), QStringLiteral("../data/blob.nii"));

  // Move the whole folder: the absolute path is gone, the relative one finds it.
  QVERIFY(QDir().rename(dirA, dirB));
  QVERIFY(!QFileInfo::exists(dirA));
  const auto reports =
      checkSessionData(loadSession(sessionB.toStdString()), sessionB.toStdString());
  QCOMPARE(reports.size(), size_t(1));
  QCOMPARE(reports[0].role, std::string("volume"));
  QCOMPARE(reports[0].status, DataStatus::Moved);
  QCOMPARE(QFileInfo(QString::fromStdString(reports[0].resolvedPath)).canonicalFilePath(),
           QFileInfo(dirB + QStringLiteral("/data/blob.nii")).canonicalFilePath());
  {
    auto w = makeWindow(root + QStringLiteral("/state2"));
    QSignalSpy errors(w.get(), &MainWindow::errorShown);
    int hookCalls = 0;
    w->setLocateHook([&](const QString&, const QString&) {
      ++hookCalls;
      return QString();
    });
    QVERIFY(w->openSession(sessionB));
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    QVERIFY2(errors.isEmpty(),
             errors.isEmpty() ? "" : qPrintable(errors.first().first().toString()));
    QCOMPARE(hookCalls, 0);  // a moved file needs no question
    std::string source;
    w->controller()->call([&](Engine& e) { source = e.volume().sourcePath; });
    QCOMPARE(QFileInfo(QString::fromStdString(source)).canonicalFilePath(),
             QFileInfo(dirB + QStringLiteral("/data/blob.nii")).canonicalFilePath());
    QVERIFY(near(w->viewport()->camera(), camera));
    // Saved again from its new place, it names the new place.
    const Session now = w->currentSession(sessionB);
    QCOMPARE(QFileInfo(QString::fromStdString(now.volume.absolutePath)).canonicalFilePath(),
             QFileInfo(dirB + QStringLiteral("/data/blob.nii")).canonicalFilePath());
  }

  // Now the file is gone from both places; a copy lies elsewhere.
  const QString elsewhere = root + QStringLiteral("/elsewhere/copy-of-blob.nii");
  QVERIFY(QDir().mkpath(QFileInfo(elsewhere).path()));
  QVERIFY(QFile::rename(dirB + QStringLiteral("/data/blob.nii"), elsewhere));
  {
    auto w = makeWindow(root + QStringLiteral("/state3"));
    w->openBuiltinScene(QStringLiteral("shepp-logan"), 24);
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    const std::string jsonBuiltin = sessionJson(*w, {});

    QSignalSpy errors(w.get(), &MainWindow::errorShown);
    QVERIFY(!w->openSession(sessionB));  // no hook, not interactive: reported, not loaded
    QCOMPARE(errors.count(), 1);
    const QString message = errors.first().first().toString();
    QVERIFY2(message.contains(QStringLiteral("blob.nii")), qPrintable(message));
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    COMPARE_JSON(sessionJson(*w, {}), jsonBuiltin);  // the scene stays

    QString hookRole, hookRecorded;
    w->setLocateHook([&](const QString& role, const QString& recorded) {
      hookRole = role;
      hookRecorded = recorded;
      return elsewhere;
    });
    errors.clear();
    QVERIFY(w->openSession(sessionB));
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    QVERIFY2(errors.isEmpty(),
             errors.isEmpty() ? "" : qPrintable(errors.first().first().toString()));
    QCOMPARE(hookRole, QStringLiteral("volume"));
    QVERIFY2(hookRecorded.endsWith(QStringLiteral("blob.nii")), qPrintable(hookRecorded));
    std::string source;
    w->controller()->call([&](Engine& e) { source = e.volume().sourcePath; });
    QCOMPARE(QFileInfo(QString::fromStdString(source)).canonicalFilePath(),
             QFileInfo(elsewhere).canonicalFilePath());
    QVERIFY(near(w->viewport()->camera(), camera));
  }

  // Back at its place with other content of the same size: the session opens without reading
  // the file first (sizes only: no question asked), and the content check once the scene shows
  // reports the change.
  const QString atPlace = dirB + QStringLiteral("/data/blob.nii");
  QVERIFY(QFile::copy(elsewhere, atPlace));
  {
    QFile f(atPlace);
    QVERIFY(f.open(QIODevice::ReadWrite));
    QVERIFY(f.seek(f.size() - 1));
    char last = 0;
    QVERIFY(f.getChar(&last));
    QVERIFY(f.seek(f.size() - 1));
    QVERIFY(f.putChar(char(last ^ 0x01)));
  }
  {
    auto w = makeWindow(root + QStringLiteral("/state4"));
    int hookCalls = 0;
    w->setLocateHook([&](const QString&, const QString&) {
      ++hookCalls;
      return QString();
    });
    QSignalSpy errors(w.get(), &MainWindow::errorShown);
    QVERIFY(w->openSession(sessionB));
    QCOMPARE(hookCalls, 0);
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    QTRY_COMPARE_WITH_TIMEOUT(errors.count(), 1, kSettleMs);
    const QString message = errors.first().first().toString();
    QVERIFY2(message.contains(QStringLiteral("not the file the session was saved with")),
             qPrintable(message));
    std::string source;
    w->controller()->call([&](Engine& e) { source = e.volume().sourcePath; });
    QCOMPARE(QFileInfo(QString::fromStdString(source)).canonicalFilePath(),
             QFileInfo(atPlace).canonicalFilePath());  // still used, as the CLI does
  }
}

void TestWorkstationSessions::crashDuringSaveLeavesThePreviousFileIntact() {
  const QString dir = freshDir(QStringLiteral("crash-save"));
  const QString file = dir + QStringLiteral("/kept.visopt-session");
  QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
  env.insert(QStringLiteral("QT_QPA_PLATFORM"), QStringLiteral("offscreen"));
  env.remove(QStringLiteral("VISOPT_SESSION_FAULT"));
  const QStringList common = {QStringLiteral("--no-optimize"),
                              QStringLiteral("--size"),
                              QStringLiteral("400x300"),
                              QStringLiteral("--timeout"),
                              QStringLiteral("240"),
                              QStringLiteral("--state-dir"),
                              dir + QStringLiteral("/state"),
                              QStringLiteral("--save-session"),
                              file};
  QString log;
  QCOMPARE(
      runWorkstation(QStringList{QStringLiteral("--scene"), QStringLiteral("builtin:shepp-logan"),
                                 QStringLiteral("--resolution"), QStringLiteral("24")} +
                         common,
                     env, &log),
      0);
  const QByteArray first = readAll(file);
  QVERIFY2(!first.isEmpty(), qPrintable(log));
  QCOMPARE(loadSession(file.toStdString()).builtinScene, std::string("shepp-logan"));

  // Another scene, killed in the middle of writing it.
  const QStringList other =
      QStringList{QStringLiteral("--scene"), QStringLiteral("builtin:marschner-lobb"),
                  QStringLiteral("--resolution"), QStringLiteral("20")} +
      common;
  QProcessEnvironment faulty = env;
  faulty.insert(QStringLiteral("VISOPT_SESSION_FAULT"), QStringLiteral("mid-write"));
  QCOMPARE(runWorkstation(other, faulty, &log), 70);
  QCOMPARE(readAll(file), first);
  const Session kept = loadSession(file.toStdString());
  QCOMPARE(kept.builtinScene, std::string("shepp-logan"));
  QCOMPARE(kept.builtinResolution, 24);

  // Control: without the fault the same run replaces the file.
  QCOMPARE(runWorkstation(other, env, &log), 0);
  QVERIFY(readAll(file) != first);
  QCOMPARE(loadSession(file.toStdString()).builtinScene, std::string("marschner-lobb"));
}

void TestWorkstationSessions::autosaveIsOfferedAfterACrashOnly() {
  const QString dir = freshDir(QStringLiteral("autosave"));
  const QString state = dir + QStringLiteral("/state");
  Camera camera;
  std::string json;
  {
    auto w = makeWindow(state);
    QVERIFY(!w->sessionFiles().previousRunCrashed());
    QVERIFY(!w->offerRecovery());
    w->openBuiltinScene(QStringLiteral("shepp-logan"), 24);
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    camera = orbitCamera(w->viewport()->camera(), 25.f, 30.f);
    w->viewport()->setCamera(camera, false);
    QVERIFY(w->autosaveNow());
    QVERIFY(QFileInfo::exists(w->sessionFiles().autosavePath()));
    QVERIFY(QFileInfo::exists(w->sessionFiles().runningMarkerPath()));
    json = sessionJson(*w, {});
    // A crash: the window goes without closing (no clean-exit mark).
  }
  QVERIFY(QFileInfo::exists(state + QStringLiteral("/running.marker")));
  {
    auto w = makeWindow(state);
    QVERIFY(w->sessionFiles().previousRunCrashed());
    QSignalSpy errors(w.get(), &MainWindow::errorShown);
    QVERIFY(w->offerRecovery());
    QVERIFY(w->waitForSettledFrame(kSettleMs));
    QCOMPARE(errors.count(), 0);
    QVERIFY2(near(w->viewport()->camera(), camera),
             qPrintable(describeCamera(w->viewport()->camera())));
    COMPARE_JSON(sessionJson(*w, {}), json);
    QVERIFY(w->sessionPath().isEmpty());  // saved under a name the user picks
    QVERIFY(w->modified());
    QVERIFY(w->sessionFiles().recentSessions().isEmpty());  // the autosave is no recent session
    // A clean exit.
    w->close();
  }
  QVERIFY(!QFileInfo::exists(state + QStringLiteral("/running.marker")));
  {
    auto w = makeWindow(state);
    QVERIFY(!w->sessionFiles().previousRunCrashed());
    QVERIFY(!w->offerRecovery());
  }
  // A marker without an autosave (crash before the first autosave) offers nothing either.
  {
    auto w = makeWindow(state);
    QVERIFY(QFileInfo::exists(w->sessionFiles().runningMarkerPath()));
    QVERIFY(!QFileInfo::exists(w->sessionFiles().autosavePath()));
    QVERIFY(!w->offerRecovery());
  }
}

void TestWorkstationSessions::recentSessionsListTheSavedPathFirst() {
  const QString dir = freshDir(QStringLiteral("recent"));
  auto w = makeWindow(dir + QStringLiteral("/state"));
  w->openBuiltinScene(QStringLiteral("marschner-lobb"), 16);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const QString a = dir + QStringLiteral("/a.visopt-session");
  const QString b = dir + QStringLiteral("/b.visopt-session");
  QVERIFY(w->saveSessionTo(a));
  QCOMPARE(w->sessionFiles().recentSessions().value(0), QFileInfo(a).absoluteFilePath());
  QVERIFY(w->saveSessionTo(b));
  QStringList recent = w->sessionFiles().recentSessions();
  QCOMPARE(recent.size(), 2);
  QCOMPARE(recent.value(0), QFileInfo(b).absoluteFilePath());
  QCOMPARE(recent.value(1), QFileInfo(a).absoluteFilePath());
  QVERIFY(w->openSession(a));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  recent = w->sessionFiles().recentSessions();
  QCOMPARE(recent, QStringList({QFileInfo(a).absoluteFilePath(), QFileInfo(b).absoluteFilePath()}));
  // The list is kept in the state folder: another window sees it.
  auto other = makeWindow(dir + QStringLiteral("/state"));
  QCOMPARE(other->sessionFiles().recentSessions(), recent);
}

// Opening a session replaces the whole scene, the world mask included: a session without a mask
// leaves none, in the engine and in the brush (whose next stroke would otherwise bring the old
// mask back into the engine).
void TestWorkstationSessions::sessionWithoutAMaskLeavesNoMaskInTheBrush() {
  const QString dir = freshDir(QStringLiteral("no-mask"));
  auto w = makeWindow(dir + QStringLiteral("/state"));
  w->openBuiltinScene(QStringLiteral("shepp-logan"), 24);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const QString plain = dir + QStringLiteral("/plain.visopt-session");
  QVERIFY(w->saveSessionTo(plain));
  QVERIFY(!loadSession(plain.toStdString()).worldMask);

  const auto snap = w->controller()->snapshot();
  QVERIFY(snap && snap->volume);
  SessionMask mask = SessionMask::cleared(snap->volume->grid().dims);
  for (size_t i = 0; i < mask.voxelCount(); i += 7) mask.set(i, true);
  w->maskTool()->setMask(mask);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  size_t engineCount = 0;
  w->controller()->call(
      [&](Engine& e) { engineCount = e.worldMask() ? e.worldMask()->count() : 0; });
  QCOMPARE(engineCount, mask.count());

  QVERIFY(w->openSession(plain));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  bool engineHasMask = true;
  w->controller()->call(
      [&](Engine& e) { engineHasMask = e.worldMask() && e.worldMask()->count() > 0; });
  QVERIFY(!engineHasMask);
  const auto brushMask = w->maskTool()->mask();
  QVERIFY2(!brushMask || brushMask->count() == 0,
           qPrintable(QStringLiteral("the brush still holds %1 voxels of the previous mask")
                          .arg(brushMask ? brushMask->count() : 0)));
}

// A session whose mask does not fit its volume (here: the built-in scene's resolution was
// changed; as well: a data file replaced by one of other dimensions) loads with a warning.
void TestWorkstationSessions::maskOfOtherDimensionsIsReportedNotFatal() {
  const QString dir = freshDir(QStringLiteral("mask-dims"));
  auto w = makeWindow(dir + QStringLiteral("/state"));
  w->openBuiltinScene(QStringLiteral("shepp-logan"), 24);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const auto snap = w->controller()->snapshot();
  QVERIFY(snap && snap->volume);
  SessionMask mask = SessionMask::cleared(snap->volume->grid().dims);
  for (size_t i = 0; i < mask.voxelCount(); i += 5) mask.set(i, true);
  w->maskTool()->setMask(mask);
  const QString path = dir + QStringLiteral("/masked.visopt-session");
  QVERIFY(w->saveSessionTo(path));
  QByteArray json = readAll(path);
  QVERIFY(json.contains("\"resolution\": 24"));
  json.replace("\"resolution\": 24", "\"resolution\": 20");
  const QString other = dir + QStringLiteral("/other-resolution.visopt-session");
  QVERIFY(writeAll(other, json));

  QSignalSpy errors(w.get(), &MainWindow::errorShown);
  QVERIFY(w->openSession(other));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(!errors.isEmpty());
  const QString message = errors.first().first().toString();
  QVERIFY2(message.contains(QStringLiteral("mask")), qPrintable(message));
  QCOMPARE(w->currentSession().builtinResolution, 20);
  bool engineHasMask = true;
  w->controller()->call([&](Engine& e) { engineHasMask = e.worldMask() != nullptr; });
  QVERIFY(!engineHasMask);
  // Still usable.
  w->openBuiltinScene(QStringLiteral("marschner-lobb"), 16);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QCOMPARE(w->currentSession().builtinScene, std::string("marschner-lobb"));
}

QTEST_MAIN(TestWorkstationSessions)
#include "test_workstation_sessions.moc"
