// The workstation's worker while the camera is dragged (EngineController, Engine::followCamera):
// with following on, coarse iterations run between previews and the finest state opens for the
// dragged-to view before the camera rests; with it off, only previews run. The default scene at
// 64^3, the camera turned 120 degrees about the head after the first optimisation.
#include <cmath>

#include <QElapsedTimer>
#include <QTest>

#include "engine_controller.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

void pumpUntil(const std::function<bool()>& done, int timeoutMs) {
  QElapsedTimer t;
  t.start();
  while (!done() && t.elapsed() < timeoutMs)
    QCoreApplication::processEvents(QEventLoop::AllEvents, 5);
}

// Loads the scene, optimises it to convergence for its own view and returns its camera.
Camera convergedScene(EngineController& c) {
  c.post(QStringLiteral("scene"), [&c](Engine& e) {
    e.loadBuiltinScene("shepp-logan", 64, true);
    e.resetOptimization();
    c.refreshSnapshot(e, true);
  });
  Camera camera;
  c.call([&](Engine& e) { camera = e.camera(); });
  c.setViewportSize(128, 128);
  c.setCamera(camera, false);
  c.setOptimizationRunning(true);
  pumpUntil([&] { return c.converged(); }, 240000);
  return camera;
}

Camera turned(const Camera& c, float degrees) {
  const glm::vec3 d = c.eye - c.target;
  const float r = glm::length(d);
  const float azimuth = std::atan2(d.x, -d.y) * 57.29578f;
  const float elevation = std::asin(d.z / r) * 57.29578f;
  return Camera::orbit(c.target, azimuth + degrees, elevation, r);
}

// The visibility through occluders of the finest state for the current camera (one finest
// iteration measures it before its step; run as a command, so nothing else runs meanwhile).
double finestVisibility(EngineController& c) {
  double v = -1.0;
  c.call([&](Engine& e) {
    const auto st = e.continueOptimization(1);
    if (!st.empty()) v = st.front().visibilityViewOccluders;
  });
  return v;
}

}  // namespace

class DragFollowingTest : public QObject {
  Q_OBJECT
 private slots:
  void followingOpensTheDraggedToViewBeforeTheCameraRests() {
    EngineController c(Precision::FP32);
    QVERIFY(c.followWhileDragging());  // the default
    const Camera start = convergedScene(c);
    QVERIFY(c.converged());
    int previewsAfterFollowing = 0;
    connect(&c, &EngineController::frameReady, this, [&](const QImage&, const FrameInfo& info) {
      if (info.preview && c.followIterations() > 0) ++previewsAfterFollowing;
    });
    c.setCamera(turned(start, 120.f), true);  // pressed and moved; not released
    pumpUntil([&] { return c.followIterations() >= 16 && c.waitIdle(0); }, 120000);
    QVERIFY2(c.followIterations() >= 16, "coarse iterations run while the camera is held");
    QVERIFY2(previewsAfterFollowing > 0, "a preview shows what they opened");
    QVERIFY(c.waitIdle(1000));  // and then the worker rests until the drag moves on
    const double v = finestVisibility(c);
    QVERIFY2(v > 0.3, qPrintable(QStringLiteral("V_occ %1").arg(v)));
  }

  // A mouse in motion: a newer camera arrives before each preview is done, and following still
  // runs (one call per preview), or it would wait for the mouse to stop.
  void followingRunsDuringAContinuousDrag() {
    EngineController c(Precision::FP32);
    const Camera start = convergedScene(c);
    QVERIFY(c.converged());
    QElapsedTimer drag;
    drag.start();
    float degrees = 0.f;
    while (drag.elapsed() < 1500) {
      degrees += 0.5f;
      c.setCamera(turned(start, degrees), true);
      pumpUntil([] { return false; }, 16);
    }
    QVERIFY2(c.followIterations() > 0,
             qPrintable(QStringLiteral("follow iterations %1").arg(c.followIterations())));
    c.setCamera(turned(start, degrees), false);
    QVERIFY(c.waitIdle(240000));
  }

  void withFollowingOffADragOnlyPreviews() {
    EngineController c(Precision::FP32);
    c.setFollowWhileDragging(false);
    const Camera start = convergedScene(c);
    QVERIFY(c.converged());
    c.setCamera(turned(start, 120.f), true);
    QTest::qWait(200);
    QVERIFY(c.waitIdle(60000));
    QCOMPARE(c.followIterations(), 0);
    const double v = finestVisibility(c);
    QVERIFY2(v < 0.1, qPrintable(QStringLiteral("V_occ %1").arg(v)));
  }
};

QTEST_MAIN(DragFollowingTest)
#include "test_drag_following.moc"
