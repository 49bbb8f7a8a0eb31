// The Hotspot tool (ClearView, Krüger et al. 2006) end to end through MainWindow: H makes the 3D
// view show Engine::renderClearView; the hotspot follows the cursor by compositing only, onto the
// frame's own pixels whatever its size, and only the newest of many quick moves is rendered; the
// wheel scales the hotspot's size; a camera drag still orbits (and extracts again); a setting in
// the Hotspot panel changes the frame; a combination the library refuses is a message in the
// panel and the status bar, never a crash or a dialog; a session keeps the settings.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QLabel>
#include <QPushButton>
#include <QSignalSpy>
#include <QStatusBar>
#include <QTest>
#include <QWheelEvent>

#include <visopt/engine.h>
#include <visopt/image.h>
#include <visopt/session.h>

#include "clearview_frames.h"
#include "hotspot_mode.h"
#include "main_window.h"
#include "panels/hotspot_panel.h"
#include "tools/hotspot_tool.h"
#include "viewport_widget.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

constexpr int kSettleMs = 240000;  // generous: the machine is shared

QString testRoot() {
  return QStringLiteral(VISOPT_TEST_TMP) + QStringLiteral("/hotspot-tool");
}

QString freshDir(const QString& name) {
  const QString dir = testRoot() + QLatin1Char('/') + name;
  QDir(dir).removeRecursively();
  QDir().mkpath(dir);
  return dir;
}

// A shown window (hover events reach only a shown widget) with the optimisation paused.
std::unique_ptr<MainWindow> makeWindow(const QString& name) {
  auto w = std::make_unique<MainWindow>(Precision::FP32, freshDir(name) + QStringLiteral("/state"));
  w->setInteractive(false);
  w->setOptimizationRunning(false);
  w->resize(900, 700);
  w->show();
  return w;
}

std::unique_ptr<MainWindow> openScene(const QString& name) {
  auto w = makeWindow(name);
  w->openBuiltinScene(QStringLiteral("shepp-logan"), 40);
  return w;
}

// The frame settled, also after the status bar's first texts have changed the layout (and so
// the 3D view's size).
bool settle(MainWindow& w) {
  if (!w.waitForSettledFrame(kSettleMs)) return false;
  QTest::qWait(600);
  return w.waitForSettledFrame(kSettleMs);
}

// Brings the Hotspot panel to the front of its tabbed column.
void showHotspotPanel(MainWindow& w) {
  for (QDockWidget* dock : w.findChildren<QDockWidget*>())
    if (dock->windowTitle() == QStringLiteral("Hotspot")) {
      dock->show();
      dock->raise();
    }
  QApplication::processEvents();
}

// Activates the window and presses H in the 3D view, as a user does.
bool pressH(MainWindow& w) {
  w.activateWindow();
  if (!QTest::qWaitForWindowActive(&w)) return false;
  w.viewport()->setFocus();
  QTest::keyClick(w.viewport(), Qt::Key_H);
  return w.viewport()->tool() == w.hotspotTool();
}

