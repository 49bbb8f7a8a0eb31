#include "panels/context_surfaces_panel.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QPainter>
#include <QPixmap>
#include <QPushButton>
#include <QRadioButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QStackedWidget>
#include <QTableWidget>
#include <QToolButton>
#include <QVBoxLayout>

#include <visopt/error.h>

namespace visopt::ws {

namespace {

constexpr int kSliderSteps = 1000;
enum Column { kSource = 0, kVisible = 1, kColor = 2, kRepresentation = 3, kColumns = 4 };

float encodeSrgb(float linear) {
  const float c = std::clamp(linear, 0.f, 1.f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
}

float decodeSrgb(float encoded) {
  const float c = std::clamp(encoded, 0.f, 1.f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Decimals for a spin box over a range of this width: about five significant digits.
int decimalsFor(double range) {
  if (!(range > 0.0)) return 4;
  return std::clamp(4 - static_cast<int>(std::floor(std::log10(range))), 0, 8);
}

QIcon swatch(const glm::vec3& linear) {
  QPixmap pixmap(28, 16);
  pixmap.fill(displayColor(linear));
  QPainter painter(&pixmap);
  painter.setPen(Qt::black);
  painter.drawRect(pixmap.rect().adjusted(0, 0, -1, -1));
  return QIcon(pixmap);
}

}  // namespace

QColor displayColor(const glm::vec3& linear) {
  return QColor::fromRgbF(encodeSrgb(linear.r), encodeSrgb(linear.g), encodeSrgb(linear.b));
}

glm::vec3 linearColor(const QColor& display) {
  return {decodeSrgb(display.redF()), decodeSrgb(display.greenF()), decodeSrgb(display.blueF())};
}

QString validateSurfaceFields(const SurfaceSourceFields& fields) {
  if (fields.kind != SurfaceSourceFields::Kind::Iso && fields.file.trimmed().isEmpty())
    return QObject::tr("Choose a file.");
  if (fields.kind == SurfaceSourceFields::Kind::Iso && !std::isfinite(fields.isoValue))
    return QObject::tr("The isovalue is not a number.");
  if (!fields.filled && !(fields.shell > 0.0))
    return QObject::tr("A thin shell needs a positive thickness.");
  return {};
}

ContextSurfaceSpec makeSurfaceSpec(const SurfaceSourceFields& fields) {
  ContextSurfaceSpec spec;
  switch (fields.kind) {
    case SurfaceSourceFields::Kind::Iso:
      spec.source = SurfaceSource::iso(fields.isoValue, fields.insideHigh).format();
      break;
    case SurfaceSourceFields::Kind::Mesh:
      spec.source = SurfaceSource::mesh(fields.file.trimmed().toStdString()).format();
      break;
    case SurfaceSourceFields::Kind::Vdb:
      spec.source = SurfaceSource::vdb(fields.file.trimmed().toStdString()).format();
      break;
  }
  spec.filled = fields.filled;
  spec.shell = fields.filled ? 0.f : static_cast<float>(fields.shell);
  return spec;
}

QString describeSurfaceSource(const std::string& source) {
  SurfaceSource s;
  try {
    s = SurfaceSource::parse(source);
  } catch (const Error&) {
    return QString::fromStdString(source);  // shown as it is; building it reports the error
  }
  switch (s.kind) {
    case SurfaceSource::Kind::Iso: {
      char buffer[64];
      const auto end = std::to_chars(buffer, buffer + sizeof(buffer), s.isoValue).ptr;
      return QObject::tr("iso %1 (%2)")
          .arg(QString::fromLatin1(buffer, int(end - buffer)),
               s.insideHigh ? QObject::tr("inside high") : QObject::tr("inside low"));
    }
    case SurfaceSource::Kind::Mesh:
      return QStringLiteral("mesh: ") + QFileInfo(QString::fromStdString(s.file)).fileName();
    case SurfaceSource::Kind::Vdb:
      return QStringLiteral("vdb: ") + QFileInfo(QString::fromStdString(s.file)).fileName();
  }
  return QString::fromStdString(source);
}

QString describeRepresentation(const ContextSurfaceSpec& spec) {
  if (spec.filled) return QObject::tr("filled");
  return QObject::tr("shell ±%1 mm").arg(static_cast<double>(spec.shell), 0, 'g', 4);
}

// ---------------------------------------------------------------------------------------------

AddSurfaceDialog::AddSurfaceDialog(QWidget* parent) : QDialog(parent) {
  setWindowTitle(tr("Add context surface"));
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;

  kind_ = new QComboBox(this);
  kind_->setObjectName(QStringLiteral("kind"));
  kind_->addItem(tr("Isosurface of the data"), static_cast<int>(SurfaceSourceFields::Kind::Iso));
  kind_->addItem(tr("Mesh file (OBJ/PLY/OFF/STL)"),
                 static_cast<int>(SurfaceSourceFields::Kind::Mesh));
  kind_->addItem(tr("OpenVDB level set (.vdb)"), static_cast<int>(SurfaceSourceFields::Kind::Vdb));
  form->addRow(tr("Source"), kind_);
  layout->addLayout(form);

  pages_ = new QStackedWidget(this);
  // Isosurface page.
  auto* isoPage = new QWidget(pages_);
  auto* isoForm = new QFormLayout(isoPage);
  isoForm->setContentsMargins(0, 0, 0, 0);
  isoSlider_ = new QSlider(Qt::Horizontal, isoPage);
  isoSlider_->setObjectName(QStringLiteral("isoSlider"));
  isoSlider_->setRange(0, kSliderSteps);
  isoValue_ = new QDoubleSpinBox(isoPage);
  isoValue_->setObjectName(QStringLiteral("isoValue"));
  isoValue_->setToolTip(tr("The data value whose isosurface becomes the context surface."));
  auto* isoRow = new QHBoxLayout;
  isoRow->addWidget(isoSlider_, 1);
  isoRow->addWidget(isoValue_);
  isoForm->addRow(tr("Isovalue"), isoRow);
  side_ = new QComboBox(isoPage);
  side_->setObjectName(QStringLiteral("side"));
  side_->addItem(tr("Inside: values above"), true);
  side_->addItem(tr("Inside: values below"), false);
  side_->setToolTip(tr("Which side of the isovalue is the solid inside of the surface."));
  isoForm->addRow(tr("Inside"), side_);
  pages_->addWidget(isoPage);
  // File page (mesh and vdb).
  auto* filePage = new QWidget(pages_);
  auto* fileForm = new QFormLayout(filePage);
  fileForm->setContentsMargins(0, 0, 0, 0);
  file_ = new QLineEdit(filePage);
  file_->setObjectName(QStringLiteral("file"));
  browse_ = new QPushButton(tr("Browse…"), filePage);
  auto* fileRow = new QHBoxLayout;
  fileRow->addWidget(file_, 1);
  fileRow->addWidget(browse_);
  fileForm->addRow(tr("File"), fileRow);
  pages_->addWidget(filePage);
  layout->addWidget(pages_);

  auto* repForm = new QFormLayout;
  filled_ = new QRadioButton(tr("Filled"), this);
  filled_->setObjectName(QStringLiteral("filled"));
  filled_->setToolTip(tr("The surface encloses a solid body."));
  shell_ = new QRadioButton(tr("Thin shell"), this);
  shell_->setObjectName(QStringLiteral("shell"));
  shell_->setToolTip(
      tr("Only a shell of the given thickness each side of the surface is solid (the default for "
         "an isosurface: a scan's skin is a layer, and a filled skin hides all that it holds)."));
  shell_->setChecked(true);  // the default for an isosurface (defaultContextSurfaceSpec)
  auto* repRow = new QHBoxLayout;
  repRow->addWidget(filled_);
  repRow->addWidget(shell_);
  repRow->addStretch(1);
  repForm->addRow(tr("Representation"), repRow);
  thickness_ = new QDoubleSpinBox(this);
  thickness_->setObjectName(QStringLiteral("thickness"));
  thickness_->setRange(0.001, 1e4);
  thickness_->setDecimals(3);
  thickness_->setSingleStep(0.5);
  thickness_->setValue(1.0);
  thickness_->setSuffix(tr(" mm"));
  thickness_->setToolTip(
      tr("How far the thin shell reaches on each side of the surface, in "
         "world units (mm)."));
  repForm->addRow(tr("Shell thickness"), thickness_);
  layout->addLayout(repForm);

  problem_ = new QLabel(this);
  problem_->setObjectName(QStringLiteral("problem"));
  layout->addWidget(problem_);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, this);
  ok_ = buttons->button(QDialogButtonBox::Ok);
  ok_->setText(tr("Add"));
  layout->addWidget(buttons);

  setValueRange(0.0, 1.0);
  isoValue_->setValue(0.5);
  isoSlider_->setValue(sliderPosition(0.5));

  connect(buttons, &QDialogButtonBox::accepted, this, [this] {
    if (isValid()) accept();
  });
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  connect(kind_, &QComboBox::currentIndexChanged, this, [this] {
    // Each source's default representation: an isosurface of a scan bounds a layer (a thin
    // shell), a mesh or .vdb file a closed body (filled).
    const bool iso =
        kind_->currentData().toInt() == static_cast<int>(SurfaceSourceFields::Kind::Iso);
    (iso ? shell_ : filled_)->setChecked(true);
    updateState();
  });
  connect(file_, &QLineEdit::textChanged, this, &AddSurfaceDialog::updateState);
  connect(shell_, &QRadioButton::toggled, this, &AddSurfaceDialog::updateState);
  connect(thickness_, &QDoubleSpinBox::valueChanged, this, &AddSurfaceDialog::updateState);
  connect(browse_, &QPushButton::clicked, this, &AddSurfaceDialog::browse);
  connect(isoSlider_, &QSlider::valueChanged, this, [this](int position) {
    const QSignalBlocker block(isoValue_);
    isoValue_->setValue(min_ + (max_ - min_) * position / kSliderSteps);
  });
  connect(isoValue_, &QDoubleSpinBox::valueChanged, this, [this](double value) {
    const QSignalBlocker block(isoSlider_);
    isoSlider_->setValue(sliderPosition(value));
  });
  updateState();
}

int AddSurfaceDialog::sliderPosition(double value) const {
  if (!(max_ > min_)) return 0;
  const double t = std::clamp((value - min_) / (max_ - min_), 0.0, 1.0);
  return static_cast<int>(std::lround(t * kSliderSteps));
}

void AddSurfaceDialog::setValueRange(double min, double max) {
  if (!(max > min)) max = min + 1.0;
  min_ = min;
  max_ = max;
  const QSignalBlocker b0(isoValue_), b1(isoSlider_);
  isoValue_->setDecimals(decimalsFor(max - min));
  isoValue_->setRange(min, max);
  isoValue_->setSingleStep((max - min) / 100.0);
  isoSlider_->setValue(sliderPosition(isoValue_->value()));
}

void AddSurfaceDialog::setKind(SurfaceSourceFields::Kind kind) {
  kind_->setCurrentIndex(kind_->findData(static_cast<int>(kind)));
}

void AddSurfaceDialog::setFields(const SurfaceSourceFields& fields) {
  setKind(fields.kind);
  isoValue_->setValue(fields.isoValue);
  side_->setCurrentIndex(fields.insideHigh ? 0 : 1);
  file_->setText(fields.file);
  (fields.filled ? filled_ : shell_)->setChecked(true);
  if (fields.shell > 0.0) thickness_->setValue(fields.shell);
  updateState();
}

SurfaceSourceFields AddSurfaceDialog::fields() const {
  SurfaceSourceFields f;
  f.kind = static_cast<SurfaceSourceFields::Kind>(kind_->currentData().toInt());
  f.isoValue = isoValue_->value();
  f.insideHigh = side_->currentData().toBool();
  f.file = file_->text();
  f.filled = filled_->isChecked();
  f.shell = thickness_->value();
  return f;
}

void AddSurfaceDialog::updateState() {
  const bool iso = kind_->currentData().toInt() == static_cast<int>(SurfaceSourceFields::Kind::Iso);
  pages_->setCurrentIndex(iso ? 0 : 1);
  thickness_->setEnabled(shell_->isChecked());
  const QString problem = validateSurfaceFields(fields());
  problem_->setText(problem);
  problem_->setVisible(!problem.isEmpty());
  ok_->setEnabled(problem.isEmpty());
}

void AddSurfaceDialog::browse() {
  const bool vdb = kind_->currentData().toInt() == static_cast<int>(SurfaceSourceFields::Kind::Vdb);
  const QString filter =
      vdb ? tr("OpenVDB (*.vdb)") : tr("Meshes (*.obj *.ply *.off *.stl);;All files (*)");
  const QString file =
      QFileDialog::getOpenFileName(this, tr("Context surface"), file_->text(), filter);
  if (!file.isEmpty()) file_->setText(file);
}

// ---------------------------------------------------------------------------------------------

ContextSurfacesPanel::ContextSurfacesPanel(QWidget* parent) : QWidget(parent) {
  colorPicker_ = [](const QColor& initial, QWidget* parentWidget) -> std::optional<QColor> {
    const QColor chosen =
        QColorDialog::getColor(initial, parentWidget, QObject::tr("Context surface colour"));
    if (!chosen.isValid()) return std::nullopt;
    return chosen;
  };
  dialogRunner_ = [](AddSurfaceDialog& dialog) { return dialog.exec() == QDialog::Accepted; };

  auto* layout = new QVBoxLayout(this);
  table_ = new QTableWidget(0, kColumns, this);
  table_->setObjectName(QStringLiteral("surfaces"));
  table_->setHorizontalHeaderLabels({tr("Surface"), tr("Visible"), tr("Colour"), tr("Kind")});
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->verticalHeader()->setVisible(false);
  table_->horizontalHeader()->setSectionResizeMode(kSource, QHeaderView::Stretch);
  for (int c : {kVisible, kColor, kRepresentation})
    table_->horizontalHeader()->setSectionResizeMode(c, QHeaderView::ResizeToContents);
  layout->addWidget(table_, 1);

  auto* buttons = new QHBoxLayout;
  add_ = new QToolButton(this);
  add_->setObjectName(QStringLiteral("add"));
  add_->setText(tr("Add…"));
  add_->setPopupMode(QToolButton::InstantPopup);
  add_->setToolTip(
      tr("Add a context surface: an isosurface of the data, a mesh or an OpenVDB "
         "level set, filled or as a thin shell."));
  auto* menu = new QMenu(add_);
  menu->addAction(tr("Isosurface…"), this, [this] { requestAdd(SurfaceSourceFields::Kind::Iso); });
  menu->addAction(tr("From mesh file (OBJ/PLY/OFF/STL)…"), this,
                  [this] { requestAdd(SurfaceSourceFields::Kind::Mesh); });
  menu->addAction(tr("From .vdb file…"), this,
                  [this] { requestAdd(SurfaceSourceFields::Kind::Vdb); });
  add_->setMenu(menu);
  remove_ = new QPushButton(tr("Remove"), this);
  remove_->setObjectName(QStringLiteral("remove"));
  remove_->setToolTip(tr("Remove the selected context surface."));
  buttons->addWidget(add_);
  buttons->addWidget(remove_);
  buttons->addStretch(1);
  layout->addLayout(buttons);

  connect(remove_, &QPushButton::clicked, this, &ContextSurfacesPanel::removeSelected);
  connect(table_, &QTableWidget::itemSelectionChanged, this, &ContextSurfacesPanel::updateButtons);
  updateButtons();
}

void ContextSurfacesPanel::setValueRange(double min, double max) {
  min_ = min;
  max_ = max;
}

void ContextSurfacesPanel::setSurfaces(const std::vector<ContextSurfaceSpec>& surfaces) {
  const int selected = table_->currentRow();
  surfaces_ = surfaces;
  table_->setRowCount(0);  // deletes the old rows' widgets
  table_->setRowCount(rowCount());
  for (int row = 0; row < rowCount(); ++row) fillRow(row);
  if (selected >= 0 && selected < rowCount()) table_->selectRow(selected);
  updateButtons();
}

void ContextSurfacesPanel::fillRow(int row) {
  const ContextSurfaceSpec& spec = surfaces_[static_cast<size_t>(row)];
  auto* source = new QTableWidgetItem(describeSurfaceSource(spec.source));
  source->setToolTip(QString::fromStdString(spec.source));
  table_->setItem(row, kSource, source);

  auto* visible = new QCheckBox(table_);
  visible->setChecked(spec.visible);
  visible->setToolTip(tr("Show or hide this surface in the rendering."));
  connect(visible, &QCheckBox::toggled, this, [this, row](bool on) {
    if (row < rowCount()) surfaces_[static_cast<size_t>(row)].visible = on;
    emit visibilityChanged(row, on);
  });
  table_->setCellWidget(row, kVisible, visible);

  auto* color = new QToolButton(table_);
  color->setIcon(swatch(spec.color));
  color->setIconSize(QSize(28, 16));
  color->setAutoRaise(true);
  color->setToolTip(tr("Change the surface's colour."));
  connect(color, &QToolButton::clicked, this, [this, row] { pickColor(row); });
  table_->setCellWidget(row, kColor, color);

  auto* representation = new QTableWidgetItem(describeRepresentation(spec));
  representation->setToolTip(spec.filled ? tr("A solid body.")
                                         : tr("A thin shell reaching this far each side."));
  table_->setItem(row, kRepresentation, representation);
}

QCheckBox* ContextSurfacesPanel::visibilityBox(int row) const {
  if (row < 0 || row >= rowCount()) return nullptr;
  return qobject_cast<QCheckBox*>(table_->cellWidget(row, kVisible));
}

QToolButton* ContextSurfacesPanel::colorButton(int row) const {
  if (row < 0 || row >= rowCount()) return nullptr;
  return qobject_cast<QToolButton*>(table_->cellWidget(row, kColor));
}

void ContextSurfacesPanel::requestAdd(SurfaceSourceFields::Kind kind) {
  AddSurfaceDialog dialog(this);
  dialog.setValueRange(min_, max_);
  SurfaceSourceFields fields;
  fields.kind = kind;
  fields.isoValue = 0.5 * (min_ + max_);
  dialog.setFields(fields);
  if (dialogRunner_ && dialogRunner_(dialog) && dialog.isValid())
    emit addSurfaceRequested(dialog.spec());
}

void ContextSurfacesPanel::pickColor(int row) {
  if (row < 0 || row >= rowCount() || !colorPicker_) return;
  ContextSurfaceSpec& spec = surfaces_[static_cast<size_t>(row)];
  const std::optional<QColor> chosen = colorPicker_(displayColor(spec.color), this);
  if (!chosen || !chosen->isValid()) return;
  spec.color = linearColor(*chosen);
  if (QToolButton* button = colorButton(row)) button->setIcon(swatch(spec.color));
  emit colorChanged(row, spec.color);
}

void ContextSurfacesPanel::removeSelected() {
  const int row = table_->currentRow();
  if (row >= 0 && row < rowCount()) emit removeSurfaceRequested(row);
}

void ContextSurfacesPanel::updateButtons() {
  const QModelIndexList rows = table_->selectionModel()->selectedRows();
  remove_->setEnabled(!rows.isEmpty());
}

}  // namespace visopt::ws
