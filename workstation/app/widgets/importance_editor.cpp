#include "widgets/importance_editor.h"

#include <algorithm>
#include <limits>
#include <utility>

#include <QCheckBox>
#include <QFileDialog>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
#include <QTimer>
#include <QVBoxLayout>

#include "widgets/curve_editor.h"

namespace visopt::ws {

ImportanceEditor::ImportanceEditor(QWidget* parent) : QWidget(parent) {
  qRegisterMetaType<std::vector<glm::dvec2>>();
  loadButton_ = new QPushButton(tr("Load importance volume…"), this);
  loadButton_->setToolTip(tr("Use a volume file of importance values g(x) in [0, 1]"));
  overlay_ = new QCheckBox(tr("Show importance overlay"), this);
  overlay_->setToolTip(tr("Tint the view by the importance"));
  logScale_ = new QCheckBox(tr("Log histogram"), this);
  logScale_->setToolTip(tr("Show the histogram counts on a logarithmic scale"));
  volumeLabel_ = new QLabel(this);
  volumeLabel_->setVisible(false);
  volumeLabel_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  curve_ = new CurveEditor(this);
  curve_->setYName(tr("importance"));
  curve_->setPoints({{0.0, 1.0}, {1.0, 1.0}});

  auto* top = new QHBoxLayout;
  top->addWidget(loadButton_);
  top->addWidget(overlay_);
  top->addStretch(1);
  top->addWidget(logScale_);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addLayout(top);
  layout->addWidget(volumeLabel_);
  layout->addWidget(curve_, 1);

  debounce_ = new QTimer(this);
  debounce_->setSingleShot(true);
  debounce_->setInterval(editDebounceMs);
  connect(debounce_, &QTimer::timeout, this, [this] { emit importanceCurveEdited(curve()); });
  connect(curve_, &CurveEditor::pointsEdited, debounce_, qOverload<>(&QTimer::start));
  connect(logScale_, &QCheckBox::toggled, curve_, &CurveEditor::setLogScale);
  connect(overlay_, &QCheckBox::toggled, this, &ImportanceEditor::overlayToggled);
  connect(loadButton_, &QPushButton::clicked, this, [this] {
    const QString path = openFileDialog_
                             ? openFileDialog_()
                             : QFileDialog::getOpenFileName(this, tr("Load importance volume"));
    if (!path.isEmpty()) emit importanceVolumeRequested(path);
  });
  updateRange();
}

ImportanceEditor::~ImportanceEditor() = default;

void ImportanceEditor::setHistogram(std::shared_ptr<const Histogram> histogram) {
  histogram_ = std::move(histogram);
  curve_->setHistogram(histogram_);
  updateRange();
}

void ImportanceEditor::setCurve(const std::vector<glm::dvec2>& points) {
  debounce_->stop();
  std::vector<glm::dvec2> clamped = points;
  for (glm::dvec2& p : clamped) p.y = std::clamp(p.y, 0.0, 1.0);
  curve_->setPoints(std::move(clamped));
  updateRange();
}

std::vector<glm::dvec2> ImportanceEditor::curve() const {
  return curve_->points();
}

void ImportanceEditor::setImportanceVolumeName(const QString& name) {
  volumeName_ = name;
  volumeLabel_->setText(tr("Importance from %1; editing the curve replaces it").arg(name));
  volumeLabel_->setToolTip(name);
  volumeLabel_->setVisible(!name.isEmpty());
}

void ImportanceEditor::setOverlayChecked(bool on) {
  const QSignalBlocker block(overlay_);
  overlay_->setChecked(on);
}

bool ImportanceEditor::overlayChecked() const {
  return overlay_->isChecked();
}

bool ImportanceEditor::editPending() const {
  return debounce_->isActive();
}

void ImportanceEditor::flushPendingEdit() {
  if (!debounce_->isActive()) return;
  debounce_->stop();
  emit importanceCurveEdited(curve());
}

void ImportanceEditor::updateRange() {
  if (histogram_) return;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const glm::dvec2& p : curve_->points()) {
    lo = std::min(lo, p.x);
    hi = std::max(hi, p.x);
  }
  if (lo <= hi) curve_->setValueRange(lo, hi);
}

}  // namespace visopt::ws