void sendWheel(QWidget* widget, QPoint pos, int angle) {
  QWheelEvent event(QPointF(pos), widget->mapToGlobal(QPointF(pos)), QPoint(), QPoint(0, angle),
                    Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
  QApplication::sendEvent(widget, &event);
}

// Every frame the viewport shows from now on, with what it says about itself.
struct FrameLog {
  struct Entry {
    QImage image;
    FrameInfo info;
  };
  std::vector<Entry> frames;
  QMetaObject::Connection connection;
  explicit FrameLog(ViewportWidget* view) {
    connection = QObject::connect(view, &ViewportWidget::frameShown, view,
                                  [this, view](const FrameInfo& info) {
                                    frames.push_back({view->frame(), info});
                                  });
  }
  ~FrameLog() { QObject::disconnect(connection); }
  int clearViewFrames() const {
    return int(std::count_if(frames.begin(), frames.end(),
                             [](const Entry& e) { return e.info.clearView; }));
  }
};

size_t differingPixels(const QImage& a, const QImage& b) {
  if (a.size() != b.size()) return size_t(-1);
  const QImage x = a.convertToFormat(QImage::Format_RGBA8888);
  const QImage y = b.convertToFormat(QImage::Format_RGBA8888);
  size_t n = 0;
  for (int row = 0; row < x.height(); ++row) {
    const auto* p = reinterpret_cast<const uint32_t*>(x.constScanLine(row));
    const auto* q = reinterpret_cast<const uint32_t*>(y.constScanLine(row));
    for (int col = 0; col < x.width(); ++col) n += p[col] != q[col];
  }
  return n;
}

// The image the library gives for these settings, as the viewport would show it (Image::toSrgb8:
// the frame must be this, byte for byte).
QImage expectedFrame(MainWindow& w, const ClearViewSettings& settings) {
  Image image;
  w.controller()->call([&](Engine& e) { image = e.renderClearView(settings); });
  const std::vector<uint8_t> rgba = image.toSrgb8();
  return QImage(rgba.data(), image.width, image.height, QImage::Format_RGBA8888).copy();
}

// The pixel the controller renders the hotspot at for a cursor at `pos` over `view`, in a frame
// of `frame` pixels.
glm::vec2 focusPixelFor(QPoint pos, QSize view, QSize frame) {
  const QPointF f = HotspotTool::fractionOf(QPointF(pos), view);
  const glm::vec2 size(float(frame.width()), float(frame.height()));
  return glm::clamp(glm::vec2(float(f.x()), float(f.y())) * size, glm::vec2(0.f), size - 0.5f);
}

QString statusBarText(MainWindow& w) {
  QString all;
  for (QLabel* label : w.statusBar()->findChildren<QLabel*>())
    all += label->text() + QLatin1Char('\n');
  return all + w.statusBar()->currentMessage();
}

// A float32 volume with a JSON sidecar (no importance, no context surface): a bright ball inside
// a dimmer shell.
QString writeBallVolume(const QString& dir) {
  const int n = 24;
  std::vector<float> v(size_t(n) * n * n);
  size_t i = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int x = 0; x < n; ++x) {
        const glm::vec3 p = (glm::vec3(x, j, k) + 0.5f) / float(n) - 0.5f;
        const float r = glm::length(p);
        v[i++] = r < 0.18f ? 1.f : (r < 0.36f ? 0.4f : 0.f);
      }
  const QString path = dir + QStringLiteral("/ball.raw");
  std::ofstream(path.toStdString(), std::ios::binary)
      .write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
  std::ofstream(path.toStdString() + ".json")
      << R"({"dims":[24,24,24],"type":"float32","spacing":[1,1,1]})";
  return path;
}

}  // namespace

class TestHotspotTool : public QObject {
  Q_OBJECT
 private slots:
  void initTestCase();
  void hShowsClearViewAndTheCursorOnlyComposites();
  void quickMovesRenderOnlyTheNewestOntoTheFramesPixels();
  void wheelScalesTheSizeAndDragOrbits();
  void panelSettingsChangeTheFrame();
  void refusedCombinationsAreMessagesNotCrashes();
  void sessionKeepsTheHotspotSettings();
  void secondLayersChangeTheFrameAndAreKept();
  void optimiseAroundTheHotspotMakesItTheImportance();
};

void TestHotspotTool::initTestCase() {
  QDir(testRoot()).removeRecursively();
  QVERIFY(QDir().mkpath(testRoot()));
}

