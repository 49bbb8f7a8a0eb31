// Transfer-function editor: the histogram, the curve editor driven by the mouse and keyboard, the
// debounced signal, presets (built-in, resource, user round trip) and ParaView import.
#include <QtTest>

#include <QCheckBox>
#include <QComboBox>
#include <QFile>
#include <QImage>
#include <QMouseEvent>
#include <QPushButton>
#include <QSignalSpy>
#include <QTemporaryDir>

#include <cmath>
#include <limits>
#include <memory>

#include "visopt/transfer_function.h"
#include "visopt/volume.h"
#include "widgets/curve_editor.h"
#include "widgets/histogram.h"
#include "widgets/transfer_function_editor.h"

using visopt::TransferFunction;
using visopt::ws::CurveEditor;
using visopt::ws::Histogram;
using visopt::ws::TransferFunctionEditor;

namespace {

TransferFunction makeTf(std::vector<visopt::OpacityPoint> opacity,
                        std::vector<visopt::ColorPoint> color = {{0.0, glm::vec3(0.f)},
                                                                 {100.0, glm::vec3(1.f)}}) {
  TransferFunction tf;
  tf.name = "test";
  tf.opacity = std::move(opacity);
  tf.color = std::move(color);
  return tf;
}

std::shared_ptr<const Histogram> rampHistogram(double lo, double hi, int bins = 50) {
  auto h = std::make_shared<Histogram>();
  h->valueMin = lo;
  h->valueMax = hi;
  for (int i = 0; i < bins; ++i) h->counts.push_back(i == 3 ? 100000.0 : 10.0 + i);
  return h;
}

visopt::Volume makeVolume(const std::vector<float>& values, glm::ivec3 dims, double lo, double hi,
                          visopt::Precision precision) {
  visopt::Volume v;
  v.name = "synthetic";
  v.valueMin = lo;
  v.valueMax = hi;
  visopt::GridSpec grid;
  grid.dims = dims;
  v.normalized = visopt::Field3D("synthetic", grid, precision);
  for (size_t i = 0; i < values.size(); ++i)
    v.normalized.set(i, std::isnan(values[i]) ? values[i] : v.toNormalized(values[i]));
  return v;
}

bool samePoints(const TransferFunction& a, const TransferFunction& b) {
  if (a.opacity.size() != b.opacity.size() || a.color.size() != b.color.size()) return false;
  for (size_t i = 0; i < a.opacity.size(); ++i)
    if (a.opacity[i].value != b.opacity[i].value || a.opacity[i].opacity != b.opacity[i].opacity)
      return false;
  for (size_t i = 0; i < a.color.size(); ++i)
    if (a.color[i].value != b.color[i].value || a.color[i].rgb != b.color[i].rgb) return false;
  return true;
}

QString describe(const TransferFunction& tf) {
  QString s;
  for (const auto& p : tf.opacity) s += QStringLiteral("(%1, %2) ").arg(p.value).arg(p.opacity);
  return s;
}

}  // namespace

class TestTfEditor : public QObject {
  Q_OBJECT

 private:
  // An editor showing `tf` over a histogram on [0, 100], shown (offscreen) at a fixed size.
  void setUp(TransferFunctionEditor& ed, const TransferFunction& tf) {
    ed.setInteractive(false);
    ed.setUserPresetDir(QStringLiteral(VISOPT_TEST_TMP "/tf-editor-no-user-presets"));
    ed.resize(640, 420);
    ed.setHistogram(rampHistogram(0.0, 100.0));
    ed.setTransferFunction(tf);
    ed.show();
    QVERIFY(QTest::qWaitForWindowExposed(&ed));
    QVERIFY(ed.curveEditor()->plotRect().width() > 300.0);
    QCOMPARE(ed.curveEditor()->valueMin(), 0.0);
    QCOMPARE(ed.curveEditor()->valueMax(), 100.0);
  }

