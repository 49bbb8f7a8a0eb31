// Transfer-function editor: the opacity curve and the colour stops (one CurveEditor with its
// colour strip) over the volume's histogram, a preset menu (built-in presets, the JSON files in
// resources/transfer-functions, user presets saved as JSON under the user-preset directory),
// "Save preset…", "Import ParaView JSON…" and a log-scale switch for the histogram.
//
// Edits reach the rest of the application through transferFunctionEdited, debounced: every edit
// (re)starts a single-shot timer (editDebounceMs) and only its expiry emits, with the function as
// it is then. flushPendingEdit() emits a pending edit at once. setTransferFunction never emits.
//
// Errors (unreadable preset, bad ParaView file, failed save) are emitted as errorOccurred with the
// library's message, and shown in a QMessageBox::warning only when interactive() (the default).
#pragma once

#include <functional>
#include <memory>

#include <QMetaType>
#include <QString>
#include <QWidget>

#include "visopt/transfer_function.h"
#include "widgets/histogram.h"

class QCheckBox;
class QComboBox;
class QPushButton;
class QTimer;

namespace visopt::ws {

class CurveEditor;

class TransferFunctionEditor : public QWidget {
  Q_OBJECT

 public:
  static constexpr int editDebounceMs = 60;

  explicit TransferFunctionEditor(QWidget* parent = nullptr);
  ~TransferFunctionEditor() override;

  void setHistogram(std::shared_ptr<const Histogram> histogram);
  // Shows `tf` (its points, name and unit distance are kept); does not emit, and drops an edit
  // still waiting in the debounce timer.
  void setTransferFunction(const visopt::TransferFunction& tf);
  visopt::TransferFunction transferFunction() const;

  // ---- presets ----
  // Where user presets live; defaults to QStandardPaths::AppDataLocation/transfer-functions.
  void setUserPresetDir(const QString& dir);
  QString userPresetDir() const { return userPresetDir_; }
  // Re-reads the preset lists into the combo box.
  void refreshPresets();
  // Combo entries: index 0 is a "Presets…" placeholder; entries are "NAME" (built-in),
  // "NAME (resource)" and "NAME (user)".
  QComboBox* presetCombo() const { return presetCombo_; }
  int findPreset(const QString& label) const;  // -1 when absent
  // Loads the preset at combo `index` and schedules an edit; false (and errorOccurred) on error.
  bool applyPreset(int index);
  // Saves the current function as user preset `name` (file NAME.json in userPresetDir(), name
  // sanitised); false (and errorOccurred) on error.
  bool saveUserPreset(const QString& name);
  // Loads a visopt or ParaView colour-map JSON file and schedules an edit.
  bool importFile(const QString& path);

  // Hooks for the dialogs, so tests can bypass them: an empty result means "cancelled".
  void setOpenFileDialog(std::function<QString()> dialog) { openFileDialog_ = std::move(dialog); }
  void setPresetNameDialog(std::function<QString()> dialog) {
    presetNameDialog_ = std::move(dialog);
  }
  void setInteractive(bool on) { interactive_ = on; }
  bool interactive() const { return interactive_; }

  CurveEditor* curveEditor() const { return curve_; }
  QCheckBox* logScaleCheckBox() const { return logScale_; }
  QPushButton* savePresetButton() const { return saveButton_; }
  QPushButton* importButton() const { return importButton_; }
  bool editPending() const;

 public slots:
  // Emits a pending edit now (tests, or before saving a session).
  void flushPendingEdit();

 signals:
  void transferFunctionEdited(const visopt::TransferFunction& tf);
  // A built-in preset (TransferFunction::presetNames) was applied; emitted after the edit.
  void builtinPresetApplied(const QString& name);
  void errorOccurred(const QString& message);

 private:
  void scheduleEdit();
  void reportError(const QString& message);
  void updateRange();
  void onSavePresetClicked();
  void onImportClicked();

  CurveEditor* curve_ = nullptr;
  QComboBox* presetCombo_ = nullptr;
  QCheckBox* logScale_ = nullptr;
  QPushButton* saveButton_ = nullptr;
  QPushButton* importButton_ = nullptr;
  QTimer* debounce_ = nullptr;
  std::shared_ptr<const Histogram> histogram_;
  std::string name_;
  float unitDistance_ = 0.f;
  QString userPresetDir_;
  bool interactive_ = true;
  std::function<QString()> openFileDialog_;
  std::function<QString()> presetNameDialog_;
};

}  // namespace visopt::ws

Q_DECLARE_METATYPE(visopt::TransferFunction)
