// The workstation's side panels: each edit emits exactly the edited settings, reset restores the
// library's defaults, add-surface specs have the documented source strings, per-row signals carry
// their row, the deviation legend shows the colormap, and the status text is formatted as
// documented.
#include <cmath>

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QLineEdit>
#include <QPushButton>
#include <QRadioButton>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTableWidget>
#include <QTest>
#include <QToolButton>

#include "panels/comparison_view.h"
#include "panels/context_surfaces_panel.h"
#include "panels/deviation_panel.h"
#include "panels/optimization_panel.h"
#include "panels/status_summary.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

template <class T>
T* child(QWidget& parent, const char* name) {
  T* w = parent.findChild<T*>(QString::fromLatin1(name));
  if (!w) qFatal("no child %s", name);
  return w;
}

bool sameExtinction(const ExtinctionSettings& a, const ExtinctionSettings& b) {
  return a.rho == b.rho && a.q == b.q && a.r == b.r && a.muMax == b.muMax &&
         a.optimizer == b.optimizer && a.learningRate == b.learningRate && a.beta1 == b.beta1 &&
         a.beta2 == b.beta2 && a.beta3 == b.beta3 && a.alpha == b.alpha && a.epsilon == b.epsilon &&
         a.alphaWarmup == b.alphaWarmup && a.beta3Warmup == b.beta3Warmup && a.levels == b.levels &&
         a.maxIterationsPerLevel == b.maxIterationsPerLevel && a.tolerance == b.tolerance &&
         a.minIterationsPerLevel == b.minIterationsPerLevel && a.frustumScale == b.frustumScale &&
         a.depthCells == b.depthCells && a.lightGridSize == b.lightGridSize;
}

bool sameLevelSet(const LevelSetSettings& a, const LevelSetSettings& b) {
  return a.lambda == b.lambda && a.curvatureEpsilon == b.curvatureEpsilon && a.cfl == b.cfl &&
         a.substeps == b.substeps && a.redistanceIterations == b.redistanceIterations &&
         a.redistanceTolerance == b.redistanceTolerance && a.spatialOrder == b.spatialOrder &&
         a.semiImplicit == b.semiImplicit;
}

std::vector<ContextSurfaceSpec> twoSurfaces() {
  std::vector<ContextSurfaceSpec> s(2);
  s[0].source = "iso:0.5:inside-high";
  s[1].source = "mesh:/data/bunny.obj";
  s[1].filled = false;
  s[1].shell = 1.5f;
  s[1].color = glm::vec3(0.2f, 0.4f, 0.6f);
  return s;
}

}  // namespace