 private slots:
  void histogramExactCounts();
  void histogramLargeParallel();
  void histogramDegenerateRange();
  void clickAddsPoint();
  void dragMovesPoint();
  void dragIsClamped();
  void deleteByRightClickAndKey();
  void colorStopsAddAndPick();
  void tooltipShowsExactValues();
  void debounceGivesOneSignal();
  void setTransferFunctionDoesNotEmit();
  void builtinPresets();
  void userPresetRoundTrip();
  void paraviewImport();
  void importErrorsAreReported();
  void logScaleChangesDrawing();
};

void TestTfEditor::histogramExactCounts() {
  // Range [-10, 10] in 4 bins of 5: [-10,-5) [-5,0) [0,5) [5,10]; a NaN (fp32 only: fp16
  // storage saturates it) is not counted.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (visopt::Precision precision : {visopt::Precision::FP32, visopt::Precision::FP16}) {
    std::vector<float> values = {-10.f, -7.f, -5.f, -1.f, 0.f, 2.5f, 4.9f, 5.f, 10.f, 1.f};
    if (precision == visopt::Precision::FP32) values.back() = nan;
    const visopt::Volume v = makeVolume(values, {5, 2, 1}, -10.0, 10.0, precision);
    const Histogram h = visopt::ws::computeHistogram(v, 4);
    const std::vector<double> expected = precision == visopt::Precision::FP32
                                             ? std::vector<double>{2.0, 2.0, 3.0, 2.0}
                                             : std::vector<double>{2.0, 2.0, 4.0, 2.0};
    QVERIFY2(h.counts == expected, visopt::toString(precision));
    QCOMPARE(h.valueMin, -10.0);
    QCOMPARE(h.valueMax, 10.0);
    QCOMPARE(h.total(), precision == visopt::Precision::FP32 ? 9.0 : 10.0);
    QCOMPARE(h.maxCount(), precision == visopt::Precision::FP32 ? 3.0 : 4.0);
    QCOMPARE(h.binWidth(), 5.0);
  }
}

void TestTfEditor::histogramLargeParallel() {
  // 64^3 voxels with values i % 7 over [0, 6] in 7 bins: value k lands in bin k.
  const glm::ivec3 dims(64, 64, 64);
  const size_t n = 64 * 64 * 64;
  std::vector<float> values(n);
  for (size_t i = 0; i < n; ++i) values[i] = static_cast<float>(i % 7);
  const visopt::Volume v = makeVolume(values, dims, 0.0, 6.0, visopt::Precision::FP32);
  const Histogram h = visopt::ws::computeHistogram(v, 7);
  QCOMPARE(h.bins(), 7);
  for (size_t k = 0; k < 7; ++k) {
    const double expected = static_cast<double>(n / 7 + (k < n % 7 ? 1 : 0));
    QCOMPARE(h.counts[k], expected);
  }
  // The default bin count, and the same total.
  const Histogram h256 = visopt::ws::computeHistogram(v);
  QCOMPARE(h256.bins(), 256);
  QCOMPARE(h256.total(), static_cast<double>(n));
}

void TestTfEditor::histogramDegenerateRange() {
  const visopt::Volume v =
      makeVolume({3.f, 3.f, 3.f}, {3, 1, 1}, 3.0, 3.0, visopt::Precision::FP32);
  const Histogram h = visopt::ws::computeHistogram(v, 8);
  QCOMPARE(h.counts[0], 3.0);
  QCOMPARE(h.total(), 3.0);
  const Histogram one = visopt::ws::computeHistogram(v, 0);  // at least one bin
  QCOMPARE(one.bins(), 1);
}

