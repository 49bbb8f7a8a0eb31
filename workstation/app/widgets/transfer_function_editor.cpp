#include "widgets/transfer_function_editor.h"

#include <algorithm>
#include <exception>
#include <limits>
#include <utility>
#include <vector>

#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QInputDialog>
#include <QMessageBox>
#include <QPushButton>
#include <QStandardPaths>
#include <QTimer>
#include <QVBoxLayout>

#include "widgets/curve_editor.h"

namespace visopt::ws {

namespace {

constexpr int kKindRole = Qt::UserRole;
constexpr int kKeyRole = Qt::UserRole + 1;
const QString kBuiltin = QStringLiteral("builtin");
const QString kResource = QStringLiteral("resource");
const QString kUser = QStringLiteral("user");

// A preset name made safe as a file name: letters, digits, '-', '_', '.', ' ' survive.
QString fileStemFor(const QString& name) {
  QString out;
  for (QChar c : name.trimmed()) {
    const bool ok = c.isLetterOrNumber() || c == u'-' || c == u'_' || c == u' ' || c == u'.';
    out += ok ? c : QChar(u'_');
  }
  while (out.startsWith(u'.')) out.remove(0, 1);
  return out;
}

QStringList jsonFilesIn(const QString& dir) {
  const QDir d(dir);
  if (!d.exists()) return {};
  return d.entryList({QStringLiteral("*.json")}, QDir::Files | QDir::Readable, QDir::Name);
}

}  // namespace

TransferFunctionEditor::TransferFunctionEditor(QWidget* parent) : QWidget(parent) {
  qRegisterMetaType<visopt::TransferFunction>();
  userPresetDir_ = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) +
                   QStringLiteral("/transfer-functions");

  presetCombo_ = new QComboBox(this);
  presetCombo_->setToolTip(tr("Load a preset transfer function"));
  saveButton_ = new QPushButton(tr("Save preset…"), this);
  saveButton_->setToolTip(tr("Save the current transfer function as a user preset"));
  importButton_ = new QPushButton(tr("Import ParaView JSON…"), this);
  importButton_->setToolTip(tr("Load a ParaView colour map (.json) or a visopt transfer function"));
  logScale_ = new QCheckBox(tr("Log histogram"), this);
  logScale_->setToolTip(tr("Show the histogram counts on a logarithmic scale"));
  curve_ = new CurveEditor(this);
  curve_->setColorStripEnabled(true);
  curve_->setYName(tr("opacity"));
  curve_->setToolTip(QString());

  // Two short rows, so the dock stays narrow and the viewport keeps the width.
  presetCombo_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  presetCombo_->setMinimumContentsLength(12);
  auto* top = new QHBoxLayout;
  top->addWidget(presetCombo_, 1);
  top->addWidget(logScale_);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(saveButton_);
  buttons->addWidget(importButton_);
  buttons->addStretch(1);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addLayout(top);
  layout->addLayout(buttons);
  layout->addWidget(curve_, 1);

  debounce_ = new QTimer(this);
  debounce_->setSingleShot(true);
  debounce_->setInterval(editDebounceMs);
  connect(debounce_, &QTimer::timeout, this,
          [this] { emit transferFunctionEdited(transferFunction()); });
  connect(curve_, &CurveEditor::pointsEdited, this, &TransferFunctionEditor::scheduleEdit);
  connect(curve_, &CurveEditor::colorStopsEdited, this, &TransferFunctionEditor::scheduleEdit);
  connect(logScale_, &QCheckBox::toggled, curve_, &CurveEditor::setLogScale);
  connect(presetCombo_, &QComboBox::activated, this, [this](int index) {
    if (index > 0) applyPreset(index);
  });
  connect(saveButton_, &QPushButton::clicked, this, &TransferFunctionEditor::onSavePresetClicked);
  connect(importButton_, &QPushButton::clicked, this, &TransferFunctionEditor::onImportClicked);

  setTransferFunction(visopt::TransferFunction::preset("generic", 0.0, 1.0));
  refreshPresets();
}

TransferFunctionEditor::~TransferFunctionEditor() = default;