class TestPanels : public QObject {
  Q_OBJECT
 private slots:
  // --- OptimizationPanel ---
  void optimizationEditsEmitExactValues() {
    OptimizationPanel panel;
    ExtinctionSettings e;
    e.beta1 = 0.8f;  // not in the form: must come back unchanged
    e.muMax = 3.f;
    LevelSetSettings ls;
    ls.cfl = 0.25f;
    panel.setSettings(e, ls, Precision::FP16);
    QCOMPARE(panel.precision(), Precision::FP16);
    QSignalSpy spy(&panel, &OptimizationPanel::settingsEdited);

    child<QDoubleSpinBox>(panel, "q")->setValue(12.5);
    QCOMPARE(spy.count(), 1);
    auto last = [&] { return qvariant_cast<ExtinctionSettings>(spy.last().at(0)); };
    auto lastLs = [&] { return qvariant_cast<LevelSetSettings>(spy.last().at(1)); };
    QCOMPARE(last().q, 12.5f);
    QCOMPARE(last().beta1, 0.8f);
    QCOMPARE(last().muMax, 3.f);
    QCOMPARE(lastLs().cfl, 0.25f);

    child<QCheckBox>(panel, "rhoAuto")->setChecked(false);
    child<QDoubleSpinBox>(panel, "rho")->setValue(0.75);
    QCOMPARE(last().rho, 0.75f);
    child<QCheckBox>(panel, "rhoAuto")->setChecked(true);
    QVERIFY(last().rho < 0.f);
    child<QDoubleSpinBox>(panel, "r")->setValue(3.0);
    QCOMPARE(last().r, 3.f);
    child<QDoubleSpinBox>(panel, "lambda")->setValue(0.45);
    QCOMPARE(lastLs().lambda, 0.45f);
    child<QDoubleSpinBox>(panel, "learningRate")->setValue(0.02);
    QCOMPARE(last().learningRate, 0.02f);
    child<QComboBox>(panel, "optimizer")->setCurrentIndex(1);
    QCOMPARE(last().optimizer, OptimizerKind::Adam);
    child<QSpinBox>(panel, "levels")->setValue(4);
    QCOMPARE(last().levels, 4);
    child<QSpinBox>(panel, "iterationsPerLevel")->setValue(120);
    QCOMPARE(last().maxIterationsPerLevel, 120);
    child<QSpinBox>(panel, "redistanceIterations")->setValue(16);
    QCOMPARE(lastLs().redistanceIterations, 16);
    auto* integrator = child<QComboBox>(panel, "levelSetIntegrator");
    QVERIFY(integrator->currentText().contains(QStringLiteral("default")));
    QCOMPARE(lastLs().semiImplicit, true);
    integrator->setCurrentIndex(integrator->findData(0));
    QCOMPARE(lastLs().semiImplicit, false);
    QCOMPARE(spy.count(), 12);

    // Everything else stayed as it was; the getters agree with the signal.
    ExtinctionSettings expect = e;
    expect.q = 12.5f;
    expect.r = 3.f;
    expect.learningRate = 0.02f;
    expect.optimizer = OptimizerKind::Adam;
    expect.levels = 4;
    expect.maxIterationsPerLevel = 120;
    QVERIFY(sameExtinction(last(), expect));
    QVERIFY(sameExtinction(panel.extinctionSettings(), expect));
    LevelSetSettings expectLs = ls;
    expectLs.lambda = 0.45f;
    expectLs.redistanceIterations = 16;
    expectLs.semiImplicit = false;
    QVERIFY(sameLevelSet(lastLs(), expectLs));
    QVERIFY(sameLevelSet(panel.levelSetSettings(), expectLs));

    // setSettings emits nothing.
    panel.setSettings(ExtinctionSettings{}, LevelSetSettings{}, Precision::FP32);
    QCOMPARE(spy.count(), 12);
  }

  void optimizationResetRestoresDefaults() {
    OptimizationPanel panel;
    ExtinctionSettings e;
    e.q = 7.f;
    e.rho = 2.f;
    e.levels = 1;
    e.tolerance = 0.5f;
    LevelSetSettings ls;
    ls.lambda = 0.9f;
    ls.substeps = 9;
    panel.setSettings(e, ls, Precision::FP16);
    QSignalSpy spy(&panel, &OptimizationPanel::settingsEdited);
    QTest::mouseClick(child<QPushButton>(panel, "reset"), Qt::LeftButton);
    QCOMPARE(spy.count(), 1);
    QVERIFY(
        sameExtinction(qvariant_cast<ExtinctionSettings>(spy.last().at(0)), ExtinctionSettings{}));
    QVERIFY(sameLevelSet(qvariant_cast<LevelSetSettings>(spy.last().at(1)), LevelSetSettings{}));
    QVERIFY(sameExtinction(panel.extinctionSettings(), ExtinctionSettings{}));
    QVERIFY(sameLevelSet(panel.levelSetSettings(), LevelSetSettings{}));
    QVERIFY(child<QCheckBox>(panel, "rhoAuto")->isChecked());  // default rho < 0
    QCOMPARE(child<QDoubleSpinBox>(panel, "q")->value(),
             static_cast<double>(ExtinctionSettings{}.q));
    QCOMPARE(panel.precision(), Precision::FP16);  // needs a reload: left alone
    // Editing one field after the reset still yields defaults elsewhere (the form round-trips).
    child<QSpinBox>(panel, "levels")->setValue(5);
    ExtinctionSettings expect;
    expect.levels = 5;
    QVERIFY(sameExtinction(panel.extinctionSettings(), expect));
    QVERIFY(sameLevelSet(panel.levelSetSettings(), LevelSetSettings{}));
  }