void TestTfEditor::clickAddsPoint() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  const double v = 30.0;
  const double a = 0.7;
  QVERIFY(std::abs(ed.transferFunction().opacityAt(v) - 0.3f) < 1e-6f);

  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(v, a).toPoint());
  QCOMPARE(c->points().size(), size_t{3});
  QCOMPARE(c->selectedPoint(), 1);
  const glm::dvec2 p = c->points()[1];
  QVERIFY2(std::abs(p.x - v) <= c->valuePerPixel(), qPrintable(QString::number(p.x)));
  QVERIFY2(std::abs(p.y - a) <= c->yPerPixel(), qPrintable(QString::number(p.y)));

  QCOMPARE(spy.count(), 0);  // debounced
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  const auto tf = qvariant_cast<TransferFunction>(spy.at(0).at(0));
  QCOMPARE(tf.opacity.size(), size_t{3});
  QVERIFY(samePoints(tf, ed.transferFunction()));
  // The library's function now goes through the new point.
  const double slope = a / v;  // steepest segment next to the point, roughly
  QVERIFY2(std::abs(tf.opacityAt(v) - a) <= c->yPerPixel() + 2.0 * slope * c->valuePerPixel(),
           qPrintable(describe(tf)));
  QCOMPARE(tf.opacityAt(0.0), 0.f);
  QCOMPARE(tf.opacityAt(100.0), 1.f);
  QCOMPARE(tf.name, std::string("test"));
}

void TestTfEditor::dragMovesPoint() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {50.0, 0.5f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  const QPoint from = c->toWidget(50.0, 0.5).toPoint();
  const QPoint via = c->toWidget(60.0, 0.4).toPoint();
  const QPoint to = c->toWidget(70.0, 0.2).toPoint();
  QTest::mousePress(c, Qt::LeftButton, {}, from);
  QTest::mouseMove(c, via);
  QTest::mouseMove(c, to);
  QTest::mouseRelease(c, Qt::LeftButton, {}, to);

  QCOMPARE(c->points().size(), size_t{3});  // moved, not added
  const glm::dvec2 p = c->points()[1];
  // Grabbing keeps the offset between the press and the point's centre: within a pixel.
  QVERIFY2(std::abs(p.x - 70.0) <= c->valuePerPixel() * 1.0001, qPrintable(QString::number(p.x)));
  QVERIFY2(std::abs(p.y - 0.2) <= c->yPerPixel() * 1.0001, qPrintable(QString::number(p.y)));
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  const TransferFunction tf = ed.transferFunction();
  QVERIFY(std::abs(tf.opacityAt(p.x) - static_cast<float>(p.y)) < 1e-6f);
  // At the old place the opacity now follows the segment (0,0)-(p): about 0.2 * 50 / 70.
  QVERIFY2(std::abs(tf.opacityAt(50.0) - 0.2 * 50.0 / 70.0) < 0.01, qPrintable(describe(tf)));
  QCOMPARE(tf.opacity[0].value, 0.0);
  QCOMPARE(tf.opacity[2].value, 100.0);
  QCOMPARE(tf.opacity[2].opacity, 1.f);
}

void TestTfEditor::dragIsClamped() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {40.0, 0.5f}, {60.0, 0.6f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  // Past the next point's value and above the top: x stops at the neighbour, y at 1.
  QTest::mousePress(c, Qt::LeftButton, {}, c->toWidget(40.0, 0.5).toPoint());
  QTest::mouseMove(c, c->toWidget(90.0, 1.3).toPoint());
  QTest::mouseRelease(c, Qt::LeftButton, {}, c->toWidget(90.0, 1.3).toPoint());
  QCOMPARE(c->points().size(), size_t{4});
  QCOMPARE(c->points()[1].x, 60.0);
  QCOMPARE(c->points()[1].y, 1.0);
  // Now (0,0) (60,1) (60,0.6) (100,1). Moving (60,1) before its left neighbour and below the
  // bottom: x stops at the neighbour, y at 0.
  QTest::mousePress(c, Qt::LeftButton, {}, c->toWidget(60.0, 1.0).toPoint());
  QCOMPARE(c->selectedPoint(), 1);
  QTest::mouseMove(c, c->toWidget(-20.0, -0.4).toPoint());
  QTest::mouseRelease(c, Qt::LeftButton, {}, c->toWidget(-20.0, -0.4).toPoint());
  const auto& pts = c->points();
  QCOMPARE(pts.size(), size_t{4});
  for (size_t i = 1; i < pts.size(); ++i) QVERIFY(pts[i - 1].x <= pts[i].x);
  QCOMPARE(pts[1].x, 0.0);
  QCOMPARE(pts[1].y, 0.0);
  QCOMPARE(pts[2].x, 60.0);  // the other point at 60 stayed
  QCOMPARE(pts[2].y, static_cast<double>(0.6f));
  ed.flushPendingEdit();
  TransferFunction tf = ed.transferFunction();
  tf.validate("dragged");  // still a valid, sorted function
}