void TransferFunctionEditor::setHistogram(std::shared_ptr<const Histogram> histogram) {
  histogram_ = std::move(histogram);
  curve_->setHistogram(histogram_);
  updateRange();
}

void TransferFunctionEditor::setTransferFunction(const visopt::TransferFunction& tf) {
  debounce_->stop();
  name_ = tf.name;
  unitDistance_ = tf.unitDistance;
  std::vector<glm::dvec2> points;
  points.reserve(tf.opacity.size());
  for (const OpacityPoint& p : tf.opacity)
    points.emplace_back(p.value, static_cast<double>(p.opacity));
  std::vector<ColorStop> stops;
  stops.reserve(tf.color.size());
  for (const ColorPoint& c : tf.color) stops.push_back({c.value, c.rgb});
  curve_->setPoints(std::move(points));
  curve_->setColorStops(std::move(stops));
  updateRange();
}

visopt::TransferFunction TransferFunctionEditor::transferFunction() const {
  visopt::TransferFunction tf;
  tf.name = name_;
  tf.unitDistance = unitDistance_;
  for (const glm::dvec2& p : curve_->points()) tf.opacity.push_back({p.x, static_cast<float>(p.y)});
  for (const ColorStop& s : curve_->colorStops()) tf.color.push_back({s.value, s.rgb});
  return tf;
}

void TransferFunctionEditor::updateRange() {
  if (histogram_) return;  // the histogram's range (set by CurveEditor::setHistogram)
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const glm::dvec2& p : curve_->points()) {
    lo = std::min(lo, p.x);
    hi = std::max(hi, p.x);
  }
  for (const ColorStop& s : curve_->colorStops()) {
    lo = std::min(lo, s.value);
    hi = std::max(hi, s.value);
  }
  if (lo <= hi) curve_->setValueRange(lo, hi);
}

bool TransferFunctionEditor::editPending() const {
  return debounce_->isActive();
}

void TransferFunctionEditor::scheduleEdit() {
  debounce_->start();
}

void TransferFunctionEditor::flushPendingEdit() {
  if (!debounce_->isActive()) return;
  debounce_->stop();
  emit transferFunctionEdited(transferFunction());
}

void TransferFunctionEditor::reportError(const QString& message) {
  emit errorOccurred(message);
  if (interactive_) QMessageBox::warning(this, tr("Transfer function"), message);
}

// ---- presets ----

void TransferFunctionEditor::setUserPresetDir(const QString& dir) {
  userPresetDir_ = dir;
  refreshPresets();
}

void TransferFunctionEditor::refreshPresets() {
  const QString current = presetCombo_->currentText();
  presetCombo_->clear();
  presetCombo_->addItem(tr("Presets…"));
  std::vector<std::string> builtins = visopt::TransferFunction::presetNames();
  for (const std::string& name : builtins) {
    const QString n = QString::fromStdString(name);
    presetCombo_->addItem(n);
    presetCombo_->setItemData(presetCombo_->count() - 1, kBuiltin, kKindRole);
    presetCombo_->setItemData(presetCombo_->count() - 1, n, kKeyRole);
  }
  // Resource files with a built-in's name are that built-in's source: listed once, as built-in.
  const QString resourceDir = QStringLiteral(VISOPT_RESOURCE_DIR "/transfer-functions");
  for (const QString& file : jsonFilesIn(resourceDir)) {
    const QString stem = QFileInfo(file).completeBaseName();
    if (std::find(builtins.begin(), builtins.end(), stem.toStdString()) != builtins.end()) continue;
    presetCombo_->addItem(tr("%1 (resource)").arg(stem));
    presetCombo_->setItemData(presetCombo_->count() - 1, kResource, kKindRole);
    presetCombo_->setItemData(presetCombo_->count() - 1, resourceDir + u'/' + file, kKeyRole);
  }
  for (const QString& file : jsonFilesIn(userPresetDir_)) {
    presetCombo_->addItem(tr("%1 (user)").arg(QFileInfo(file).completeBaseName()));
    presetCombo_->setItemData(presetCombo_->count() - 1, kUser, kKindRole);
    presetCombo_->setItemData(presetCombo_->count() - 1, userPresetDir_ + u'/' + file, kKeyRole);
  }
  const int keep = presetCombo_->findText(current);
  presetCombo_->setCurrentIndex(keep > 0 ? keep : 0);
}