  void optimizationPrecisionAndButtons() {
    OptimizationPanel panel;
    panel.setSettings(ExtinctionSettings{}, LevelSetSettings{}, Precision::FP32);
    QSignalSpy precision(&panel, &OptimizationPanel::precisionChangeRequested);
    QSignalSpy edited(&panel, &OptimizationPanel::settingsEdited);
    auto* box = child<QComboBox>(panel, "precision");
    box->setCurrentIndex(box->findText(QStringLiteral("fp16")));
    QCOMPARE(precision.count(), 1);
    QCOMPARE(qvariant_cast<Precision>(precision.last().at(0)), Precision::FP16);
    QCOMPARE(edited.count(), 0);

    QSignalSpy run(&panel, &OptimizationPanel::runToggled);
    QSignalSpy freeze(&panel, &OptimizationPanel::freezeToggled);
    QSignalSpy restart(&panel, &OptimizationPanel::restartRequested);
    auto* runButton = child<QPushButton>(panel, "run");
    QTest::mouseClick(runButton, Qt::LeftButton);
    QCOMPARE(run.count(), 1);
    QCOMPARE(run.last().at(0).toBool(), true);
    QVERIFY(panel.isRunning());
    QVERIFY(runButton->text().contains(QStringLiteral("Pause")));
    panel.setRunning(false);  // from the engine: no signal
    QCOMPARE(run.count(), 1);
    QVERIFY(!panel.isRunning());
    QVERIFY(runButton->text().contains(QStringLiteral("Run")));
    QTest::mouseClick(child<QPushButton>(panel, "freeze"), Qt::LeftButton);
    QCOMPARE(freeze.count(), 1);
    QCOMPARE(freeze.last().at(0).toBool(), true);
    QTest::mouseClick(child<QPushButton>(panel, "restart"), Qt::LeftButton);
    QCOMPARE(restart.count(), 1);

    // Every field has a tooltip.
    for (const char* name :
         {"rho", "rhoAuto", "q", "r", "lambda", "learningRate", "optimizer", "levels",
          "iterationsPerLevel", "redistanceIterations", "levelSetIntegrator", "precision", "reset",
          "run", "freeze", "restart"})
      QVERIFY2(!child<QWidget>(panel, name)->toolTip().isEmpty(), name);
  }

  // --- Context surfaces ---
  void surfaceSpecStrings() {
    SurfaceSourceFields f;
    f.kind = SurfaceSourceFields::Kind::Iso;
    f.isoValue = 0.35;
    f.insideHigh = true;
    ContextSurfaceSpec s = makeSurfaceSpec(f);
    QCOMPARE(QString::fromStdString(s.source), QStringLiteral("iso:0.35:inside-high"));
    QVERIFY(s.filled);
    QCOMPARE(s.shell, 0.f);

    f.isoValue = -120.0;
    f.insideHigh = false;
    f.filled = false;
    f.shell = 2.5;
    s = makeSurfaceSpec(f);
    QCOMPARE(QString::fromStdString(s.source), QStringLiteral("iso:-120:inside-low"));
    QVERIFY(!s.filled);
    QCOMPARE(s.shell, 2.5f);

    f.kind = SurfaceSourceFields::Kind::Mesh;
    f.file = QStringLiteral("/data/meshes/bunny.obj");
    f.filled = true;
    s = makeSurfaceSpec(f);
    QCOMPARE(QString::fromStdString(s.source), QStringLiteral("mesh:/data/meshes/bunny.obj"));
    QVERIFY(s.filled);
    QCOMPARE(s.shell, 0.f);

    f.kind = SurfaceSourceFields::Kind::Vdb;
    f.file = QStringLiteral("/data/sdf/vessel.vdb");
    f.filled = false;
    f.shell = 0.75;
    s = makeSurfaceSpec(f);
    QCOMPARE(QString::fromStdString(s.source), QStringLiteral("vdb:/data/sdf/vessel.vdb"));
    QVERIFY(!s.filled);
    QCOMPARE(s.shell, 0.75f);

    // Invalid fields.
    f.file.clear();
    QVERIFY(!validateSurfaceFields(f).isEmpty());
    f.file = QStringLiteral("a.vdb");
    f.shell = 0.0;
    QVERIFY(!validateSurfaceFields(f).isEmpty());
    f.filled = true;
    QVERIFY(validateSurfaceFields(f).isEmpty());
  }