void TestTfEditor::deleteByRightClickAndKey() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {50.0, 0.5f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  // A right click on empty space does nothing.
  QTest::mouseClick(c, Qt::RightButton, {}, c->toWidget(20.0, 0.9).toPoint());
  QCOMPARE(c->points().size(), size_t{3});
  QVERIFY(!ed.editPending());
  // A right click on a point deletes it.
  QTest::mouseClick(c, Qt::RightButton, {}, c->toWidget(50.0, 0.5).toPoint());
  QCOMPARE(c->points().size(), size_t{2});
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  QVERIFY(std::abs(ed.transferFunction().opacityAt(50.0) - 0.5f) < 1e-6f);  // now (0,0)-(100,1)
  QCOMPARE(ed.transferFunction().opacity[0].value, 0.0);
  QCOMPARE(ed.transferFunction().opacity[1].value, 100.0);
  // Select with a click (no move: nothing changes), then Delete.
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(100.0, 1.0).toPoint());
  QCOMPARE(c->selectedPoint(), 1);
  QCOMPARE(c->points().size(), size_t{2});
  QVERIFY(!ed.editPending());
  QTest::keyClick(c, Qt::Key_Delete);
  QCOMPARE(c->points().size(), size_t{1});
  QCOMPARE(c->points()[0].x, 0.0);
  // The last point stays (the library refuses an empty list).
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(0.0, 0.0).toPoint());
  QCOMPARE(c->selectedPoint(), 0);
  QTest::keyClick(c, Qt::Key_Delete);
  QTest::mouseClick(c, Qt::RightButton, {}, c->toWidget(0.0, 0.0).toPoint());
  QCOMPARE(c->points().size(), size_t{1});
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 2);
  QCOMPARE(qvariant_cast<TransferFunction>(spy.at(1).at(0)).opacity.size(), size_t{1});
}