void TestHotspotTool::hShowsClearViewAndTheCursorOnlyComposites() {
  auto w = openScene(QStringLiteral("h"));
  QVERIFY(settle(*w));
  ViewportWidget* view = w->viewport();
  const QImage normal = view->frame();
  QVERIFY(!w->hotspotMode()->active());

  QSignalSpy iterations(w->controller(), &EngineController::iterationDone);
  FrameLog log(view);
  QVERIFY(pressH(*w));
  QVERIFY(w->hotspotMode()->active());
  QVERIFY(w->controller()->clearView().has_value());
  // The optimisation waits while ClearView is on (and the worker still goes idle).
  w->setOptimizationRunning(true);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(log.clearViewFrames() >= 1);
  QVERIFY(log.frames.back().info.clearView);
  const FrameInfo first = log.frames.back().info;
  QVERIFY(first.clearViewStats.extractions >= 1);
  QVERIFY(first.clearViewStats.contextPixels > 0);  // the skull (context surface 0)
  QVERIFY(first.clearViewStats.focusPixels > 0);    // the tumours (importance 0.5)
  // Not the normal render (of the same view, at the same size).
  const QImage clearView = view->frame();
  const size_t changed = differingPixels(clearView, normal.scaled(clearView.size()));
  QVERIFY2(changed > size_t(clearView.width() * clearView.height() / 10),
           qPrintable(QStringLiteral("%1 pixels differ from the normal render").arg(changed)));
  // The panel and the status bar say ClearView.
  QVERIFY(w->hotspotMode()->statusText().startsWith(QStringLiteral("ClearView")));
  QTest::qWait(700);  // the status label is refreshed twice a second
  QVERIFY2(statusBarText(*w).contains(QStringLiteral("ClearView")), qPrintable(statusBarText(*w)));
  QVERIFY(!w->hotspotPanel()->statsText().isEmpty());
  QVERIFY(w->hotspotMode()->problem().isEmpty());

  // The cursor moves the hotspot: a new frame, composited only.
  const int64_t extractions = first.clearViewStats.extractions;
  const QImage before = view->frame();
  const size_t framesBefore = log.frames.size();
  QTest::mouseMove(view, QPoint(view->width() / 3, view->height() / 3));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(log.frames.size() > framesBefore);
  const FrameInfo moved = log.frames.back().info;
  QVERIFY(moved.clearView);
  QVERIFY(!moved.clearViewStats.extracted);
  QCOMPARE(moved.clearViewStats.extractions, extractions);
  QVERIFY2(
      differingPixels(view->frame(), before) > 100,
      qPrintable(QStringLiteral("%1 pixels changed").arg(differingPixels(view->frame(), before))));
  const QPointF f = w->hotspotTool()->focus();
  QVERIFY(std::abs(f.x() - 1.0 / 3.0) < 0.01 && std::abs(f.y() - 1.0 / 3.0) < 0.01);
  QCOMPARE(iterations.count(), 0);

  // N (or any other tool) goes back to the normal render, and the optimisation resumes.
  QTest::keyClick(view, Qt::Key_N);
  QVERIFY(!w->hotspotMode()->active());
  QVERIFY(!w->controller()->clearView().has_value());
  QTRY_VERIFY_WITH_TIMEOUT(iterations.count() > 0, kSettleMs);
  w->setOptimizationRunning(false);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(!log.frames.back().info.clearView);
  QVERIFY(w->hotspotMode()->statusText().isEmpty());
}

void TestHotspotTool::quickMovesRenderOnlyTheNewestOntoTheFramesPixels() {
  auto w = openScene(QStringLiteral("coalesce"));
  QVERIFY(settle(*w));
  QVERIFY(pressH(*w));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  ViewportWidget* view = w->viewport();

  // The frame at half the widget's size (as a high-DPI screen or a preview differs from it): the
  // cursor's place maps onto the frame's own pixels.
  const QSize frameSize(view->width() / 2, view->height() / 2);
  w->controller()->setViewportSize(frameSize.width(), frameSize.height());
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QCOMPARE(view->frame().size(), frameSize);

  // The worker busy for a moment while the cursor crosses the view: of the twenty positions only
  // the newest is rendered.
  FrameLog log(view);
  w->controller()->post(QStringLiteral("busy"), [](Engine&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
  });
  QPoint last;
  for (int i = 0; i < 20; ++i) {
    last = QPoint(view->width() / 5 + i * view->width() / 40, view->height() / 2 + i);
    QTest::mouseMove(view, last);
  }
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY2(log.clearViewFrames() >= 1 && log.clearViewFrames() <= 2,
           qPrintable(QStringLiteral("%1 frames for 20 moves").arg(log.clearViewFrames())));
  const FrameInfo info = log.frames.back().info;
  QVERIFY(info.clearView);
  QVERIFY(!info.clearViewStats.extracted);

  ClearViewSettings settings = w->hotspotMode()->settings();
  settings.width = frameSize.width();
  settings.height = frameSize.height();
  settings.focusPixel = focusPixelFor(last, view->size(), frameSize);
  QVERIFY(settings.focusPixel.x > 0.f && settings.focusPixel.x < float(frameSize.width()));
  const QImage expected = expectedFrame(*w, settings);
  QCOMPARE(differingPixels(view->frame(), expected), size_t(0));
  // ... and not the frame of the first position.
  ClearViewSettings early = settings;
  early.focusPixel =
      focusPixelFor(QPoint(view->width() / 5, view->height() / 2), view->size(), frameSize);
  QVERIFY(differingPixels(view->frame(), expectedFrame(*w, early)) > 0);
}