  void addDialogWidgetsBuildSpec() {
    AddSurfaceDialog dialog;
    dialog.setValueRange(0.0, 200.0);
    dialog.setKind(SurfaceSourceFields::Kind::Iso);
    child<QDoubleSpinBox>(dialog, "isoValue")->setValue(42.5);
    child<QComboBox>(dialog, "side")->setCurrentIndex(1);
    child<QRadioButton>(dialog, "shell")->setChecked(true);
    child<QDoubleSpinBox>(dialog, "thickness")->setValue(3.0);
    QVERIFY(dialog.isValid());
    ContextSurfaceSpec s = dialog.spec();
    QCOMPARE(QString::fromStdString(s.source), QStringLiteral("iso:42.5:inside-low"));
    QVERIFY(!s.filled);
    QCOMPARE(s.shell, 3.f);
    // The slider follows the value; moving it changes the value within the range.
    auto* slider = child<QSlider>(dialog, "isoSlider");
    QCOMPARE(slider->value(), 213);  // 42.5 / 200 of 1000 steps, rounded
    slider->setValue(slider->maximum());
    QCOMPARE(dialog.fields().isoValue, 200.0);

    dialog.setKind(SurfaceSourceFields::Kind::Mesh);
    QVERIFY(!dialog.isValid());  // no file yet
    child<QLineEdit>(dialog, "file")->setText(QStringLiteral("/tmp/part.stl"));
    child<QRadioButton>(dialog, "filled")->setChecked(true);
    QVERIFY(dialog.isValid());
    s = dialog.spec();
    QCOMPARE(QString::fromStdString(s.source), QStringLiteral("mesh:/tmp/part.stl"));
    QVERIFY(s.filled);
    QCOMPARE(s.shell, 0.f);
  }

  void panelAddThroughRunner() {
    ContextSurfacesPanel panel;
    panel.setValueRange(-1.0, 1.0);
    QSignalSpy spy(&panel, &ContextSurfacesPanel::addSurfaceRequested);
    double offeredValue = 99.0;
    panel.setDialogRunner([&](AddSurfaceDialog& dialog) {
      offeredValue = dialog.fields().isoValue;
      SurfaceSourceFields f = dialog.fields();
      QTest::qVerify(f.kind == SurfaceSourceFields::Kind::Vdb, "kind", "", __FILE__, __LINE__);
      f.file = QStringLiteral("/x/y.vdb");
      dialog.setFields(f);
      return true;
    });
    panel.requestAdd(SurfaceSourceFields::Kind::Vdb);
    QCOMPARE(spy.count(), 1);
    const auto spec = qvariant_cast<ContextSurfaceSpec>(spy.last().at(0));
    QCOMPARE(QString::fromStdString(spec.source), QStringLiteral("vdb:/x/y.vdb"));
    QCOMPARE(offeredValue, 0.0);  // the middle of the range
    // Cancelled: nothing.
    panel.setDialogRunner([](AddSurfaceDialog&) { return false; });
    panel.requestAdd(SurfaceSourceFields::Kind::Iso);
    QCOMPARE(spy.count(), 1);
  }

  void surfaceRowsCarryTheirRow() {
    ContextSurfacesPanel panel;
    panel.setSurfaces(twoSurfaces());
    QCOMPARE(panel.rowCount(), 2);
    QCOMPARE(panel.table()->item(1, 3)->text(), QStringLiteral("shell ±1.5 mm"));
    QCOMPARE(panel.table()->item(0, 3)->text(), QStringLiteral("filled"));
    QCOMPARE(panel.table()->item(1, 0)->text(), QStringLiteral("mesh: bunny.obj"));
    QCOMPARE(panel.table()->item(0, 0)->text(), QStringLiteral("iso 0.5 (inside high)"));

    QSignalSpy visibility(&panel, &ContextSurfacesPanel::visibilityChanged);
    QSignalSpy color(&panel, &ContextSurfacesPanel::colorChanged);
    QSignalSpy remove(&panel, &ContextSurfacesPanel::removeSurfaceRequested);

    panel.visibilityBox(1)->setChecked(false);
    QCOMPARE(visibility.count(), 1);
    QCOMPARE(visibility.last().at(0).toInt(), 1);
    QCOMPARE(visibility.last().at(1).toBool(), false);
    QVERIFY(!panel.surfaces()[1].visible);
    QVERIFY(panel.surfaces()[0].visible);

    QColor offered;
    const QColor picked = QColor::fromRgb(255, 128, 0);
    panel.setColorPicker([&](const QColor& initial, QWidget*) -> std::optional<QColor> {
      offered = initial;
      return picked;
    });
    QTest::mouseClick(panel.colorButton(1), Qt::LeftButton);
    QCOMPARE(color.count(), 1);
    QCOMPARE(color.last().at(0).toInt(), 1);
    const glm::vec3 c = qvariant_cast<glm::vec3>(color.last().at(1));
    const glm::vec3 expect = linearColor(picked);
    QVERIFY(std::fabs(c.r - 1.f) < 1e-5f && std::fabs(c.b) < 1e-6f);
    QVERIFY(std::fabs(c.g - expect.g) < 1e-6f && c.g > 0.2f && c.g < 0.23f);  // sRGB 128 -> 0.216
    QCOMPARE(offered, displayColor(glm::vec3(0.2f, 0.4f, 0.6f)));
    QVERIFY(std::fabs(panel.surfaces()[1].color.g - expect.g) < 1e-6f);
    // A cancelled picker emits nothing.
    panel.setColorPicker([](const QColor&, QWidget*) { return std::optional<QColor>(); });
    panel.pickColor(0);
    QCOMPARE(color.count(), 1);

    panel.table()->selectRow(1);
    QTest::mouseClick(child<QPushButton>(panel, "remove"), Qt::LeftButton);
    QCOMPARE(remove.count(), 1);
    QCOMPARE(remove.last().at(0).toInt(), 1);

    // Refreshing from the engine emits nothing.
    panel.setSurfaces(twoSurfaces());
    QCOMPARE(visibility.count(), 1);
    QVERIFY(panel.visibilityBox(1)->isChecked());
    panel.setSurfaces({});
    QCOMPARE(panel.rowCount(), 0);
  }