void TestTfEditor::colorStopsAddAndPick() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  QVERIFY(c->colorStripEnabled());
  QVERIFY(!c->stripRect().isEmpty());
  int pickerCalls = 0;
  QColor offered;
  c->setColorPicker([&](const QColor& current, QWidget*) -> std::optional<QColor> {
    ++pickerCalls;
    offered = current;
    return QColor::fromRgbF(1.f, 0.f, 0.f);
  });
  // A click in the strip adds a stop with the colour already there (grey at 50).
  QTest::mouseClick(c, Qt::LeftButton, {}, c->colorStopPosition(50.0).toPoint());
  QCOMPARE(c->colorStops().size(), size_t{3});
  QCOMPARE(c->points().size(), size_t{2});  // not an opacity point
  const visopt::ws::ColorStop added = c->colorStops()[1];
  QVERIFY(std::abs(added.value - 50.0) <= c->valuePerPixel());
  QVERIFY(std::abs(added.rgb.g - static_cast<float>(added.value / 100.0)) < 1e-5f);
  // A double click on it picks its colour through the hook.
  QTest::mouseDClick(c, Qt::LeftButton, {}, c->colorStopPosition(added.value).toPoint());
  QCOMPARE(pickerCalls, 1);
  QVERIFY(std::abs(offered.greenF() - added.rgb.g) < 0.01f);
  QCOMPARE(c->colorStops().size(), size_t{3});
  ed.flushPendingEdit();
  const TransferFunction tf = ed.transferFunction();
  QCOMPARE(tf.color.size(), size_t{3});
  QCOMPARE(tf.color[1].rgb, glm::vec3(1.f, 0.f, 0.f));
  QCOMPARE(tf.colorAt(tf.color[1].value), glm::vec3(1.f, 0.f, 0.f));
  // Dragging a stop moves it along x only; a picker that cancels changes nothing.
  c->setColorPicker([](const QColor&, QWidget*) { return std::optional<QColor>(); });
  QTest::mousePress(c, Qt::LeftButton, {}, c->colorStopPosition(tf.color[1].value).toPoint());
  QTest::mouseMove(c, c->colorStopPosition(80.0).toPoint());
  QTest::mouseRelease(c, Qt::LeftButton, {}, c->colorStopPosition(80.0).toPoint());
  QVERIFY(std::abs(c->colorStops()[1].value - 80.0) <= c->valuePerPixel() * 1.0001);
  QTest::mouseDClick(c, Qt::LeftButton, {}, c->colorStopPosition(80.0).toPoint());
  QCOMPARE(c->colorStops()[1].rgb, glm::vec3(1.f, 0.f, 0.f));
  // Right click deletes a stop.
  QTest::mouseClick(c, Qt::RightButton, {},
                    c->colorStopPosition(c->colorStops()[1].value).toPoint());
  QCOMPARE(c->colorStops().size(), size_t{2});
}

void TestTfEditor::tooltipShowsExactValues() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {37.25, 0.625f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  const QString tip = c->toolTipTextAt(c->toWidget(37.25, 0.625));
  QVERIFY2(tip.contains(QStringLiteral("37.25")) && tip.contains(QStringLiteral("0.625")),
           qPrintable(tip));
  QVERIFY2(tip.contains(QStringLiteral("opacity")), qPrintable(tip));
  // Hover highlights the point under the mouse.
  const QPoint over = c->toWidget(37.25, 0.625).toPoint();
  QMouseEvent move(QEvent::MouseMove, QPointF(over), QPointF(c->mapToGlobal(over)), Qt::NoButton,
                   Qt::NoButton, Qt::NoModifier);
  QApplication::sendEvent(c, &move);
  QCOMPARE(c->hoveredPoint(), 1);
  const QString empty = c->toolTipTextAt(c->toWidget(80.0, 0.1));
  QVERIFY2(empty.startsWith(QStringLiteral("value 8")), qPrintable(empty));
  QVERIFY2(empty.contains(QStringLiteral("count")), qPrintable(empty));
}

void TestTfEditor::debounceGivesOneSignal() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {50.0, 0.5f}, {100.0, 1.f}}));
  CurveEditor* c = ed.curveEditor();
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  QTest::mousePress(c, Qt::LeftButton, {}, c->toWidget(50.0, 0.5).toPoint());
  for (int i = 1; i <= 5; ++i) QTest::mouseMove(c, c->toWidget(50.0 + i, 0.5 - 0.05 * i).toPoint());
  QTest::mouseRelease(c, Qt::LeftButton, {}, c->toWidget(55.0, 0.25).toPoint());
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(80.0, 0.1).toPoint());  // adds a point
  QCOMPARE(spy.count(), 0);
  QVERIFY(ed.editPending());
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  QVERIFY(samePoints(qvariant_cast<TransferFunction>(spy.at(0).at(0)), ed.transferFunction()));
  QCOMPARE(ed.transferFunction().opacity.size(), size_t{4});
  ed.flushPendingEdit();  // nothing pending: no second signal
  QCOMPARE(spy.count(), 1);
  // Without a flush, the timer emits once after the edits stop.
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(20.0, 0.8).toPoint());
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(30.0, 0.8).toPoint());
  QCOMPARE(spy.count(), 1);
  QTRY_COMPARE(spy.count(), 2);
  QTest::qWait(3 * TransferFunctionEditor::editDebounceMs);
  QCOMPARE(spy.count(), 2);
  QCOMPARE(qvariant_cast<TransferFunction>(spy.at(1).at(0)).opacity.size(), size_t{6});
}