void TestHotspotTool::wheelScalesTheSizeAndDragOrbits() {
  auto w = openScene(QStringLiteral("wheel"));
  QVERIFY(settle(*w));
  QVERIFY(pressH(*w));
  ViewportWidget* view = w->viewport();
  const QPoint c = view->rect().center();
  QTest::mouseMove(view, c);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  HotspotTool* tool = w->hotspotTool();
  QCOMPARE(tool->size(), 0.f);  // automatic until the wheel turns
  QVERIFY(!w->hotspotMode()->sessionSettings());
  const auto snap = w->controller()->snapshot();
  const float radius = 0.5f * glm::length(snap->volume->grid().worldBounds().size());
  QCOMPARE(tool->sizeStart(), 0.5f * radius);

  FrameLog log(view);
  const Camera camera = view->camera();
  const QImage before = view->frame();
  sendWheel(view, c, 120);
  const float one = 0.5f * radius * HotspotTool::kFactorPerNotch;
  QVERIFY(std::abs(tool->size() - one) < 1e-4f * one);
  QCOMPARE(w->hotspotMode()->settings().size, tool->size());
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(view->camera().eye == camera.eye);  // the wheel is the hotspot's, not the zoom's
  QVERIFY(log.frames.back().info.clearView);
  QVERIFY(!log.frames.back().info.clearViewStats.extracted);
  QVERIFY(differingPixels(view->frame(), before) > 0);
  const QImage oneNotch = view->frame();
  sendWheel(view, c, 240);  // two notches more
  QVERIFY(std::abs(tool->size() - one * 1.21f) < 1e-4f * one);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(differingPixels(view->frame(), oneNotch) > 0);
  // The panel shows it, and it is the user's now (saved in sessions).
  auto* sizeBox = w->hotspotPanel()->findChild<QDoubleSpinBox*>(QStringLiteral("size"));
  QVERIFY(sizeBox);
  QVERIFY(std::abs(sizeBox->value() - double(tool->size())) < 0.01);
  QVERIFY(w->hotspotMode()->sessionSettings());
  QCOMPARE(w->hotspotMode()->sessionSettings()->size, tool->size());
  QVERIFY(w->modified());
  // Escape: automatic again.
  QTest::keyClick(view, Qt::Key_Escape);
  QCOMPARE(tool->size(), 0.f);
  QCOMPARE(w->hotspotMode()->settings().size, 0.f);

  // A left drag orbits the camera (and the new view extracts the layers again).
  const int64_t extractions = log.frames.back().info.clearViewStats.extractions;
  QTest::mousePress(view, Qt::LeftButton, {}, c);
  QTest::mouseMove(view, c + QPoint(40, 0));
  QTest::mouseMove(view, c + QPoint(80, 10));
  QTest::mouseRelease(view, Qt::LeftButton, {}, c + QPoint(80, 10));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(glm::length(view->camera().eye - camera.eye) > 1e-3f);
  QVERIFY(log.frames.back().info.clearView);
  QVERIFY(!log.frames.back().info.preview);
  QVERIFY(log.frames.back().info.clearViewStats.extractions > extractions);
  // The hotspot stayed where the drag began.
  QVERIFY(std::abs(tool->focus().x() - double(c.x()) / view->width()) < 1e-6);
}