  void colorRoundTrip() {
    for (float v : {0.f, 0.001f, 0.2f, 0.5f, 1.f}) {
      const glm::vec3 back = linearColor(displayColor(glm::vec3(v)));
      QVERIFY(std::fabs(back.r - v) < 1e-3f);
    }
  }

  // --- Deviation ---
  void deviationPanelSignals() {
    DeviationPanel panel;
    panel.setDeviationSettings(false, Colormap::Viridis, 10.f);
    QSignalSpy spy(&panel, &DeviationPanel::deviationSettingsChanged);
    child<QCheckBox>(panel, "enabled")->setChecked(true);
    QCOMPARE(spy.count(), 1);
    QCOMPARE(spy.last().at(0).toBool(), true);
    QCOMPARE(qvariant_cast<Colormap>(spy.last().at(1)), Colormap::Viridis);
    QCOMPARE(spy.last().at(2).toFloat(), 10.f);

    auto* maps = child<QComboBox>(panel, "colormap");
    QCOMPARE(maps->count(), static_cast<int>(colormapNames().size()));
    maps->setCurrentIndex(maps->findData(QStringLiteral("magma")));
    QCOMPARE(qvariant_cast<Colormap>(spy.last().at(1)), Colormap::Magma);
    QCOMPARE(panel.legend()->colormap(), Colormap::Magma);

    auto* max = child<QDoubleSpinBox>(panel, "maxDeviation");
    max->setValue(5.0);
    QCOMPARE(spy.last().at(2).toFloat(), 5.f);

    // Millimetres: unavailable without a voxel size, then the value shows scaled.
    panel.setUnit(DeviationUnit::Millimetres);
    QCOMPARE(panel.unit(), DeviationUnit::Voxels);
    panel.setVoxelSize(0.5f);
    const qsizetype before = spy.count();
    panel.setUnit(DeviationUnit::Millimetres);
    QCOMPARE(panel.unit(), DeviationUnit::Millimetres);
    QCOMPARE(spy.count(), before);  // the setting did not change
    QCOMPARE(max->value(), 2.5);
    QVERIFY(max->suffix().contains(QStringLiteral("mm")));
    QCOMPARE(panel.legend()->unit(), QStringLiteral("mm"));
    QCOMPARE(panel.legend()->maxValue(), 2.5);
    max->setValue(2.0);  // 2 mm at 0.5 mm per voxel
    QCOMPARE(spy.last().at(2).toFloat(), 4.f);
    QCOMPARE(panel.maxVoxels(), 4.f);
    QCOMPARE(panel.legend()->tickLabels().back(), QStringLiteral("≥2 mm"));
    panel.setUnit(DeviationUnit::Voxels);
    QCOMPARE(max->value(), 4.0);
    QCOMPARE(panel.legend()->tickLabels(),
             QStringList({"0", "1", "2", "3", QStringLiteral("≥4 vx")}));

    // setDeviationSettings emits nothing.
    const qsizetype count = spy.count();
    panel.setDeviationSettings(true, Colormap::Grey, 7.f);
    QCOMPARE(spy.count(), count);
    QCOMPARE(panel.colormap(), Colormap::Grey);
    QCOMPARE(max->value(), 7.0);
  }