void TestTfEditor::setTransferFunctionDoesNotEmit() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  TransferFunction tf = makeTf({{10.0, 0.25f}, {90.0, 0.75f}});
  tf.name = "other";
  tf.unitDistance = 2.5f;
  ed.setTransferFunction(tf);
  QTest::qWait(3 * TransferFunctionEditor::editDebounceMs);
  QCOMPARE(spy.count(), 0);
  QVERIFY(samePoints(ed.transferFunction(), tf));
  QCOMPARE(ed.transferFunction().name, std::string("other"));
  QCOMPARE(ed.transferFunction().unitDistance, 2.5f);
  // A pending edit is dropped by setTransferFunction.
  CurveEditor* c = ed.curveEditor();
  QTest::mouseClick(c, Qt::LeftButton, {}, c->toWidget(50.0, 0.9).toPoint());
  QVERIFY(ed.editPending());
  ed.setTransferFunction(tf);
  QVERIFY(!ed.editPending());
  ed.flushPendingEdit();
  QTest::qWait(3 * TransferFunctionEditor::editDebounceMs);
  QCOMPARE(spy.count(), 0);
}

void TestTfEditor::builtinPresets() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  for (const std::string& name : TransferFunction::presetNames())
    QVERIFY2(ed.findPreset(QString::fromStdString(name)) > 0, name.c_str());
  QVERIFY(ed.findPreset(QStringLiteral("paraview-export-example (resource)")) > 0);
  // Built-in files are listed once, as built-ins.
  QCOMPARE(ed.findPreset(QStringLiteral("ct-bone (resource)")), -1);

  QVERIFY(ed.applyPreset(ed.findPreset(QStringLiteral("ct-bone"))));
  QVERIFY(samePoints(ed.transferFunction(), TransferFunction::preset("ct-bone")));
  // "generic" spans the histogram's range.
  QVERIFY(ed.applyPreset(ed.findPreset(QStringLiteral("generic"))));
  QVERIFY(samePoints(ed.transferFunction(), TransferFunction::preset("generic", 0.0, 100.0)));
  QCOMPARE(ed.presetCombo()->currentText(), QStringLiteral("generic"));
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);  // both loads, debounced into one
  QVERIFY(samePoints(qvariant_cast<TransferFunction>(spy.at(0).at(0)),
                     TransferFunction::preset("generic", 0.0, 100.0)));
  // Choosing from the combo box loads too.
  const int mri = ed.findPreset(QStringLiteral("mri"));
  ed.presetCombo()->setCurrentIndex(mri);
  emit ed.presetCombo()->activated(mri);
  QVERIFY(samePoints(ed.transferFunction(), TransferFunction::preset("mri")));
  QVERIFY(!ed.applyPreset(0));  // the placeholder
  QVERIFY(!ed.applyPreset(10000));
}

