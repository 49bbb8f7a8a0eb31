#include "panels/deviation_panel.h"

#include <algorithm>

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QPainter>
#include <QSignalBlocker>
#include <QStandardItemModel>
#include <QVBoxLayout>

#include "panels/context_surfaces_panel.h"  // displayColor

namespace visopt::ws {

namespace {

constexpr int kTicks = 5;
constexpr int kPad = 6;
constexpr int kBarHeight = 14;

QString displayName(const std::string& name) {
  QString text = QString::fromStdString(name);
  if (!text.isEmpty()) text[0] = text[0].toUpper();
  return text;
}

}  // namespace

// --- DeviationLegend ---------------------------------------------------------------------------

DeviationLegend::DeviationLegend(QWidget* parent) : QWidget(parent) {
  setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Fixed);
  setToolTip(tr("Distance of the context surfaces from their original shape."));
}

void DeviationLegend::setColormap(Colormap colormap) {
  colormap_ = colormap;
  update();
}

void DeviationLegend::setRange(double maxValue, const QString& unit) {
  maxValue_ = maxValue;
  unit_ = unit;
  update();
}

QColor DeviationLegend::colorAt(float t) const {
  return displayColor(evaluateColormap(colormap_, std::clamp(t, 0.f, 1.f)));
}

QRect DeviationLegend::barRect() const {
  const int textWidth = fontMetrics().horizontalAdvance(tickLabels().back());
  const int side = std::max(kPad, textWidth / 2 + 2);
  return QRect(side, kPad, std::max(1, width() - 2 * side), kBarHeight);
}

QStringList DeviationLegend::tickLabels() const {
  QStringList labels;
  for (int i = 0; i < kTicks; ++i) {
    const double value = maxValue_ * i / (kTicks - 1);
    labels << QString::number(value, 'g', 3);
  }
  labels.back() = QStringLiteral("≥") + labels.back() + QLatin1Char(' ') + unit_;
  return labels;
}

QSize DeviationLegend::sizeHint() const {
  return QSize(220, kPad + kBarHeight + 4 + fontMetrics().height() + kPad);
}

QSize DeviationLegend::minimumSizeHint() const {
  return QSize(120, sizeHint().height());
}

void DeviationLegend::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  const QRect bar = barRect();
  const int w = bar.width();
  for (int x = 0; x < w; ++x) {
    const float t = w > 1 ? static_cast<float>(x) / static_cast<float>(w - 1) : 0.f;
    painter.fillRect(QRect(bar.left() + x, bar.top(), 1, bar.height()), colorAt(t));
  }
  painter.setPen(palette().color(QPalette::WindowText));
  const QStringList labels = tickLabels();
  const int textTop = bar.bottom() + 4;
  for (int i = 0; i < kTicks; ++i) {
    const int x = bar.left() + (w - 1) * i / (kTicks - 1);
    painter.drawLine(x, bar.bottom() + 1, x, bar.bottom() + 3);
    const int textWidth = fontMetrics().horizontalAdvance(labels[i]);
    int left = x - textWidth / 2;
    left = std::clamp(left, 0, std::max(0, width() - textWidth));
    painter.drawText(QRect(left, textTop, textWidth, fontMetrics().height()), Qt::AlignCenter,
                     labels[i]);
  }
}

// --- DeviationPanel ----------------------------------------------------------------------------