  void legendEndsMatchColormap() {
    for (Colormap map : {Colormap::Viridis, Colormap::Magma, Colormap::Inferno, Colormap::CoolWarm,
                         Colormap::Grey}) {
      DeviationLegend legend;
      legend.resize(240, legend.sizeHint().height());
      legend.setColormap(map);
      QCOMPARE(legend.colorAt(0.f), displayColor(evaluateColormap(map, 0.f)));
      QCOMPARE(legend.colorAt(1.f), displayColor(evaluateColormap(map, 1.f)));
      // And as painted: the bar's first and last columns.
      const QImage image = legend.grab().toImage();
      const QRect bar = legend.barRect();
      const int y = bar.center().y();
      auto near = [](QColor a, QColor b) {
        return std::abs(a.red() - b.red()) <= 1 && std::abs(a.green() - b.green()) <= 1 &&
               std::abs(a.blue() - b.blue()) <= 1;
      };
      QVERIFY(near(image.pixelColor(bar.left(), y), displayColor(evaluateColormap(map, 0.f))));
      QVERIFY(near(image.pixelColor(bar.right(), y), displayColor(evaluateColormap(map, 1.f))));
    }
  }

  // --- Comparison view ---
  void comparisonGridKeepsAspect() {
    QCOMPARE(comparisonGridShape(4), QSize(2, 2));
    QCOMPARE(comparisonGridShape(2), QSize(2, 1));
    QCOMPARE(comparisonGridShape(3), QSize(3, 1));
    QCOMPARE(comparisonGridShape(5), QSize(3, 2));
    QCOMPARE(fitKeepingAspect(QSize(200, 100), QRect(0, 0, 100, 100)), QRect(0, 25, 100, 50));

    ComparisonView view;
    view.resize(600, 500);
    std::vector<std::pair<QString, QImage>> images;
    for (const char* label : {"Ours", "MIP", "Cut-away", "Transparency"}) {
      QImage image(320, 160, QImage::Format_RGB32);
      image.fill(Qt::red);
      images.emplace_back(QString::fromLatin1(label), image);
    }
    view.setImages(images);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    const QRect r0 = view.imageRect(0), r1 = view.imageRect(1), r2 = view.imageRect(2),
                r3 = view.imageRect(3);
    QVERIFY(!r0.isEmpty());
    QVERIFY(std::abs(r0.width() - 2 * r0.height()) <= 2);
    QVERIFY(r1.left() > r0.right() && r1.top() == r0.top());    // 2x2: right of the first
    QVERIFY(r2.top() > r0.bottom() && r2.left() == r0.left());  // below the first
    QVERIFY(r3.left() == r1.left() && r3.top() == r2.top());
    QVERIFY(view.rect().contains(r3));
    QVERIFY(view.imageRect(4).isEmpty());

    const QImage composite = view.composite();
    QVERIFY(composite.width() >= 2 * 320 && composite.height() >= 2 * 160);

    QSignalSpy save(&view, &ComparisonView::saveRequested);
    auto* saveButton = child<QPushButton>(view, "save");
    auto* busy = child<QWidget>(view, "busy");
    view.setBusy(true);
    QVERIFY(busy->isVisible());
    QVERIFY(!saveButton->isEnabled());
    view.setBusy(false);
    QVERIFY(!busy->isVisible());
    QTest::mouseClick(saveButton, Qt::LeftButton);
    QCOMPARE(save.count(), 1);
    view.setImages({});
    QVERIFY(!saveButton->isEnabled());
  }

  // --- Status ---
  void statusText() {
    IterationStats s;
    s.level = 2;
    s.iteration = 35;
    s.energyRho = 2.0e5;
    s.energyQ = -1.25e6;
    s.visibilityView = 0.6412;
    const QString text = formatStatus(&s, 12.34, 410'000'000, false, true);
    QCOMPARE(text, QString::fromUtf8("level 2 · it 35 · E −1.05e6 · V 0.64 · 12.3 fps · 410 MB · "
                                     "running"));
    QCOMPARE(formatStatus(nullptr, 0.0, 1'234'000'000, true, true),
             QString::fromUtf8("1.23 GB · frozen"));
    QCOMPARE(formatStatus(nullptr, 30.0, 0, false, false),
             QString::fromUtf8("30.0 fps · 0 MB · paused"));
    QCOMPARE(formatSignificant(0.0), QStringLiteral("0"));
    QCOMPARE(formatSignificant(12.345), QStringLiteral("12.3"));
    QCOMPARE(formatSignificant(-0.5), QString::fromUtf8("−0.500"));
    QCOMPARE(formatSignificant(9.996e6), QStringLiteral("1.00e7"));
    QCOMPARE(formatSignificant(3.2e-4), QString::fromUtf8("3.20e−4"));
  }
};

QTEST_MAIN(TestPanels)
#include "test_panels.moc"
