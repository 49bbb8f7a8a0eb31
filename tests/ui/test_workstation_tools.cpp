// The workstation's wiring, end to end through MainWindow: what a user does with the tools and
// editors reaches the engine, and its effect shows in the rendered frame. A brush stroke over the
// viewport sets world-mask voxels in the engine and tints exactly the masked part of the image
// with the overlay; the lens follows the cursor to the engine's normalised lens centre; a
// transfer-function edit reaches the engine; "compare methods" renders four distinct images.
#include <cmath>
#include <memory>

#include <QSignalSpy>
#include <QTest>

#include <visopt/engine.h>
#include <visopt/image.h>

#include "main_window.h"
#include "panels/comparison_view.h"
#include "tools/lens_tool.h"
#include "tools/mask_paint_tool.h"
#include "viewport_widget.h"
#include "widgets/transfer_function_editor.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

constexpr int kSettleMs = 240000;

std::unique_ptr<MainWindow> openScene(const QString& name) {
  auto w = std::make_unique<MainWindow>(
      Precision::FP32, QStringLiteral(VISOPT_TEST_TMP) + QStringLiteral("/tools-") + name);
  w->setInteractive(false);
  w->setOptimizationRunning(false);
  w->resize(900, 700);
  w->show();  // hover events (the lens) reach only a shown widget
  w->openBuiltinScene(QStringLiteral("shepp-logan"), 40);
  return w;
}

// The current view at 160 x 160 (the frame's own size follows the window).
Image renderNow(MainWindow& w, bool maskOverlay) {
  RenderSettings s = w.renderSettings();
  s.width = s.height = 160;
  s.jitter = false;
  s.worldMaskOverlay = maskOverlay;
  // The tint is measured in absolute radiance: the volume's ambient occlusion darkens the thin
  // volume in front of the head, where much of the tint shows, below the threshold used here.
  s.ambientOcclusion = false;
  Image out;
  w.controller()->call([&](Engine& e) { out = e.render(s); });
  return out;
}

}  // namespace

class TestWorkstationTools : public QObject {
  Q_OBJECT
 private slots:
  void brushStrokeSetsTheEngineMaskAndTintsTheImage();
  void lensFollowsTheCursorIntoTheEngine();
  void transferFunctionEditReachesTheEngine();
  void compareMethodsRendersFourDistinctImages();
};

void TestWorkstationTools::brushStrokeSetsTheEngineMaskAndTintsTheImage() {
  auto w = openScene(QStringLiteral("brush"));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  size_t before = 1;
  w->controller()->call([&](Engine& e) { before = e.worldMask() ? e.worldMask()->count() : 0; });
  QCOMPARE(before, size_t(0));

  MaskPaintTool* brush = w->maskTool();
  w->viewport()->setTool(brush);
  const auto snap = w->controller()->snapshot();
  QVERIFY(snap && snap->volume);
  const glm::vec3 extent = snap->volume->grid().worldBounds().size();
  brush->setRadius(0.1f * std::max(extent.x, std::max(extent.y, extent.z)));
  ViewportWidget* view = w->viewport();
  const QPoint c = view->rect().center();
  const QPoint c160(c.x() * 160 / view->width(), c.y() * 160 / view->height());
  QTest::mousePress(view, Qt::LeftButton, {}, c);
  QTest::mouseMove(view, c + QPoint(10, 0));
  QTest::mouseRelease(view, Qt::LeftButton, {}, c + QPoint(10, 0));
  QVERIFY(w->waitForSettledFrame(kSettleMs));

  size_t masked = 0;
  w->controller()->call([&](Engine& e) { masked = e.worldMask() ? e.worldMask()->count() : 0; });
  QVERIFY2(masked > 50, qPrintable(QStringLiteral("%1 voxels masked").arg(masked)));
  QCOMPARE(masked, brush->mask()->count());
  // The overlay tints the middle of the image (where the stroke was), not its corners.
  const Image plain = renderNow(*w, false), tinted = renderNow(*w, true);
  writePng(tinted, VISOPT_TEST_TMP "/tools-mask-overlay.png");
  writePng(plain, VISOPT_TEST_TMP "/tools-mask-plain.png");
  {
    Image diff = plain;
    for (int y = 0; y < 160; ++y)
      for (int x = 0; x < 160; ++x)
        diff.at(x, y) = 4.f * glm::abs(tinted.at(x, y) - plain.at(x, y));
    writePng(diff, VISOPT_TEST_TMP "/tools-mask-diff.png");
  }
  const auto magentaShift = [&](int x, int y) {
    const glm::vec3 d = tinted.at(x, y) - plain.at(x, y);
    return d.r + d.b - 2.f * d.g;  // towards (1, 0, 1)
  };
  // The tint covers part of the head, around where the stroke was (volume in front of the
  // surface may hide some of it), and nothing of the background.
  int surface = 0, tintedPixels = 0;
  glm::vec2 centroid(0.f);
  for (int y = 0; y < 160; ++y)
    for (int x = 0; x < 160; ++x) {
      if (plain.at(x, y).r < 0.2f) continue;
      ++surface;
      if (magentaShift(x, y) > 0.02f) {
        ++tintedPixels;
        centroid += glm::vec2(float(x), float(y));
      }
    }
  QVERIFY2(
      tintedPixels > 20 && tintedPixels < surface / 2,
      qPrintable(QStringLiteral("%1 of %2 surface pixels tinted").arg(tintedPixels).arg(surface)));
  centroid /= float(tintedPixels);
  QVERIFY2(glm::length(centroid - glm::vec2(float(c160.x()), float(c160.y()))) < 12.f,
           qPrintable(QStringLiteral("tint centred at %1 %2, stroke at %3 %4")
                          .arg(double(centroid.x))
                          .arg(double(centroid.y))
                          .arg(c160.x())
                          .arg(c160.y())));
  QCOMPARE(magentaShift(2, 2), 0.f);  // background

  // Undo takes the mask out of the engine again.
  brush->undo();
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  w->controller()->call([&](Engine& e) { masked = e.worldMask() ? e.worldMask()->count() : 0; });
  QCOMPARE(masked, size_t(0));
}