DeviationPanel::DeviationPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;

  enabled_ = new QCheckBox(tr("Deviation view"), this);
  enabled_->setObjectName(QStringLiteral("enabled"));
  enabled_->setToolTip(
      tr("Colour the context surfaces by how far the optimisation moved them from their original "
         "shape (|φ₀| at the surface) instead of their own colour."));
  form->addRow(enabled_);

  colormap_ = new QComboBox(this);
  colormap_->setObjectName(QStringLiteral("colormap"));
  for (const std::string& name : colormapNames())
    colormap_->addItem(displayName(name), QString::fromStdString(name));
  colormap_->setToolTip(tr("The colour scale from no deviation (left) to the maximum (right)."));
  form->addRow(tr("Colormap"), colormap_);

  max_ = new QDoubleSpinBox(this);
  max_->setObjectName(QStringLiteral("maxDeviation"));
  max_->setDecimals(3);
  max_->setKeyboardTracking(false);
  max_->setToolTip(
      tr("The deviation shown with the colormap's last colour; larger deviations "
         "are clamped to it."));
  unit_ = new QComboBox(this);
  unit_->setObjectName(QStringLiteral("units"));
  unit_->addItem(tr("voxels"), static_cast<int>(DeviationUnit::Voxels));
  unit_->addItem(tr("mm"), static_cast<int>(DeviationUnit::Millimetres));
  unit_->setToolTip(tr("Show the deviation in voxels or in millimetres (world units)."));
  auto* maxRow = new QHBoxLayout;
  maxRow->addWidget(max_, 1);
  maxRow->addWidget(unit_);
  form->addRow(tr("Max deviation"), maxRow);
  layout->addLayout(form);

  legend_ = new DeviationLegend(this);
  legend_->setObjectName(QStringLiteral("legend"));
  layout->addWidget(legend_);
  layout->addStretch(1);

  setVoxelSize(0.f);
  setDeviationSettings(false, Colormap::Viridis, 10.f);

  connect(enabled_, &QCheckBox::toggled, this, &DeviationPanel::onEdited);
  connect(colormap_, &QComboBox::currentIndexChanged, this, [this](int) {
    legend_->setColormap(colormap());
    onEdited();
  });
  connect(max_, &QDoubleSpinBox::valueChanged, this, [this](double value) {
    const double voxels = unit() == DeviationUnit::Millimetres && voxelSize_ > 0.f
                              ? value / static_cast<double>(voxelSize_)
                              : value;
    maxVoxels_ = static_cast<float>(voxels);
    showMaximum();
    onEdited();
  });
  connect(unit_, &QComboBox::currentIndexChanged, this, [this](int) { showMaximum(); });
}

void DeviationPanel::setDeviationSettings(bool enabled, Colormap colormap, float maxVoxels) {
  const QSignalBlocker b0(enabled_), b1(colormap_);
  enabled_->setChecked(enabled);
  colormap_->setCurrentIndex(colormap_->findData(QString::fromLatin1(toString(colormap))));
  legend_->setColormap(colormap);
  maxVoxels_ = maxVoxels;
  showMaximum();
}

bool DeviationPanel::deviationEnabled() const {
  return enabled_->isChecked();
}

Colormap DeviationPanel::colormap() const {
  return parseColormap(colormap_->currentData().toString().toStdString());
}

void DeviationPanel::setVoxelSize(float mm) {
  voxelSize_ = mm > 0.f ? mm : 0.f;
  auto* model = qobject_cast<QStandardItemModel*>(unit_->model());
  if (model) model->item(1)->setEnabled(voxelSize_ > 0.f);
  if (voxelSize_ <= 0.f && unit() == DeviationUnit::Millimetres) setUnit(DeviationUnit::Voxels);
  showMaximum();
}

void DeviationPanel::setUnit(DeviationUnit unit) {
  if (unit == DeviationUnit::Millimetres && voxelSize_ <= 0.f) return;
  unit_->setCurrentIndex(unit_->findData(static_cast<int>(unit)));
}

DeviationUnit DeviationPanel::unit() const {
  return static_cast<DeviationUnit>(unit_->currentData().toInt());
}

void DeviationPanel::showMaximum() {
  const bool mm = unit() == DeviationUnit::Millimetres && voxelSize_ > 0.f;
  const double scale = mm ? static_cast<double>(voxelSize_) : 1.0;
  const QSignalBlocker block(max_);
  max_->setRange(0.01 * scale, 10000.0 * scale);
  max_->setSuffix(mm ? tr(" mm") : tr(" vx"));
  max_->setSingleStep(scale);
  max_->setValue(static_cast<double>(maxVoxels_) * scale);
  legend_->setRange(static_cast<double>(maxVoxels_) * scale,
                    mm ? QStringLiteral("mm") : QStringLiteral("vx"));
}

void DeviationPanel::onEdited() {
  emit deviationSettingsChanged(enabled_->isChecked(), colormap(), maxVoxels_);
}

}  // namespace visopt::ws
