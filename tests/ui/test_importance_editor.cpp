// Importance editor: the importance curve g(s) edited with the mouse, its debounced signal, the
// importance-volume button, the overlay switch and the "from volume" label.
#include <QtTest>

#include <QCheckBox>
#include <QLabel>
#include <QPushButton>
#include <QSignalSpy>

#include <cmath>
#include <memory>
#include <vector>

#include "widgets/curve_editor.h"
#include "widgets/histogram.h"
#include "widgets/importance_editor.h"

using visopt::ws::CurveEditor;
using visopt::ws::Histogram;
using visopt::ws::ImportanceEditor;
using Curve = std::vector<glm::dvec2>;

namespace {

std::shared_ptr<const Histogram> histogram(double lo, double hi) {
  auto h = std::make_shared<Histogram>();
  h->valueMin = lo;
  h->valueMax = hi;
  h->counts = {5.0, 1.0, 7.0, 2.0, 9.0, 3.0, 4.0, 8.0};
  return h;
}

// g(s) of a piecewise-linear curve, constant outside (the library's importance curve).
double curveAt(const Curve& c, double s) {
  if (s <= c.front().x) return c.front().y;
  if (s >= c.back().x) return c.back().y;
  for (size_t i = 1; i < c.size(); ++i)
    if (s <= c[i].x)
      return c[i].x > c[i - 1].x
                 ? c[i - 1].y + (c[i].y - c[i - 1].y) * (s - c[i - 1].x) / (c[i].x - c[i - 1].x)
                 : c[i].y;
  return c.back().y;
}

}  // namespace

class TestImportanceEditor : public QObject {
  Q_OBJECT

 private:
  void setUp(ImportanceEditor& ed, const Curve& curve) {
    ed.resize(600, 360);
    ed.setHistogram(histogram(-1000.0, 3000.0));
    ed.setCurve(curve);
    ed.show();
    QVERIFY(QTest::qWaitForWindowExposed(&ed));
    QCOMPARE(ed.curveEditor()->valueMin(), -1000.0);
    QCOMPARE(ed.curveEditor()->valueMax(), 3000.0);
    QVERIFY(!ed.curveEditor()->colorStripEnabled());
  }

 private slots:
  void clickAddsPoint();
  void dragMovesAndClamps();
  void deleteKeepsOnePoint();
  void debounce();
  void setCurveDoesNotEmit();
  void loadVolumeButton();
  void overlayCheckBox();
  void volumeLabel();
};

void TestImportanceEditor::clickAddsPoint() {
  ImportanceEditor ed;
  setUp(ed, {{-1000.0, 0.0}, {3000.0, 0.0}});
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &ImportanceEditor::importanceCurveEdited);
  const double s = 1200.0;
  const double g = 0.8;
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(s, g).toPoint());
  const Curve curve = ed.curve();
  QCOMPARE(curve.size(), size_t{3});
  QVERIFY2(std::abs(curve[1].x - s) <= c->valuePerPixel(), qPrintable(QString::number(curve[1].x)));
  QVERIFY2(std::abs(curve[1].y - g) <= c->yPerPixel(), qPrintable(QString::number(curve[1].y)));
  QCOMPARE(spy.count(), 0);
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  const Curve sent = qvariant_cast<Curve>(spy.at(0).at(0));
  QCOMPARE(sent, curve);
  QVERIFY(std::abs(curveAt(sent, s) - g) <= c->yPerPixel() + 2.0 * g / 2200.0 * c->valuePerPixel());
  QCOMPARE(curveAt(sent, 2900.0) < 0.1, true);
}

void TestImportanceEditor::dragMovesAndClamps() {
  ImportanceEditor ed;
  setUp(ed, {{-1000.0, 1.0}, {500.0, 0.5}, {3000.0, 1.0}});
  CurveEditor* c = ed.curveEditor();
  QTest::mousePress(c, Qt::LeftButton, {}, c->toWidget(500.0, 0.5).toPoint());
  QTest::mouseMove(c, c->toWidget(900.0, 0.3).toPoint());
  QTest::mouseMove(c, c->toWidget(1500.0, 0.1).toPoint());
  QTest::mouseRelease(c, Qt::LeftButton, {}, c->toWidget(1500.0, 0.1).toPoint());
  Curve curve = ed.curve();
  QCOMPARE(curve.size(), size_t{3});
  QVERIFY2(std::abs(curve[1].x - 1500.0) <= c->valuePerPixel() * 1.0001,
           qPrintable(QString::number(curve[1].x)));
  QVERIFY2(std::abs(curve[1].y - 0.1) <= c->yPerPixel() * 1.0001,
           qPrintable(QString::number(curve[1].y)));
  // Past the last point and below 0: x stops at 3000, g at 0.
  QTest::mousePress(c, Qt::LeftButton, {}, c->toWidget(curve[1].x, curve[1].y).toPoint());
  QTest::mouseMove(c, c->toWidget(3500.0, -0.5).toPoint());
  QTest::mouseRelease(c, Qt::LeftButton, {}, c->toWidget(3500.0, -0.5).toPoint());
  curve = ed.curve();
  QCOMPARE(curve[1].x, 3000.0);
  QCOMPARE(curve[1].y, 0.0);
  QCOMPARE(curve[2], glm::dvec2(3000.0, 1.0));
}