void TestHotspotTool::panelSettingsChangeTheFrame() {
  auto w = openScene(QStringLiteral("panel"));
  QVERIFY(settle(*w));
  QVERIFY(pressH(*w));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  ViewportWidget* view = w->viewport();
  HotspotPanel* panel = w->hotspotPanel();
  // The scene's defaults: context surface 0 and the importance at 0.5.
  const ClearViewSettings defaults = w->hotspotMode()->settings();
  QCOMPARE(defaults.context.kind, ClearViewLayerKind::ContextSurface);
  QCOMPARE(defaults.context.surface, 0);
  QCOMPARE(defaults.focus.kind, ClearViewLayerKind::Importance);
  QCOMPARE(defaults.focus.isovalue, 0.5);
  QVERIFY(sameHotspotSettings(panel->settings(), defaults));

  FrameLog log(view);
  auto* measure = panel->findChild<QComboBox*>(QStringLiteral("measure"));
  QVERIFY(measure);
  const QImage before = view->frame();
  const int64_t extractions = w->hotspotMode()->lastStats()->extractions;
  measure->setCurrentIndex(measure->findData(int(ClearViewMeasure::Distance)));
  QCOMPARE(w->hotspotMode()->settings().measure, ClearViewMeasure::Distance);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(log.frames.back().info.clearView);
  QCOMPARE(log.frames.back().info.clearViewStats.extractions, extractions);  // composited only
  QVERIFY(differingPixels(view->frame(), before) > 100);

  auto* shader = panel->findChild<QComboBox*>(QStringLiteral("contextShader"));
  QVERIFY(shader);
  const QImage skin = view->frame();
  shader->setCurrentIndex(shader->findData(int(ClearViewShader::CoolWarm)));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(differingPixels(view->frame(), skin) > 100);

  // Another focus layer: an isosurface of the data, picked on the histogram strip: new layers.
  HotspotLayerEditor* focus = panel->focusLayer();
  focus->kindBox()->setCurrentIndex(
      focus->kindBox()->findData(int(ClearViewLayerKind::Isosurface)));
  IsovaluePicker* picker = focus->picker();
  showHotspotPanel(*w);
  QVERIFY(picker->isVisible());
  const auto snap = w->controller()->snapshot();
  const double lo = snap->volume->valueMin, hi = snap->volume->valueMax;
  const double target = lo + 0.6 * (hi - lo);
  QTest::mouseClick(picker, Qt::LeftButton, {},
                    QPoint(int(std::lround(picker->xOfValue(target))), picker->height() / 2));
  const ClearViewLayer picked = w->hotspotMode()->settings().focus;
  QCOMPARE(picked.kind, ClearViewLayerKind::Isosurface);
  QVERIFY2(std::abs(picked.isovalue - target) < 0.01 * (hi - lo),
           qPrintable(QStringLiteral("picked %1 for %2").arg(picked.isovalue).arg(target)));
  QCOMPARE(focus->isovalueBox()->value(), picked.isovalue);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(log.frames.back().info.clearView);
  QVERIFY(log.frames.back().info.clearViewStats.extractions > extractions);
  QVERIFY(w->modified());

  // Scene defaults: back to them, and no longer the user's.
  QVERIFY(w->hotspotMode()->sessionSettings());
  auto* reset = panel->findChild<QPushButton*>(QStringLiteral("reset"));
  QVERIFY(reset);
  reset->click();
  QVERIFY(sameHotspotSettings(w->hotspotMode()->settings(), defaults));
  QVERIFY(!w->hotspotMode()->sessionSettings());
}