int TransferFunctionEditor::findPreset(const QString& label) const {
  const int i = presetCombo_->findText(label);
  return i > 0 ? i : -1;
}

bool TransferFunctionEditor::applyPreset(int index) {
  if (index <= 0 || index >= presetCombo_->count()) return false;
  const QString kind = presetCombo_->itemData(index, kKindRole).toString();
  const QString key = presetCombo_->itemData(index, kKeyRole).toString();
  try {
    visopt::TransferFunction tf;
    if (kind == kBuiltin) {
      const double lo = histogram_ ? histogram_->valueMin : curve_->valueMin();
      const double hi = histogram_ ? histogram_->valueMax : curve_->valueMax();
      tf = visopt::TransferFunction::preset(key.toStdString(), lo, hi);
    } else {
      tf = visopt::TransferFunction::load(key.toStdString());
      tf.validate(key.toStdString());
    }
    setTransferFunction(tf);
  } catch (const std::exception& e) {
    reportError(QString::fromStdString(e.what()));
    return false;
  }
  presetCombo_->setCurrentIndex(index);
  scheduleEdit();
  if (kind == kBuiltin) emit builtinPresetApplied(key);
  return true;
}

bool TransferFunctionEditor::saveUserPreset(const QString& name) {
  const QString stem = fileStemFor(name);
  if (stem.isEmpty()) {
    reportError(tr("A preset needs a name."));
    return false;
  }
  if (!QDir().mkpath(userPresetDir_)) {
    reportError(tr("%1: cannot create the preset folder").arg(userPresetDir_));
    return false;
  }
  const QString path = userPresetDir_ + u'/' + stem + QStringLiteral(".json");
  try {
    visopt::TransferFunction tf = transferFunction();
    tf.name = name.trimmed().toStdString();
    tf.validate(path.toStdString());
    tf.save(path.toStdString());
    name_ = tf.name;
  } catch (const std::exception& e) {
    reportError(QString::fromStdString(e.what()));
    return false;
  }
  refreshPresets();
  const int i = findPreset(tr("%1 (user)").arg(stem));
  if (i > 0) presetCombo_->setCurrentIndex(i);
  return true;
}

bool TransferFunctionEditor::importFile(const QString& path) {
  try {
    visopt::TransferFunction tf = visopt::TransferFunction::load(path.toStdString());
    tf.validate(path.toStdString());
    setTransferFunction(tf);
  } catch (const std::exception& e) {
    reportError(QString::fromStdString(e.what()));
    return false;
  }
  presetCombo_->setCurrentIndex(0);
  scheduleEdit();
  return true;
}

void TransferFunctionEditor::onSavePresetClicked() {
  QString name;
  if (presetNameDialog_) {
    name = presetNameDialog_();
  } else {
    bool ok = false;
    name = QInputDialog::getText(this, tr("Save preset"), tr("Preset name:"), QLineEdit::Normal,
                                 QString::fromStdString(name_), &ok);
    if (!ok) return;
  }
  if (name.trimmed().isEmpty()) return;
  const QString file = userPresetDir_ + u'/' + fileStemFor(name) + QStringLiteral(".json");
  if (interactive_ && QFileInfo::exists(file) &&
      QMessageBox::question(this, tr("Save preset"),
                            tr("A preset named \"%1\" exists. Replace it?").arg(name)) !=
          QMessageBox::Yes)
    return;
  saveUserPreset(name);
}

void TransferFunctionEditor::onImportClicked() {
  const QString path = openFileDialog_
                           ? openFileDialog_()
                           : QFileDialog::getOpenFileName(this, tr("Import transfer function"),
                                                          QString(), tr("JSON (*.json);;All (*)"));
  if (!path.isEmpty()) importFile(path);
}

}  // namespace visopt::ws