void TestImportanceEditor::deleteKeepsOnePoint() {
  ImportanceEditor ed;
  setUp(ed, {{-1000.0, 1.0}, {500.0, 0.5}, {3000.0, 1.0}});
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &ImportanceEditor::importanceCurveEdited);
  QTest::mouseClick(c, Qt::RightButton, {}, c->toWidget(500.0, 0.5).toPoint());
  QCOMPARE(ed.curve(), (Curve{{-1000.0, 1.0}, {3000.0, 1.0}}));
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(3000.0, 1.0).toPoint());
  QTest::keyClick(c, Qt::Key_Backspace);
  QCOMPARE(ed.curve(), (Curve{{-1000.0, 1.0}}));
  QTest::mouseClick(c, Qt::RightButton, {}, c->toWidget(-1000.0, 1.0).toPoint());
  QCOMPARE(ed.curve().size(), size_t{1});
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  QCOMPARE(qvariant_cast<Curve>(spy.at(0).at(0)), (Curve{{-1000.0, 1.0}}));
}

void TestImportanceEditor::debounce() {
  ImportanceEditor ed;
  setUp(ed, {{-1000.0, 0.0}, {3000.0, 1.0}});
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &ImportanceEditor::importanceCurveEdited);
  for (double s : {0.0, 1000.0, 2000.0})
    QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(s, 0.9).toPoint());
  QCOMPARE(spy.count(), 0);
  QVERIFY(ed.editPending());
  ed.flushPendingEdit();
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  QCOMPARE(qvariant_cast<Curve>(spy.at(0).at(0)).size(), size_t{5});
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(2500.0, 0.2).toPoint());
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(-500.0, 0.2).toPoint());
  QTRY_COMPARE(spy.count(), 2);
  QTest::qWait(3 * ImportanceEditor::editDebounceMs);
  QCOMPARE(spy.count(), 2);
  QCOMPARE(qvariant_cast<Curve>(spy.at(1).at(0)).size(), size_t{7});
}

void TestImportanceEditor::setCurveDoesNotEmit() {
  ImportanceEditor ed;
  setUp(ed, {{-1000.0, 0.0}, {3000.0, 1.0}});
  QSignalSpy spy(&ed, &ImportanceEditor::importanceCurveEdited);
  // Sorted on the way in, g clamped to [0, 1].
  ed.setCurve({{2000.0, 1.5}, {0.0, 0.25}, {1000.0, -0.5}});
  QCOMPARE(ed.curve(), (Curve{{0.0, 0.25}, {1000.0, 0.0}, {2000.0, 1.0}}));
  CurveEditor* c = ed.curveEditor();
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(1500.0, 0.9).toPoint());
  QVERIFY(ed.editPending());
  ed.setCurve({{0.0, 1.0}});  // drops the pending edit
  QVERIFY(!ed.editPending());
  QTest::qWait(3 * ImportanceEditor::editDebounceMs);
  QCOMPARE(spy.count(), 0);
  // Without a histogram the view spans the curve.
  ImportanceEditor bare;
  bare.setCurve({{10.0, 0.0}, {20.0, 1.0}});
  QCOMPARE(bare.curveEditor()->valueMin(), 10.0);
  QCOMPARE(bare.curveEditor()->valueMax(), 20.0);
}

void TestImportanceEditor::loadVolumeButton() {
  ImportanceEditor ed;
  setUp(ed, {{0.0, 1.0}});
  QSignalSpy spy(&ed, &ImportanceEditor::importanceVolumeRequested);
  ed.setOpenFileDialog([] { return QString(); });  // cancelled
  QTest::mouseClick(ed.loadVolumeButton(), Qt::LeftButton);
  QCOMPARE(spy.count(), 0);
  ed.setOpenFileDialog([] { return QStringLiteral("/data/importance.nrrd"); });
  QTest::mouseClick(ed.loadVolumeButton(), Qt::LeftButton);
  QCOMPARE(spy.count(), 1);
  QCOMPARE(spy.at(0).at(0).toString(), QStringLiteral("/data/importance.nrrd"));
}

void TestImportanceEditor::overlayCheckBox() {
  ImportanceEditor ed;
  setUp(ed, {{0.0, 1.0}});
  QSignalSpy spy(&ed, &ImportanceEditor::overlayToggled);
  QTest::mouseClick(ed.overlayCheckBox(), Qt::LeftButton);
  QCOMPARE(spy.count(), 1);
  QCOMPARE(spy.at(0).at(0).toBool(), true);
  QVERIFY(ed.overlayChecked());
  QTest::mouseClick(ed.overlayCheckBox(), Qt::LeftButton);
  QCOMPARE(spy.count(), 2);
  QCOMPARE(spy.at(1).at(0).toBool(), false);
  ed.setOverlayChecked(true);  // programmatic: no signal
  QVERIFY(ed.overlayChecked());
  QCOMPARE(spy.count(), 2);
}

void TestImportanceEditor::volumeLabel() {
  ImportanceEditor ed;
  setUp(ed, {{0.0, 1.0}});
  QVERIFY(!ed.volumeLabel()->isVisible());
  ed.setImportanceVolumeName(QStringLiteral("bones.nrrd"));
  QVERIFY(ed.volumeLabel()->isVisible());
  QVERIFY(ed.volumeLabel()->text().contains(QStringLiteral("bones.nrrd")));
  QCOMPARE(ed.importanceVolumeName(), QStringLiteral("bones.nrrd"));
  ed.setImportanceVolumeName(QString());
  QVERIFY(!ed.volumeLabel()->isVisible());
}

QTEST_MAIN(TestImportanceEditor)
#include "test_importance_editor.moc"