void TestHotspotTool::refusedCombinationsAreMessagesNotCrashes() {
  // A volume file: no importance, no context surface. The defaults are two isosurfaces.
  const QString dir = freshDir(QStringLiteral("refused"));
  auto w = makeWindow(QStringLiteral("refused-window"));
  QSignalSpy errors(w.get(), &MainWindow::errorShown);
  w->openVolume(writeBallVolume(dir));
  QVERIFY(settle(*w));
  const ClearViewSettings defaults = w->hotspotMode()->settings();
  QCOMPARE(defaults.context.kind, ClearViewLayerKind::Isosurface);
  QCOMPARE(defaults.focus.kind, ClearViewLayerKind::Isosurface);
  QVERIFY(defaults.context.isovalue < defaults.focus.isovalue);
  QVERIFY(pressH(*w));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(w->hotspotMode()->lastStats());
  QVERIFY(w->hotspotMode()->lastStats()->focusPixels > 0);  // the ball inside the shell
  QVERIFY(w->hotspotMode()->problem().isEmpty());

  // The importance as the focus: this scene has none.
  FrameLog log(w->viewport());
  HotspotLayerEditor* focus = w->hotspotPanel()->focusLayer();
  focus->kindBox()->setCurrentIndex(
      focus->kindBox()->findData(int(ClearViewLayerKind::Importance)));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const QString problem = w->hotspotMode()->problem();
  QVERIFY2(problem.contains(QStringLiteral("importance")), qPrintable(problem));
  QCOMPARE(w->hotspotPanel()->problem(), problem);
  QVERIFY(w->hotspotPanel()->findChild<QLabel*>(QStringLiteral("problem"))->isVisible());
  QVERIFY(w->hotspotMode()->statusText().contains(problem));
  QVERIFY2(statusBarText(*w).contains(problem), qPrintable(statusBarText(*w)));
  QVERIFY(!log.frames.empty());
  QVERIFY(!log.frames.back().info.clearView);  // the normal render shows the view meanwhile
  // Moving the hotspot changes nothing of why: no frame, no new message.
  const size_t frames = log.frames.size();
  QTest::mouseMove(w->viewport(), QPoint(50, 60));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QCOMPARE(log.frames.size(), frames);

  // A context surface that the scene lacks, and an isovalue at the edge of the data.
  HotspotLayerEditor* context = w->hotspotPanel()->contextLayer();
  focus->kindBox()->setCurrentIndex(
      focus->kindBox()->findData(int(ClearViewLayerKind::Isosurface)));
  context->kindBox()->setCurrentIndex(
      context->kindBox()->findData(int(ClearViewLayerKind::ContextSurface)));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY2(w->hotspotMode()->problem().contains(QStringLiteral("context surface")),
           qPrintable(w->hotspotMode()->problem()));
  context->kindBox()->setCurrentIndex(
      context->kindBox()->findData(int(ClearViewLayerKind::Isosurface)));
  context->isovalueBox()->setValue(context->isovalueBox()->maximum());
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY2(w->hotspotMode()->problem().contains(QStringLiteral("range")),
           qPrintable(w->hotspotMode()->problem()));

  // Fixed: ClearView again, the message gone.
  context->isovalueBox()->setValue(defaults.context.isovalue);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY(w->hotspotMode()->problem().isEmpty());
  QVERIFY(!w->hotspotPanel()->findChild<QLabel*>(QStringLiteral("problem"))->isVisible());
  QVERIFY(log.frames.back().info.clearView);
  QCOMPARE(errors.count(), 0);  // no error dialogs for any of it
}

