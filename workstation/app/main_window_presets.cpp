// One-step scan presets of the main window: "skin as context, bone as importance" for a CT, and
// the importance a built-in transfer-function preset is made for. The library holds what the
// presets carry (TransferFunction::presetImportance, presetContextIsovalue), so the CLI's
// `--tf preset:ct-skin-bone --context iso:-400` and this menu entry set up the same scene.
#include <visopt/context_surface.h>
#include <visopt/engine.h>
#include <visopt/error.h>
#include <visopt/transfer_function.h>

#include <QStatusBar>

#include "hotspot_mode.h"
#include "main_window.h"
#include "widgets/importance_editor.h"
#include "widgets/transfer_function_editor.h"

namespace visopt::ws {

namespace {
constexpr const char* kCtPreset = "ct-skin-bone";

// The same surface whatever the text says ("iso:-400" from an older session and
// "iso:-400:inside-high" are one); text that is no source is no match.
bool sameSource(const std::string& text, const SurfaceSource& source) {
  try {
    return SurfaceSource::parse(text) == source;
  } catch (const Error&) {
    return false;
  }
}
}  // namespace

void MainWindow::applyImportanceCurve(const std::vector<glm::dvec2>& curve,
                                      const std::string& origin) {
  importanceEditor_->setCurve(curve);
  importanceEditor_->setImportanceVolumeName({});
  hotspot_->setSceneHasImportance(true);  // the hotspot's default focus becomes the importance
  controller_->post(tr("Importance"),
                    [curve, origin](Engine& e) { e.setImportanceCurve(curve, origin); });
  setModified();
}

void MainWindow::onBuiltinPresetApplied(const QString& name) {
  const std::string preset = name.toStdString();
  const std::vector<glm::dvec2> curve = TransferFunction::presetImportance(preset);
  if (curve.empty()) return;
  const auto snap = controller_->snapshot();
  if (!snap || !snap->volume) return;
  // The engine is the authority on whether an importance exists; ask it on its thread and come
  // back here to change editor and engine together.
  controller_->post(tr("Importance"), [this, curve, preset](Engine& e) {
    if (e.hasImportance()) return;
    QMetaObject::invokeMethod(
        this,
        [this, curve, preset] {
          applyImportanceCurve(curve, "preset:" + preset);
          statusBar()->showMessage(
              tr("Importance: the bone of preset %1").arg(QString::fromStdString(preset)), 8000);
        },
        Qt::QueuedConnection);
  });
}

void MainWindow::useSkinAsContextBoneAsImportance() {
  const auto snap = controller_->snapshot();
  if (!snap || !snap->volume) {
    showError(tr("Open a CT volume first."));
    return;
  }
  const double skin = *TransferFunction::presetContextIsovalue(kCtPreset);
  const double lo = snap->volume->valueMin, hi = snap->volume->valueMax;
  // Hounsfield units put air near -1000 and the skin at about -400: data whose range does not
  // hold the skin isovalue are not a CT in HU (an MRI, or a CT stored without its rescale).
  if (!(lo < skin && skin < hi)) {
    showError(tr("\"CT: skin as context, bone as importance\" needs a CT in Hounsfield units: "
                 "this volume's values run %1 .. %2, so there is no skin at %3 HU.")
                  .arg(lo)
                  .arg(hi)
                  .arg(skin));
    return;
  }
  const int presetIndex = tfEditor_->findPreset(QString::fromLatin1(kCtPreset));
  if (presetIndex > 0 && tfEditor_->applyPreset(presetIndex)) tfEditor_->flushPendingEdit();
  applyImportanceCurve(TransferFunction::presetImportance(kCtPreset),
                       std::string("preset:") + kCtPreset);
  const SurfaceSource skinSource = SurfaceSource::iso(skin);
  const ContextSurfaceSpec spec =
      defaultContextSurfaceSpec(skinSource.format(), snap->volume->grid());
  controller_->postLong(tr("Context surface %1").arg(QString::fromStdString(spec.source)),
                        [this, spec, skinSource](Engine& e, const ProgressCallback& progress) {
                          for (const ContextSurfaceSpec& have : e.contextSurfaces())
                            if (sameSource(have.source, skinSource)) return;  // already there
                          e.addContextSurface(spec, progress);
                          controller_->refreshSnapshot(e);
                        });
  controller_->restartOptimization();
  setOptimizationRunning(true);
  setModified();
}

}  // namespace visopt::ws