void TestTfEditor::userPresetRoundTrip() {
  QTemporaryDir tmp(QStringLiteral(VISOPT_TEST_TMP "/tf-presets-XXXXXX"));
  QVERIFY(tmp.isValid());
  const QString dir = tmp.path() + QStringLiteral("/user presets");  // created on save
  TransferFunction original = makeTf(
      {{-12.345678901234, 0.f}, {7.125, 0.123456f}, {33.3, 0.987654f}, {99.99, 0.5f}},
      {{-12.345678901234, glm::vec3(0.1f, 0.2f, 0.3f)}, {50.5, glm::vec3(0.9f, 0.123457f, 0.f)}});
  original.unitDistance = 0.75f;
  {
    TransferFunctionEditor ed;
    setUp(ed, original);
    ed.setUserPresetDir(dir);
    QVERIFY(ed.saveUserPreset(QStringLiteral("My bones/1")));
    QVERIFY(QFile::exists(dir + QStringLiteral("/My bones_1.json")));
    const int index = ed.findPreset(QStringLiteral("My bones_1 (user)"));
    QVERIFY(index > 0);
    QCOMPARE(ed.presetCombo()->currentIndex(), index);
    // Through the button, with the name dialog bypassed.
    ed.setPresetNameDialog([] { return QStringLiteral("second"); });
    QTest::mouseClick(ed.savePresetButton(), Qt::LeftButton);
    QVERIFY(QFile::exists(dir + QStringLiteral("/second.json")));
    // A cancelled name dialog saves nothing.
    ed.setPresetNameDialog([] { return QString(); });
    QTest::mouseClick(ed.savePresetButton(), Qt::LeftButton);
    QCOMPARE(QDir(dir).entryList({QStringLiteral("*.json")}, QDir::Files).size(), 2);
  }
  // A fresh editor finds the presets on disk and loads the same points.
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  ed.setUserPresetDir(dir);
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  const int index = ed.findPreset(QStringLiteral("My bones_1 (user)"));
  QVERIFY(index > 0);
  QVERIFY(ed.applyPreset(index));
  const TransferFunction loaded = ed.transferFunction();
  QVERIFY2(samePoints(loaded, original), qPrintable(describe(loaded)));
  QCOMPARE(loaded.name, std::string("My bones/1"));
  QCOMPARE(loaded.unitDistance, 0.75f);
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  QVERIFY(ed.applyPreset(ed.findPreset(QStringLiteral("second (user)"))));
  QVERIFY(samePoints(ed.transferFunction(), original));
  // An empty name is refused with a message.
  QSignalSpy errors(&ed, &TransferFunctionEditor::errorOccurred);
  QVERIFY(!ed.saveUserPreset(QStringLiteral("  ")));
  QCOMPARE(errors.count(), 1);
}

void TestTfEditor::paraviewImport() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  QSignalSpy spy(&ed, &TransferFunctionEditor::transferFunctionEdited);
  const QString file =
      QStringLiteral(VISOPT_RESOURCE_DIR "/transfer-functions/paraview-export-example.json");
  ed.setOpenFileDialog([file] { return file; });
  QTest::mouseClick(ed.importButton(), Qt::LeftButton);
  const TransferFunction tf = ed.transferFunction();
  QCOMPARE(tf.opacity.size(), size_t{4});
  const double values[] = {-1000.0, -200.0, 400.0, 2000.0};
  const float alphas[] = {0.f, 0.1f, 0.8f, 1.f};
  for (size_t i = 0; i < 4; ++i) {
    QCOMPARE(tf.opacity[i].value, values[i]);
    QCOMPARE(tf.opacity[i].opacity, alphas[i]);
  }
  QCOMPARE(tf.color.size(), size_t{3});
  QCOMPARE(tf.color[1].value, 500.0);
  QCOMPARE(tf.color[1].rgb, glm::vec3(0.865f));
  QVERIFY(std::abs(tf.color[0].rgb.b - 0.752941176471f) < 1e-6f);
  ed.flushPendingEdit();
  QCOMPARE(spy.count(), 1);
  QVERIFY(samePoints(qvariant_cast<TransferFunction>(spy.at(0).at(0)), tf));
  // The same file from the resource presets gives the same function.
  ed.setTransferFunction(makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  QVERIFY(ed.applyPreset(ed.findPreset(QStringLiteral("paraview-export-example (resource)"))));
  QVERIFY(samePoints(ed.transferFunction(), tf));
  // A cancelled file dialog changes nothing.
  ed.setTransferFunction(makeTf({{0.0, 0.f}, {100.0, 1.f}}));
  ed.setOpenFileDialog([] { return QString(); });
  QTest::mouseClick(ed.importButton(), Qt::LeftButton);
  QCOMPARE(ed.transferFunction().opacity.size(), size_t{2});
  QVERIFY(!ed.editPending());
}