void TestHotspotTool::sessionKeepsTheHotspotSettings() {
  const QString dir = freshDir(QStringLiteral("session"));
  auto w1 = openScene(QStringLiteral("session-1"));
  QVERIFY(settle(*w1));
  const QString plainPath = dir + QStringLiteral("/plain.visopt-session");
  QVERIFY(w1->saveSessionTo(plainPath));
  QVERIFY(!loadSession(plainPath.toStdString()).clearView);  // defaults are not saved

  // Settings through the panel and the wheel.
  HotspotPanel* panel = w1->hotspotPanel();
  auto* measure = panel->findChild<QComboBox*>(QStringLiteral("measure"));
  measure->setCurrentIndex(measure->findData(int(ClearViewMeasure::ViewDistance)));
  auto* shader = panel->findChild<QComboBox*>(QStringLiteral("focusShader"));
  shader->setCurrentIndex(shader->findData(int(ClearViewShader::Diffuse)));
  panel->findChild<QDoubleSpinBox*>(QStringLiteral("weight"))->setValue(0.35);
  panel->findChild<QDoubleSpinBox*>(QStringLiteral("ambient"))->setValue(0.3);
  panel->findChild<QDoubleSpinBox*>(QStringLiteral("distanceScale"))->setValue(7.5);
  panel->findChild<QCheckBox*>(QStringLiteral("border"))->setChecked(false);
  panel->findChild<QCheckBox*>(QStringLiteral("volumeLayer"))->setChecked(true);
  panel->findChild<QComboBox*>(QStringLiteral("light"))->setCurrentIndex(1);
  panel->focusLayer()->levelBox()->setValue(0.4);
  QVERIFY(pressH(*w1));
  sendWheel(w1->viewport(), w1->viewport()->rect().center(), 3 * 120);
  QVERIFY(w1->waitForSettledFrame(kSettleMs));
  QVERIFY2(w1->hotspotMode()->lastStats(), qPrintable(w1->hotspotMode()->problem()));
  const ClearViewSettings set = w1->hotspotMode()->settings();
  QCOMPARE(set.measure, ClearViewMeasure::ViewDistance);
  QCOMPARE(set.focusShader, ClearViewShader::Diffuse);
  QCOMPARE(set.weight, 0.35f);
  QCOMPARE(set.focus.isovalue, 0.4);
  QVERIFY(!set.border && set.volumeLayer && !set.headlight);
  QVERIFY(set.size > 0.f);
  QVERIFY(sameHotspotSettings(panel->settings(), set));
  const QString path = dir + QStringLiteral("/hotspot.visopt-session");
  QVERIFY(w1->saveSessionTo(path));
  const Session saved = loadSession(path.toStdString());
  QVERIFY(saved.clearView);
  QVERIFY(sameHotspotSettings(*saved.clearView, set));

  // Reopened in a fresh window: the same settings, in the panel and the tool, rendered.
  auto w2 = makeWindow(QStringLiteral("session-2"));
  QSignalSpy errors(w2.get(), &MainWindow::errorShown);
  QVERIFY(w2->openSession(path));
  QVERIFY(w2->waitForSettledFrame(kSettleMs));
  QVERIFY(sameHotspotSettings(w2->hotspotMode()->settings(), set));
  QVERIFY(sameHotspotSettings(w2->hotspotPanel()->settings(), set));
  QCOMPARE(w2->hotspotTool()->size(), set.size);
  QVERIFY(!w2->modified());
  QVERIFY(pressH(*w2));
  QVERIFY(w2->waitForSettledFrame(kSettleMs));
  QVERIFY(w2->hotspotMode()->lastStats());
  QVERIFY(w2->hotspotMode()->problem().isEmpty());
  // Saved again: the same file.
  const QString again = dir + QStringLiteral("/again.visopt-session");
  QVERIFY(w2->saveSessionTo(again));
  QVERIFY(sameHotspotSettings(*loadSession(again.toStdString()).clearView, set));
  QCOMPARE(errors.count(), 0);

  // A session without hotspot settings: the scene's defaults again.
  QVERIFY(w2->openSession(plainPath));
  QVERIFY(w2->waitForSettledFrame(kSettleMs));
  QVERIFY(!w2->hotspotMode()->sessionSettings());
  QCOMPARE(w2->hotspotMode()->settings().measure, ClearViewMeasure::Curvature);
  QCOMPARE(w2->hotspotTool()->size(), 0.f);
}

