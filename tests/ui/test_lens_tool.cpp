// The importance lens tool (Himmler & Günther 2026, §III-F): the cursor maps to the lens centre in
// normalised image coordinates (y down), the wheel sets radius and strength, Escape switches it
// off; and a lens set from the tool changes the optimisation along exactly the view rays inside it.
#include <cmath>
#include <memory>
#include <vector>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QSignalSpy>
#include <QTest>
#include <QWheelEvent>
#include <QWidget>

#include <visopt/engine.h>

#include "tools/lens_tool.h"
#include "tools/picking.h"
#include "tools/window_mask_tool.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

class ToolHost : public QWidget {
 public:
  ToolHost(ViewportTool* tool, ViewContext view) : tool_(tool), view_(std::move(view)) {
    resize(view_.imageSize);
    setMouseTracking(true);
  }

 protected:
  void mousePressEvent(QMouseEvent* e) override { tool_->mousePress(e, view_); }
  void mouseMoveEvent(QMouseEvent* e) override { tool_->mouseMove(e, view_); }
  void mouseReleaseEvent(QMouseEvent* e) override { tool_->mouseRelease(e, view_); }
  void keyPressEvent(QKeyEvent* e) override { tool_->keyPress(e, view_); }

 private:
  ViewportTool* tool_;
  ViewContext view_;
};

void sendWheel(ViewportTool& tool, const ViewContext& view, QPointF pos, int angle,
               Qt::KeyboardModifiers modifiers) {
  QWheelEvent event(pos, pos, QPoint(), QPoint(0, angle), Qt::NoButton, modifiers,
                    Qt::NoScrollPhase, false);
  tool.wheel(&event, view);
}

ImportanceLens lastLens(const QSignalSpy& spy) {
  return spy.last().at(0).value<ImportanceLens>();
}

// An occluding slab (value 1, y in [-8, -3]) in front of an important plane (value 0.5,
// y = 4) on a 24^3 grid of unit spacing centred at the origin; the camera looks along +y.
constexpr int kN = 24;
constexpr int kView = 32;  // engine viewport and frustum rays per side

Volume slabVolume() {
  GridSpec g;
  g.dims = glm::ivec3(kN);
  g.origin = glm::vec3(-0.5f * float(kN - 1));
  Volume v;
  v.name = "slab";
  v.valueMin = 0.0;
  v.valueMax = 1.0;
  v.normalized = Field3D("volume", g, Precision::FP32);
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const glm::vec3 x = g.indexToWorld(glm::vec3(float(i), float(j), float(k)));
        float value = 0.f;
        if (x.y >= -8.f && x.y <= -3.f) value = 1.f;
        if (std::abs(x.y - 3.5f) < 0.6f && std::abs(x.x) < 10.f && std::abs(x.z) < 10.f)
          value = 0.5f;
        v.normalized.set(g.linearIndex(i, j, k), value);
      }
  return v;
}

void setupEngine(Engine& e) {
  e.setVolume(slabVolume());
  TransferFunction tf;
  tf.name = "slab";
  tf.unitDistance = 1.f;
  auto alpha = [](float mu) { return 1.f - std::exp(-mu); };
  tf.opacity = {
      {0.0, 0.f}, {0.25, 0.f}, {0.5, alpha(0.02f)}, {0.75, alpha(0.02f)}, {1.0, alpha(0.3f)}};
  tf.color = {{0.0, glm::vec3(0.8f)}, {1.0, glm::vec3(0.8f)}};
  e.setTransferFunction(tf);
  e.setImportanceCurve({{0.0, 0.0}, {0.4, 0.0}, {0.45, 1.0}, {0.55, 1.0}, {0.6, 0.0}, {1.0, 0.0}});
  e.setCamera(Camera::orbit({0, 0, 0}, 0.f, 0.f, 55.f));
  PointLight light;
  light.position = {0.f, -55.f, 0.f};
  e.setLight(light);
  e.setViewportSize(kView, kView);
  ExtinctionSettings s;
  s.levels = 1;
  s.maxIterationsPerLevel = 25;
  s.minIterationsPerLevel = 25;
  s.frustumScale = 1.f;
  s.r = 0.f;
  e.setExtinctionSettings(s);
}

// Optimised mu per voxel with the given lens.
std::vector<float> optimiseWith(const ImportanceLens& lens) {
  Engine e;
  setupEngine(e);
  e.setLens(lens);
  e.optimize();
  const Field3D* mu = e.optimizedExtinction();
  std::vector<float> out;
  if (!mu) return out;
  for (size_t i = 0; i < mu->size(); ++i) out.push_back(mu->get(i));
  return out;
}

}  // namespace

class TestLensTool : public QObject {
  Q_OBJECT
 private slots:
  void cursorWheelAndEscapeSetTheLens();
  void lensOutlineMatchesTheWeights();
  void lensChangesTheOptimisationAlongExactlyItsRays();
  void windowMaskEmptyMeansNoMask();
};

