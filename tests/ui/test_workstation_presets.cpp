// "CT: skin as context, bone as importance" in one step, through MainWindow: on a CT in
// Hounsfield units (builtin:ct-head's volume written to a file and opened as a user's scan) the
// action sets the ct-skin-bone transfer function, the preset's bone importance and the skin
// isosurface at -400 HU as a thin shell one voxel each side, the same scene the CLI's
// `--tf preset:ct-skin-bone --context iso:-400` builds, and starts the optimisation; a second
// use adds no second skin. On data that are not HU it reports an error and changes nothing.
// Choosing a CT transfer-function preset on a scan without importance makes bone the importance.
#include <memory>

#include <QSignalSpy>
#include <QTest>

#include <visopt/context_surface.h>
#include <visopt/engine.h>
#include <visopt/scenes.h>
#include <visopt/transfer_function.h>
#include <visopt/volume_io.h>

#include "engine_controller.h"
#include "main_window.h"
#include "widgets/transfer_function_editor.h"

using namespace visopt;
using namespace visopt::ws;

namespace {

constexpr int kLoadMs = 120000;

// A scene's volume written to a NIfTI file: what a user opens (no importance, no surfaces).
QString writeSceneVolume(const std::string& scene, const QString& name) {
  Engine e;
  e.loadBuiltinScene(scene, 40, false);
  const QString path = QStringLiteral(VISOPT_TEST_TMP "/") + name;
  writeVolume(e.volume(), path.toStdString());
  return path;
}

std::unique_ptr<MainWindow> openFile(const QString& path, const QString& state) {
  auto w = std::make_unique<MainWindow>(Precision::FP32,
                                        QStringLiteral(VISOPT_TEST_TMP "/presets-") + state);
  w->setInteractive(false);
  w->setOptimizationRunning(false);
  w->resize(800, 600);
  QSignalSpy ready(w.get(), &MainWindow::sceneReady);
  w->openVolume(path);
  if (!ready.wait(kLoadMs)) return nullptr;
  return w;
}

struct EngineState {
  std::string tfName;
  Engine::ImportanceSource importance;
  std::vector<ContextSurfaceSpec> surfaces;
  GridSpec grid;
};

EngineState stateOf(MainWindow& w) {
  QCoreApplication::processEvents();  // queued UI work (debounced edits) reaches the worker
  EngineState s;
  w.controller()->call([&](Engine& e) {
    s.tfName = e.transferFunction().name;
    s.importance = e.importanceSource();
    s.surfaces = e.contextSurfaces();
    s.grid = e.volume().grid();
  });
  return s;
}

}  // namespace

class TestWorkstationPresets : public QObject {
  Q_OBJECT
 private slots:
  void skinAsContextBoneAsImportanceOnACt();
  void skinAsContextRefusesDataThatAreNotHounsfieldUnits();
  void ctTransferFunctionPresetBringsItsImportance();
};

void TestWorkstationPresets::skinAsContextBoneAsImportanceOnACt() {
  auto w = openFile(writeSceneVolume("ct-head", "ct-head.nii"), QStringLiteral("ct"));
  QVERIFY(w);
  EngineState before = stateOf(*w);
  QCOMPARE(before.importance.kind, Engine::ImportanceSource::Kind::None);
  QVERIFY(before.surfaces.empty());

  w->useSkinAsContextBoneAsImportance();
  QTRY_VERIFY_WITH_TIMEOUT(!stateOf(*w).surfaces.empty(), kLoadMs);
  const EngineState after = stateOf(*w);
  QCOMPARE(after.tfName, std::string("ct-skin-bone"));
  QCOMPARE(after.importance.kind, Engine::ImportanceSource::Kind::Curve);
  const auto bone = TransferFunction::presetImportance("ct-skin-bone");
  QCOMPARE(after.importance.curve.size(), bone.size());
  for (size_t i = 0; i < bone.size(); ++i) QCOMPARE(after.importance.curve[i], bone[i]);
  QCOMPARE(after.surfaces.size(), size_t(1));
  const ContextSurfaceSpec cli = defaultContextSurfaceSpec("iso:-400", after.grid);
  // The same surface as the CLI's text (the window writes the canonical form).
  QVERIFY(SurfaceSource::parse(after.surfaces[0].source) == SurfaceSource::parse(cli.source));
  QCOMPARE(after.surfaces[0].filled, false);
  QCOMPARE(after.surfaces[0].shell, cli.shell);
  QVERIFY(w->optimizationPanel() != nullptr);

  // Once more: the skin is already the context surface.
  w->useSkinAsContextBoneAsImportance();
  QTest::qWait(200);
  QCOMPARE(stateOf(*w).surfaces.size(), size_t(1));
}

void TestWorkstationPresets::skinAsContextRefusesDataThatAreNotHounsfieldUnits() {
  // Shepp-Logan's densities lie in [0, 2]: no skin at -400.
  auto w = openFile(writeSceneVolume("shepp-logan", "shepp.nii"), QStringLiteral("mri"));
  QVERIFY(w);
  QSignalSpy errors(w.get(), &MainWindow::errorShown);
  w->useSkinAsContextBoneAsImportance();
  QCOMPARE(errors.count(), 1);
  QVERIFY2(errors.at(0).at(0).toString().contains(QStringLiteral("Hounsfield")),
           qPrintable(errors.at(0).at(0).toString()));
  QTest::qWait(200);
  const EngineState s = stateOf(*w);
  QVERIFY(s.surfaces.empty());
  QCOMPARE(s.importance.kind, Engine::ImportanceSource::Kind::None);
  QVERIFY(s.tfName != "ct-skin-bone");
}

void TestWorkstationPresets::ctTransferFunctionPresetBringsItsImportance() {
  auto w = openFile(writeSceneVolume("ct-head", "ct-head-tf.nii"), QStringLiteral("tf"));
  QVERIFY(w);
  TransferFunctionEditor* tf = w->transferFunctionEditor();
  const int index = tf->findPreset(QStringLiteral("ct-bone"));
  QVERIFY(index > 0);
  QVERIFY(tf->applyPreset(index));
  tf->flushPendingEdit();
  QTRY_COMPARE_WITH_TIMEOUT(stateOf(*w).importance.kind, Engine::ImportanceSource::Kind::Curve,
                            kLoadMs);
  QCOMPARE(stateOf(*w).importance.curve.size(),
           TransferFunction::presetImportance("ct-bone").size());

  // A preset without an importance (mri) leaves the bone importance alone.
  QVERIFY(tf->applyPreset(tf->findPreset(QStringLiteral("mri"))));
  tf->flushPendingEdit();
  QTest::qWait(200);
  QCOMPARE(stateOf(*w).importance.kind, Engine::ImportanceSource::Kind::Curve);
}

QTEST_MAIN(TestWorkstationPresets)
#include "test_workstation_presets.moc"