void TestWorkstationTools::lensFollowsTheCursorIntoTheEngine() {
  auto w = openScene(QStringLiteral("lens"));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  w->viewport()->setTool(w->lensTool());
  w->lensTool()->setLensOn(true);
  ViewportWidget* view = w->viewport();
  const QPoint at(view->width() / 4, 3 * view->height() / 4);
  QTest::mouseMove(view, at);
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  ImportanceLens lens;
  w->controller()->call([&](Engine& e) { lens = e.lens(); });
  QVERIFY(lens.radius > 0.f);
  const float ex = (float(at.x()) + 0.5f) / float(view->width()),
              ey = (float(at.y()) + 0.5f) / float(view->height());
  QVERIFY2(std::abs(lens.x - ex) < 0.01f && std::abs(lens.y - ey) < 0.01f,
           qPrintable(QStringLiteral("lens at %1 %2").arg(double(lens.x)).arg(double(lens.y))));
}

void TestWorkstationTools::transferFunctionEditReachesTheEngine() {
  auto w = openScene(QStringLiteral("tf"));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  TransferFunction tf = w->transferFunctionEditor()->transferFunction();
  QVERIFY(!tf.opacity.empty());
  for (auto& p : tf.opacity) p.opacity = 0.5f * p.opacity;
  w->transferFunctionEditor()->setTransferFunction(tf);  // no signal: nothing reaches the engine
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  float engineOpacity = -1.f;
  const double v = tf.opacity[tf.opacity.size() / 2].value;
  w->controller()->call([&](Engine& e) { engineOpacity = e.transferFunction().opacityAt(v); });
  QVERIFY(std::abs(engineOpacity - tf.opacityAt(v)) > 1e-4f || tf.opacityAt(v) == 0.f);
  emit w->transferFunctionEditor()->transferFunctionEdited(tf);  // what a debounced edit emits
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  w->controller()->call([&](Engine& e) { engineOpacity = e.transferFunction().opacityAt(v); });
  QCOMPARE(engineOpacity, tf.opacityAt(v));
  QVERIFY(w->modified());
}

void TestWorkstationTools::compareMethodsRendersFourDistinctImages() {
  auto w = openScene(QStringLiteral("compare"));
  QVERIFY(w->waitForSettledFrame(kSettleMs));
  QSignalSpy errors(w.get(), &MainWindow::errorShown);
  w->compareMethods();
  QTRY_VERIFY_WITH_TIMEOUT(!w->comparisonView()->isBusy(), kSettleMs);
  QVERIFY2(errors.isEmpty(), errors.isEmpty() ? "" : qPrintable(errors.first().first().toString()));
  const auto& images = w->comparisonView()->images();
  QCOMPARE(int(images.size()), 4);
  for (size_t i = 0; i < images.size(); ++i)
    for (size_t j = i + 1; j < images.size(); ++j)
      QVERIFY2(images[i].second != images[j].second,
               qPrintable(images[i].first + QStringLiteral(" equals ") + images[j].first));
  w->comparisonView()->composite().save(QStringLiteral(VISOPT_TEST_TMP "/tools-compare.png"));
}

QTEST_MAIN(TestWorkstationTools)
#include "test_workstation_tools.moc"