void TestLensTool::cursorWheelAndEscapeSetTheLens() {
  LensTool tool;
  QSignalSpy spy(&tool, &LensTool::lensChanged);
  ViewContext view;
  view.imageSize = QSize(400, 250);
  ToolHost host(&tool, view);
  host.show();

  QTest::mouseMove(&host, QPoint(100, 50));
  QVERIFY(spy.count() >= 1);
  ImportanceLens lens = lastLens(spy);
  QCOMPARE(lens.x, 0.25f);
  QCOMPARE(lens.y, 0.2f);
  QCOMPARE(lens.radius, tool.radius());
  QVERIFY(lens.radius > 0.f);

  const float r0 = tool.radius();
  sendWheel(tool, view, QPointF(300, 200), 120, Qt::NoModifier);
  lens = lastLens(spy);
  QCOMPARE(lens.x, 0.75f);
  QCOMPARE(lens.y, 0.8f);
  QVERIFY(std::abs(lens.radius - r0 * LensTool::kRadiusFactorPerNotch) < 1e-6f);
  sendWheel(tool, view, QPointF(300, 200), -240, Qt::NoModifier);
  QVERIFY(std::abs(lastLens(spy).radius - r0 / LensTool::kRadiusFactorPerNotch) < 1e-5f);

  const float s0 = tool.strength();
  sendWheel(tool, view, QPointF(300, 200), 120, Qt::ShiftModifier);
  QVERIFY(std::abs(lastLens(spy).strength - (s0 + LensTool::kStrengthStepPerNotch)) < 1e-6f);
  for (int i = 0; i < 100; ++i) sendWheel(tool, view, QPointF(300, 200), -120, Qt::ShiftModifier);
  QCOMPARE(lastLens(spy).strength, 0.f);

  QTest::keyClick(&host, Qt::Key_Escape);
  QCOMPARE(lastLens(spy).radius, 0.f);
  QVERIFY(!tool.lensOn());
  // Off stays off while the cursor moves; the wheel switches it on again.
  const auto emitted = spy.count();
  QTest::mouseMove(&host, QPoint(200, 125));
  QCOMPARE(spy.count(), emitted);
  QCOMPARE(tool.lens().radius, 0.f);
  sendWheel(tool, view, QPointF(100, 125), 120, Qt::NoModifier);
  QCOMPARE(spy.count(), emitted + 1);  // one signal per change
  QVERIFY(lastLens(spy).radius > 0.f);
  QCOMPARE(lastLens(spy).x, 0.25f);
  QCOMPARE(lastLens(spy).y, 0.5f);
}

void TestLensTool::lensOutlineMatchesTheWeights() {
  ImportanceLens lens;
  lens.x = 0.25f;
  lens.y = 0.75f;
  lens.radius = 0.1f;
  const QRectF r = lensOutline(lens, QSize(200, 100));
  QCOMPARE(r.center(), QPointF(50.0, 75.0));
  QVERIFY(std::abs(r.width() - 40.0) < 1e-4);  // 2 * radius * width
  QVERIFY(std::abs(r.height() - 20.0) < 1e-4);
}

