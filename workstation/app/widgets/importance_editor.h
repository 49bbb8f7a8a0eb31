// Importance editor: the importance curve g(s) (points (data value, g), g in [0, 1]) drawn over
// the histogram with the same CurveEditor (no colour strip), a "Load importance volume…" button,
// a "Show importance overlay" switch and a label naming the importance volume when the importance
// comes from one (setImportanceVolumeName; the owner clears it with an empty name when it goes
// back to the curve, e.g. after importanceCurveEdited).
//
// importanceCurveEdited is debounced like TransferFunctionEditor::transferFunctionEdited: each
// edit (re)starts a single-shot timer; flushPendingEdit() emits a pending edit at once. setCurve
// never emits. Deleting never leaves fewer than one point.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <QMetaType>
#include <QString>
#include <QWidget>
#include <glm/glm.hpp>

#include "widgets/histogram.h"

class QCheckBox;
class QLabel;
class QPushButton;
class QTimer;

namespace visopt::ws {

class CurveEditor;

class ImportanceEditor : public QWidget {
  Q_OBJECT

 public:
  static constexpr int editDebounceMs = 60;

  explicit ImportanceEditor(QWidget* parent = nullptr);
  ~ImportanceEditor() override;

  void setHistogram(std::shared_ptr<const Histogram> histogram);
  // Shows `points` (sorted by value on the way in); does not emit, drops a pending edit.
  void setCurve(const std::vector<glm::dvec2>& points);
  std::vector<glm::dvec2> curve() const;
  // "from volume NAME" under the curve; an empty name hides it.
  void setImportanceVolumeName(const QString& name);
  QString importanceVolumeName() const { return volumeName_; }
  void setOverlayChecked(bool on);  // does not emit overlayToggled
  bool overlayChecked() const;

  // Replaces the file dialog of "Load importance volume…" (empty result: cancelled).
  void setOpenFileDialog(std::function<QString()> dialog) { openFileDialog_ = std::move(dialog); }

  CurveEditor* curveEditor() const { return curve_; }
  QPushButton* loadVolumeButton() const { return loadButton_; }
  QCheckBox* overlayCheckBox() const { return overlay_; }
  QCheckBox* logScaleCheckBox() const { return logScale_; }
  QLabel* volumeLabel() const { return volumeLabel_; }
  bool editPending() const;

 public slots:
  void flushPendingEdit();

 signals:
  void importanceCurveEdited(const std::vector<glm::dvec2>& points);
  void importanceVolumeRequested(const QString& path);
  void overlayToggled(bool on);

 private:
  void updateRange();

  CurveEditor* curve_ = nullptr;
  QPushButton* loadButton_ = nullptr;
  QCheckBox* overlay_ = nullptr;
  QCheckBox* logScale_ = nullptr;
  QLabel* volumeLabel_ = nullptr;
  QTimer* debounce_ = nullptr;
  std::shared_ptr<const Histogram> histogram_;
  QString volumeName_;
  std::function<QString()> openFileDialog_;
};

}  // namespace visopt::ws

Q_DECLARE_METATYPE(std::vector<glm::dvec2>)