void TestTfEditor::importErrorsAreReported() {
  QTemporaryDir tmp(QStringLiteral(VISOPT_TEST_TMP "/tf-import-XXXXXX"));
  QVERIFY(tmp.isValid());
  const auto write = [&](const QString& name, const QByteArray& text) {
    QFile f(tmp.filePath(name));
    if (!f.open(QIODevice::WriteOnly)) return QString();
    f.write(text);
    return f.fileName();
  };
  TransferFunctionEditor ed;
  const TransferFunction before = makeTf({{0.0, 0.f}, {100.0, 1.f}});
  setUp(ed, before);
  QSignalSpy errors(&ed, &TransferFunctionEditor::errorOccurred);
  QSignalSpy edits(&ed, &TransferFunctionEditor::transferFunctionEdited);

  QVERIFY(!ed.importFile(write(QStringLiteral("broken.json"), "{ not json")));
  QCOMPARE(errors.count(), 1);
  QVERIFY2(errors.at(0).at(0).toString().contains(QStringLiteral("broken.json")),
           qPrintable(errors.at(0).at(0).toString()));
  const QByteArray badAlpha = R"([{"Name":"bad","RGBPoints":[0,0,0,0, 1,1,1,1],
                                   "Points":[0,1.5,0.5,0, 1,0.2,0.5,0]}])";
  QVERIFY(!ed.importFile(write(QStringLiteral("bad-alpha.json"), badAlpha)));
  QCOMPARE(errors.count(), 2);
  QVERIFY(!ed.importFile(tmp.filePath(QStringLiteral("missing.json"))));
  QCOMPARE(errors.count(), 3);
  QVERIFY(samePoints(ed.transferFunction(), before));
  QVERIFY(!ed.editPending());
  QTest::qWait(3 * TransferFunctionEditor::editDebounceMs);
  QCOMPARE(edits.count(), 0);
  // A user preset that went bad on disk is reported the same way.
  ed.setUserPresetDir(tmp.path());
  const int index = ed.findPreset(QStringLiteral("broken (user)"));
  QVERIFY(index > 0);
  QVERIFY(!ed.applyPreset(index));
  QCOMPARE(errors.count(), 4);
}

void TestTfEditor::logScaleChangesDrawing() {
  TransferFunctionEditor ed;
  setUp(ed, makeTf({{0.0, 0.f}, {100.0, 0.f}}));
  CurveEditor* c = ed.curveEditor();
  QVERIFY(!c->logScale());
  const QImage linear = c->grab().toImage();
  QTest::mouseClick(ed.logScaleCheckBox(), Qt::LeftButton);
  QVERIFY(ed.logScaleCheckBox()->isChecked());
  QVERIFY(c->logScale());
  const QImage logImage = c->grab().toImage();
  QVERIFY(!linear.isNull());
  QCOMPARE(linear.size(), logImage.size());
  // One huge bin: on a linear scale the other bars are nearly flat, on a log scale they are tall.
  // Count the histogram-tinted pixels in a column through a small bin, half-way up.
  const int x = static_cast<int>(c->toWidget(83.0, 0.0).x());  // bin 41, off the grid
  const auto shaded = [&](const QImage& img) {
    int n = 0;
    const QRgb base = img.pixel(x, static_cast<int>(c->toWidget(83.0, 0.99).y()));
    for (double y = 0.05; y < 0.95; y += 0.01)
      if (img.pixel(x, static_cast<int>(c->toWidget(83.0, y).y())) != base) ++n;
    return n;
  };
  QVERIFY2(shaded(logImage) >= shaded(linear) + 15,
           qPrintable(QStringLiteral("%1 vs %2").arg(shaded(logImage)).arg(shaded(linear))));
}

QTEST_MAIN(TestTfEditor)
#include "test_tf_editor.moc"