// Himmler & Günther 2026, §III-F: the lens scales the importance along the view rays inside it.
// With strength 0 the occluder in front of the important plane keeps its extinction inside the lens
// and is cleared elsewhere. Two lens positions (set from the tool's cursor) give the same result
// on every voxel whose rays are inside neither lens; inside one lens only, the occluder is kept
// with that lens and cleared with the other.
void TestLensTool::lensChangesTheOptimisationAlongExactlyItsRays() {
  LensTool tool;
  tool.setStrength(0.f);
  tool.setRadius(0.2f);
  QSignalSpy spy(&tool, &LensTool::lensChanged);
  ViewContext view;
  view.camera = Camera::orbit({0, 0, 0}, 0.f, 0.f, 55.f);
  view.imageSize = QSize(320, 320);
  ToolHost host(&tool, view);
  host.show();
  // Off-centre and asymmetric in x and y: a flipped axis would move the lens elsewhere.
  QTest::mouseMove(&host, QPoint(112, 96));  // (0.35, 0.3)
  const ImportanceLens lensA = lastLens(spy);
  QTest::mouseMove(&host, QPoint(208, 192));  // (0.65, 0.6)
  const ImportanceLens lensB = lastLens(spy);
  QCOMPARE(lensA.x, 0.35f);
  QCOMPARE(lensA.y, 0.3f);
  QCOMPARE(lensB.x, 0.65f);
  QCOMPARE(lensB.strength, 0.f);

  const std::vector<float> muA = optimiseWith(lensA);
  const std::vector<float> muB = optimiseWith(lensB);
  QCOMPARE(muA.size(), size_t(kN) * kN * kN);
  QCOMPARE(muB.size(), muA.size());

  // Which rays a slab voxel lies on: its projection in normalised image coordinates.
  Engine reference;
  setupEngine(reference);
  const GridSpec g = reference.volume().grid();
  ViewContext engineView;
  engineView.camera = reference.camera();
  engineView.imageSize = QSize(kView, kView);
  // A voxel's footprint reaches about one voxel's projected size plus one frustum ray around it.
  const float margin = 0.1f;
  int outside = 0, onlyA = 0, onlyB = 0;
  float maxOutsideDiff = 0.f, minOnlyAGain = 1e30f, minOnlyBGain = 1e30f;
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const glm::vec3 x = g.indexToWorld(glm::vec3(float(i), float(j), float(k)));
        if (!(x.y >= -8.f && x.y <= -3.f)) continue;  // the slab
        const auto p = projectToWidget(engineView, x);
        QVERIFY(p);
        const glm::vec2 uv(float(p->x()) / kView, float(p->y()) / kView);
        const float dA = glm::length(uv - glm::vec2(lensA.x, lensA.y));
        const float dB = glm::length(uv - glm::vec2(lensB.x, lensB.y));
        const size_t v = g.linearIndex(i, j, k);
        // Only voxels in front of the important plane have anything to give way to.
        if (std::abs(x.x) > 7.f || std::abs(x.z) > 7.f) continue;
        if (dA > lensA.radius + margin && dB > lensB.radius + margin) {
          ++outside;
          maxOutsideDiff = std::max(maxOutsideDiff, std::abs(muA[v] - muB[v]));
        } else if (dA < 0.9f * lensA.radius - 0.06f && dB > lensB.radius + margin) {
          ++onlyA;
          minOnlyAGain = std::min(minOnlyAGain, muA[v] - muB[v]);
        } else if (dB < 0.9f * lensB.radius - 0.06f && dA > lensA.radius + margin) {
          ++onlyB;
          minOnlyBGain = std::min(minOnlyBGain, muB[v] - muA[v]);
        }
      }
  qInfo(
      "slab voxels: %d outside both lenses (max |muA - muB| %g), %d only in A (min gain %g), "
      "%d only in B (min gain %g)",
      outside, double(maxOutsideDiff), onlyA, double(minOnlyAGain), onlyB, double(minOnlyBGain));
  QVERIFY(outside > 100 && onlyA > 20 && onlyB > 20);
  const float muBar = 0.3f;  // the slab's base extinction
  QVERIFY2(maxOutsideDiff <= 1e-5f * muBar, "rays outside both lenses are unaffected");
  QVERIFY2(minOnlyAGain > 0.2f * muBar, "lens A keeps the occluder on its rays");
  QVERIFY2(minOnlyBGain > 0.2f * muBar, "lens B keeps the occluder on its rays");
}

// The window mask: nothing painted is "no mask" (a clear, never all-zero weights); a dab sends
// weights 1 - coverage, lowest under the brush; Escape mid-stroke restores the raster.
void TestLensTool::windowMaskEmptyMeansNoMask() {
  WindowMaskTool tool;
  tool.setRasterSize(64, 32);
  tool.setBrushRadius(20.0);
  QSignalSpy changed(&tool, &WindowMaskTool::windowMaskChanged);
  QSignalSpy cleared(&tool, &WindowMaskTool::windowMaskCleared);
  ViewContext view;
  view.imageSize = QSize(320, 160);
  ToolHost host(&tool, view);
  host.show();
  QVERIFY(tool.empty());

  QTest::mousePress(&host, Qt::LeftButton, {}, QPoint(80, 40));
  QTest::mouseRelease(&host, Qt::LeftButton, {}, QPoint(80, 40));
  QVERIFY(changed.count() >= 1);
  const auto weights = changed.last().at(0).value<std::vector<float>>();
  QCOMPARE(changed.last().at(1).toInt(), 64);
  QCOMPARE(changed.last().at(2).toInt(), 32);
  QCOMPARE(weights.size(), size_t(64 * 32));
  // The brush centre (80, 40) is cell (16, 8) (cells are 5 x 5 pixels; row 0 at the top).
  QCOMPARE(weights[8 * 64 + 16], 0.f);
  QCOMPARE(weights[31 * 64 + 63], 1.f);
  QCOMPARE(weights[8 * 64 + 40], 1.f);

  const std::vector<float> before = tool.coverage();
  QTest::mousePress(&host, Qt::LeftButton, {}, QPoint(250, 120));
  QTest::mouseMove(&host, QPoint(280, 130));
  QVERIFY(tool.coverage() != before);
  QTest::keyClick(&host, Qt::Key_Escape);
  QVERIFY(tool.coverage() == before);
  QTest::mouseRelease(&host, Qt::LeftButton, {}, QPoint(280, 130));

  // Ctrl-drag over the dab with a larger brush (its hard core covers the dab) removes it:
  // nothing painted, so the mask is cleared.
  tool.setBrushRadius(50.0);
  QTest::mousePress(&host, Qt::LeftButton, Qt::ControlModifier, QPoint(70, 40));
  QTest::mouseMove(&host, QPoint(90, 40));
  QTest::mouseRelease(&host, Qt::LeftButton, Qt::ControlModifier, QPoint(90, 40));
  QVERIFY(tool.empty());
  QVERIFY(cleared.count() >= 1);
}

QTEST_MAIN(TestLensTool)
#include "test_lens_tool.moc"