// The second context and focus layers: switched on in the panel they extract new layers and
// change the frame; a session keeps them; layers beyond the second (from a session or the
// library) survive edits in the panel.
void TestHotspotTool::secondLayersChangeTheFrameAndAreKept() {
  const QString dir = freshDir(QStringLiteral("layers"));
  auto w = openScene(QStringLiteral("layers-1"));
  QVERIFY(settle(*w));
  QVERIFY(pressH(*w));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  HotspotPanel* panel = w->hotspotPanel();
  QVERIFY(!panel->deeperContextBox()->isChecked());
  QVERIFY(!panel->deeperContextLayer()->isEnabled());
  QVERIFY(w->hotspotMode()->settings().deeperContexts.empty());
  ViewportWidget* view = w->viewport();
  FrameLog log(view);
  const QImage before = view->frame();
  const int64_t extractions = w->hotspotMode()->lastStats()->extractions;

  panel->deeperContextBox()->setChecked(true);
  QVERIFY(panel->deeperContextLayer()->isEnabled());
  const ClearViewSettings one = w->hotspotMode()->settings();
  QCOMPARE(one.deeperContexts.size(), size_t(1));
  QCOMPARE(one.deeperContexts[0].kind, ClearViewLayerKind::Isosurface);
  const auto snap = w->controller()->snapshot();
  const double lo = snap->volume->valueMin, hi = snap->volume->valueMax;
  QVERIFY(std::abs(one.deeperContexts[0].isovalue - (lo + 0.75 * (hi - lo))) < 1e-6 * (hi - lo));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY2(w->hotspotMode()->problem().isEmpty(), qPrintable(w->hotspotMode()->problem()));
  QVERIFY(log.frames.back().info.clearView);
  QVERIFY(log.frames.back().info.clearViewStats.extractions > extractions);
  QCOMPARE(log.frames.back().info.clearViewStats.deeperContextPixels.size(), size_t(1));
  QVERIFY(differingPixels(view->frame(), before) > 0);

  panel->secondFocusBox()->setChecked(true);
  QCOMPARE(w->hotspotMode()->settings().moreFoci.size(), size_t(1));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QVERIFY2(w->hotspotMode()->problem().isEmpty(), qPrintable(w->hotspotMode()->problem()));

  // Saved and reopened: both second layers.
  const ClearViewSettings set = w->hotspotMode()->settings();
  const QString path = dir + QStringLiteral("/layers.visopt-session");
  QVERIFY(w->saveSessionTo(path));
  QVERIFY(sameHotspotSettings(*loadSession(path.toStdString()).clearView, set));
  auto w2 = makeWindow(QStringLiteral("layers-2"));
  QVERIFY(w2->openSession(path));
  QVERIFY(w2->waitForSettledFrame(kSettleMs));
  QVERIFY(sameHotspotSettings(w2->hotspotPanel()->settings(), set));
  QVERIFY(w2->hotspotPanel()->deeperContextBox()->isChecked());
  QVERIFY(w2->hotspotPanel()->secondFocusBox()->isChecked());

  // Three context layers behind the first, as a session may hold them: an edit of the second in
  // the panel keeps the third and fourth; switching it off removes them all.
  ClearViewSettings many = set;
  many.deeperContexts = {{ClearViewLayerKind::Isosurface, lo + 0.5 * (hi - lo), 0},
                         {ClearViewLayerKind::Isosurface, lo + 0.6 * (hi - lo), 0},
                         {ClearViewLayerKind::Isosurface, lo + 0.7 * (hi - lo), 0}};
  panel->setSettings(many);
  panel->deeperContextLayer()->isovalueBox()->setValue(lo + 0.55 * (hi - lo));
  const ClearViewSettings edited = panel->settings();
  QCOMPARE(edited.deeperContexts.size(), size_t(3));
  QVERIFY(std::abs(edited.deeperContexts[0].isovalue - (lo + 0.55 * (hi - lo))) < 0.01 * (hi - lo));
  QCOMPARE(edited.deeperContexts[2], many.deeperContexts[2]);
  panel->deeperContextBox()->setChecked(false);
  QVERIFY(panel->settings().deeperContexts.empty());
}

// "Optimise around the hotspot": the last frame's focus point and radius become the importance
// (a smooth ball), the view returns to the normal render and the optimisation runs for it.
void TestHotspotTool::optimiseAroundTheHotspotMakesItTheImportance() {
  auto w = openScene(QStringLiteral("optimise-around"));
  QVERIFY(settle(*w));
  ViewportWidget* view = w->viewport();
  auto* button = w->hotspotPanel()->findChild<QPushButton*>(QStringLiteral("optimiseAround"));
  QVERIFY(button);
  QVERIFY(!button->isEnabled());  // no ClearView frame yet
  QVERIFY(pressH(*w));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  const std::optional<ClearViewStats> stats = w->hotspotMode()->lastStats();
  QVERIFY(stats && stats->hasFocusPoint && stats->size > 0.f);
  QVERIFY(button->isEnabled());
  QSignalSpy iterations(w->controller(), &EngineController::iterationDone);
  button->click();
  QVERIFY(!w->hotspotMode()->active());
  QTRY_VERIFY_WITH_TIMEOUT(iterations.count() > 0, kSettleMs);
  w->setOptimizationRunning(false);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  Engine::ImportanceSource source;
  w->controller()->call([&](Engine& e) { source = e.importanceSource(); });
  QCOMPARE(source.kind, ImportanceKind::Hotspot);
  QVERIFY(glm::length(source.hotspotCentre - stats->focusPoint) < 1e-4f);
  QCOMPARE(source.hotspotRadius, stats->size);
  QVERIFY(!view->frame().isNull());
}

QTEST_MAIN(TestHotspotTool)
#include "test_hotspot_tool.moc"
