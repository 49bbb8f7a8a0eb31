#include "panels/hotspot_panel.h"

#include <algorithm>
#include <cmath>

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QMouseEvent>
#include <QPainter>
#include <QPushButton>
#include <QSignalBlocker>
#include <QStackedWidget>
#include <QVBoxLayout>

#include "panels/context_surfaces_panel.h"  // describeSurfaceSource
#include "widgets/spin_boxes.h"

namespace visopt::ws {

namespace {

QComboBox* makeShaderBox(QWidget* parent, const char* name) {
  auto* box = new QComboBox(parent);
  box->setObjectName(QString::fromLatin1(name));
  box->addItem(QObject::tr("Diffuse"), int(ClearViewShader::Diffuse));
  box->addItem(QObject::tr("Cool to warm"), int(ClearViewShader::CoolWarm));
  box->addItem(QObject::tr("Skin"), int(ClearViewShader::Skin));
  box->addItem(QObject::tr("Bone"), int(ClearViewShader::Bone));
  return box;
}

void selectData(QComboBox* box, int value) {
  const int i = box->findData(value);
  if (i >= 0) box->setCurrentIndex(i);
}

// A spin box shows a value rounded to its decimals; the value it was given is kept beside it
// and read back for as long as the user leaves the box alone, so that showing settings and
// reading them again changes nothing (a wheel-scaled size of 12.3456 stays that).
void showExact(QDoubleSpinBox* box, double value) {
  box->setValue(value);
  box->setProperty("exactValue", value);
  box->setProperty("shownValue", box->value());
}

double exactValue(const QDoubleSpinBox* box) {
  const QVariant shown = box->property("shownValue");
  if (shown.isValid() && shown.toDouble() == box->value())
    return box->property("exactValue").toDouble();
  return box->value();
}

QString number(double v) {
  return QString::number(v, 'g', 4);
}

}  // namespace

int isovalueDecimals(double lo, double hi) {
  const double span = hi - lo;
  if (!(span > 0.0) || !std::isfinite(span)) return 3;
  return std::clamp(3 - int(std::floor(std::log10(span))), 1, 6);
}

// ---- IsovaluePicker --------------------------------------------------------------------------

IsovaluePicker::IsovaluePicker(QWidget* parent) : QWidget(parent) {
  setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Fixed);
  setCursor(Qt::CrossCursor);
}

void IsovaluePicker::setHistogram(std::shared_ptr<const Histogram> histogram) {
  histogram_ = std::move(histogram);
  update();
}

void IsovaluePicker::setRange(double lo, double hi) {
  lo_ = lo;
  hi_ = hi > lo ? hi : lo + 1.0;
  update();
}

void IsovaluePicker::setValue(double value) {
  value_ = value;
  update();
}

QRectF IsovaluePicker::plotRect() const {
  return QRectF(2.0, 2.0, std::max(1.0, width() - 4.0), std::max(1.0, height() - 4.0));
}

double IsovaluePicker::valueAtX(double x) const {
  const QRectF r = plotRect();
  const double t = std::clamp((x - r.left()) / r.width(), 0.0, 1.0);
  return lo_ + t * (hi_ - lo_);
}

double IsovaluePicker::xOfValue(double value) const {
  const QRectF r = plotRect();
  return r.left() + (value - lo_) / (hi_ - lo_) * r.width();
}

void IsovaluePicker::paintEvent(QPaintEvent*) {
  QPainter p(this);
  const QRectF r = plotRect();
  p.fillRect(r, palette().color(QPalette::Base));
  if (histogram_ && histogram_->bins() > 0 && histogram_->maxCount() > 0.0) {
    QColor bar = palette().color(QPalette::Text);
    bar.setAlpha(70);
    const double norm = std::log1p(histogram_->maxCount());
    const double w = histogram_->binWidth();
    for (int i = 0; i < histogram_->bins(); ++i) {
      const double c = histogram_->counts[size_t(i)];
      if (!(c > 0.0)) continue;
      const double lo = histogram_->valueMin + i * w;
      const double x0 = xOfValue(lo), x1 = std::max(xOfValue(lo + w), x0 + 1.0);
      const double h = std::log1p(c) / norm * r.height();
      p.fillRect(QRectF(x0, r.bottom() - h, x1 - x0, h), bar);
    }
  }
  const double x = std::clamp(xOfValue(value_), r.left(), r.right());
  p.setPen(QPen(palette().color(QPalette::Highlight), 2.0));
  p.drawLine(QPointF(x, r.top()), QPointF(x, r.bottom()));
  p.setPen(QPen(palette().color(QPalette::Mid), 1.0));
  p.setBrush(Qt::NoBrush);
  p.drawRect(r);
}

void IsovaluePicker::mousePressEvent(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton) return;
  value_ = valueAtX(event->position().x());
  update();
  emit valuePicked(value_);
}

void IsovaluePicker::mouseMoveEvent(QMouseEvent* event) {
  if (!(event->buttons() & Qt::LeftButton)) return;
  value_ = valueAtX(event->position().x());
  update();
  emit valuePicked(value_);
}

// ---- HotspotLayerEditor ----------------------------------------------------------------------

HotspotLayerEditor::HotspotLayerEditor(const QString& role, QWidget* parent) : QWidget(parent) {
  setObjectName(role + QStringLiteral("Layer"));
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  kind_ = new QComboBox(this);
  kind_->setObjectName(QStringLiteral("kind"));
  kind_->addItem(tr("Context surface"), int(ClearViewLayerKind::ContextSurface));
  kind_->addItem(tr("Isosurface of the data"), int(ClearViewLayerKind::Isosurface));
  kind_->addItem(tr("Importance"), int(ClearViewLayerKind::Importance));
  layout->addWidget(kind_);

  // Each page at the top of its own widget: a stacked widget gives every page the size of the
  // largest (the isovalue's spin box and histogram), which would stretch a lone combo box.
  pages_ = new QStackedWidget(this);
  const auto page = [this](QWidget* content) {
    auto* holder = new QWidget(pages_);
    auto* holderLayout = new QVBoxLayout(holder);
    holderLayout->setContentsMargins(0, 0, 0, 0);
    holderLayout->addWidget(content);
    holderLayout->addStretch(1);
    pages_->addWidget(holder);
  };
  surface_ = new QComboBox(pages_);
  surface_->setObjectName(QStringLiteral("surface"));
  surface_->setToolTip(tr("One of the scene's context surfaces (the Surfaces panel's list)."));
  page(surface_);

  auto* isoPage = new QWidget(pages_);
  auto* isoLayout = new QVBoxLayout(isoPage);
  isoLayout->setContentsMargins(0, 0, 0, 0);
  isovalue_ = makeDoubleBox(isoPage, "isovalue", 0.0, 1.0, 3, 0.01);
  picker_ = new IsovaluePicker(isoPage);
  picker_->setObjectName(QStringLiteral("isoPicker"));
  isoLayout->addWidget(isovalue_);
  isoLayout->addWidget(picker_);
  page(isoPage);

  level_ = makeDoubleBox(pages_, "importanceLevel", 0.001, 1.0, 3, 0.05);
  level_->setValue(0.5);
  level_->setToolTip(
      tr("The importance's isosurface at this level g, in (0, 1] (unitless; inside where "
         "higher). Default: 0.5."));
  page(level_);
  pages_->setSizePolicy(QSizePolicy::Preferred, QSizePolicy::Maximum);
  layout->addWidget(pages_);

  connect(kind_, &QComboBox::currentIndexChanged, this, [this](int) {
    showKind();
    emit edited();
  });
  connect(surface_, &QComboBox::currentIndexChanged, this, [this](int i) {
    if (i >= 0) surfaceIndex_ = surface_->itemData(i).toInt();
    emit edited();
  });
  connect(isovalue_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    picker_->setValue(v);
    emit edited();
  });
  connect(picker_, &IsovaluePicker::valuePicked, this, [this](double v) {
    isovalue_->setValue(v);  // clamped to the range; emits edited through valueChanged
    picker_->setValue(isovalue_->value());
  });
  connect(level_, &QDoubleSpinBox::valueChanged, this, [this](double) { emit edited(); });
  showKind();
}

void HotspotLayerEditor::showKind() {
  int index = 0;
  switch (ClearViewLayerKind(kind_->currentData().toInt())) {
    case ClearViewLayerKind::ContextSurface:
      index = 0;
      break;
    case ClearViewLayerKind::Isosurface:
      index = 1;
      break;
    case ClearViewLayerKind::Importance:
      index = 2;
      break;
  }
  pages_->setCurrentIndex(index);
  // Only the page shown counts for the size: no gap under a lone combo box.
  for (int i = 0; i < pages_->count(); ++i)
    pages_->widget(i)->setSizePolicy(QSizePolicy::Preferred,
                                     i == index ? QSizePolicy::Maximum : QSizePolicy::Ignored);
  pages_->adjustSize();
  updateGeometry();
}

void HotspotLayerEditor::fillSurfaces(int keep) {
  const QSignalBlocker block(surface_);
  surface_->clear();
  for (size_t i = 0; i < surfaces_.size(); ++i)
    surface_->addItem(
        QStringLiteral("%1: %2").arg(i).arg(describeSurfaceSource(surfaces_[i].source)), int(i));
  if (keep >= int(surfaces_.size()))
    surface_->addItem(tr("%1: (not in this scene)").arg(keep), keep);
  selectData(surface_, keep);
  surfaceIndex_ = keep;
}

void HotspotLayerEditor::setSurfaces(const std::vector<ContextSurfaceSpec>& surfaces) {
  surfaces_ = surfaces;
  fillSurfaces(surfaceIndex_);
}

void HotspotLayerEditor::setValueRange(double lo, double hi) {
  const QSignalBlocker block(isovalue_);
  const int decimals = isovalueDecimals(lo, hi);
  isovalue_->setDecimals(decimals);
  isovalue_->setRange(lo, hi);
  isovalue_->setSingleStep(hi > lo ? (hi - lo) / 100.0 : 0.01);
  if (lo != lo_ || hi != hi_) {
    // New data: an isosurface chosen from now on starts in the middle of its range (a layer
    // given with setLayer replaces it).
    const double scale = std::pow(10.0, decimals);
    showExact(isovalue_, std::round(0.5 * (lo + hi) * scale) / scale);
    lo_ = lo;
    hi_ = hi;
  }
  isovalue_->setToolTip(
      tr("The data's isosurface at this value, in data units (inside where higher), within the "
         "data's range [%1, %2]. Default: the middle of the range, %3. Click or drag on the "
         "histogram below to pick it.")
          .arg(number(lo), number(hi), number(0.5 * (lo + hi))));
  picker_->setToolTip(isovalue_->toolTip());
  picker_->setRange(lo, hi);
  picker_->setValue(isovalue_->value());
}

void HotspotLayerEditor::setHistogram(std::shared_ptr<const Histogram> histogram) {
  picker_->setHistogram(std::move(histogram));
}

void HotspotLayerEditor::setLayer(const ClearViewLayer& layer) {
  const QSignalBlocker b0(kind_), b1(isovalue_), b2(level_);
  selectData(kind_, int(layer.kind));
  showKind();
  if (layer.kind == ClearViewLayerKind::Isosurface) {
    showExact(isovalue_, layer.isovalue);
    picker_->setValue(isovalue_->value());
  }
  if (layer.kind == ClearViewLayerKind::Importance) showExact(level_, layer.isovalue);
  if (layer.kind == ClearViewLayerKind::ContextSurface) fillSurfaces(layer.surface);
}

ClearViewLayer HotspotLayerEditor::layer() const {
  ClearViewLayer layer;
  layer.kind = ClearViewLayerKind(kind_->currentData().toInt());
  switch (layer.kind) {
    case ClearViewLayerKind::ContextSurface:
      layer.surface = surfaceIndex_;
      break;
    case ClearViewLayerKind::Isosurface:
      layer.isovalue = exactValue(isovalue_);
      break;
    case ClearViewLayerKind::Importance:
      layer.isovalue = exactValue(level_);
      break;
  }
  return layer;
}

// ---- HotspotPanel ----------------------------------------------------------------------------

HotspotPanel::HotspotPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);

  auto* intro = new QLabel(
      tr("ClearView (Krüger et al. 2006): with the Hotspot tool (H) the view opens the context "
         "around the cursor onto the focus behind it. Wheel: size; drag: orbit."),
      this);
  intro->setWordWrap(true);
  layout->addWidget(intro);

  // --- Layers ---
  auto* layers = new QGroupBox(tr("Layers"), this);
  auto* layersForm = new QFormLayout(layers);
  context_ = new HotspotLayerEditor(QStringLiteral("context"), layers);
  context_->kindBox()->setToolTip(
      tr("The semi-transparent context surface that the hotspot opens. Default: the scene's "
         "context surface 0, else the data's isosurface at the middle of its range."));
  layersForm->addRow(tr("Context"), context_);
  deeperOn_ = new QCheckBox(tr("Second context layer, behind the first"), layers);
  deeperOn_->setObjectName(QStringLiteral("deeperContextOn"));
  deeperOn_->setToolTip(
      tr("A further semi-transparent context surface, searched along each ray from where the "
         "first one was hit (choose one that lies behind it, e.g. the skull behind the skin); "
         "the hotspot opens both. Default: off."));
  layersForm->addRow(QString(), deeperOn_);
  deeper_ = new HotspotLayerEditor(QStringLiteral("deeperContext"), layers);
  layersForm->addRow(tr("Context 2"), deeper_);
  focus_ = new HotspotLayerEditor(QStringLiteral("focus"), layers);
  focus_->kindBox()->setToolTip(
      tr("The opaque focus surface seen through the hotspot. Default: the importance at 0.5 "
         "when the scene has one, else the data's isosurface at the middle of its range."));
  layersForm->addRow(tr("Focus"), focus_);
  secondFocusOn_ = new QCheckBox(tr("Second focus layer"), layers);
  secondFocusOn_->setObjectName(QStringLiteral("secondFocusOn"));
  secondFocusOn_->setToolTip(
      tr("A further opaque focus surface; each pixel shows the nearer of the two, and the "
         "hotspot's centre lies on the nearer one. Default: off."));
  layersForm->addRow(QString(), secondFocusOn_);
  secondFocus_ = new HotspotLayerEditor(QStringLiteral("secondFocus"), layers);
  layersForm->addRow(tr("Focus 2"), secondFocus_);
  volumeLayer_ = new QCheckBox(tr("Volume in front"), layers);
  volumeLayer_->setObjectName(QStringLiteral("volumeLayer"));
  volumeLayer_->setToolTip(
      tr("Also composite the transfer function's matter in front of the surfaces "
         "(emission-absorption, unshaded), opened around the hotspot like the context. "
         "Default: off."));
  layersForm->addRow(QString(), volumeLayer_);
  layout->addWidget(layers);

  // --- Hotspot ---
  auto* hotspot = new QGroupBox(tr("Hotspot"), this);
  auto* hotspotForm = new QFormLayout(hotspot);
  size_ = makeDoubleBox(hotspot, "size", 0.0, 1000.0, 2, 1.0);
  size_->setSpecialValueText(tr("automatic"));
  size_->setSuffix(tr(" mm"));
  size_->setToolTip(
      tr("The hotspot's radius about the focus point, in world units (mm for medical data). "
         "Default: automatic (0), twice the focus point's depth below the context. The mouse "
         "wheel over the view scales it by 1.1 per notch; Escape there returns to automatic."));
  hotspotForm->addRow(tr("Size"), size_);
  measure_ = new QComboBox(hotspot);
  measure_->setObjectName(QStringLiteral("measure"));
  measure_->addItem(tr("Curvature"), int(ClearViewMeasure::Curvature));
  measure_->addItem(tr("Distance"), int(ClearViewMeasure::Distance));
  measure_->addItem(tr("View distance"), int(ClearViewMeasure::ViewDistance));
  measure_->setToolTip(
      tr("What keeps the context opaque besides the distance from the focus point: its "
         "image-space curvature (§3.2.1; the default), its distance to the focus surface along "
         "its normal (§3.2.2) or along the view ray (§3.2.3)."));
  hotspotForm->addRow(tr("Measure"), measure_);
  weight_ = makeDoubleBox(hotspot, "weight", 0.0, 100.0, 2, 0.1);
  weight_->setToolTip(
      tr("The measure's weight against the distance term, >= 0 (unitless): 0 opens a plain "
         "sphere, larger values keep more of the curved context. Default: 1."));
  hotspotForm->addRow(tr("Weight"), weight_);
  distanceScale_ = makeDoubleBox(hotspot, "distanceScale", 0.0, 1e6, 2, 1.0);
  distanceScale_->setSpecialValueText(tr("= size"));
  distanceScale_->setSuffix(tr(" mm"));
  distanceScale_->setToolTip(
      tr("For the distance measures: the distance, in world units (mm for medical data), at "
         "which the measure reaches 1. Default: 0, the hotspot's size."));
  hotspotForm->addRow(tr("Distance scale"), distanceScale_);
  border_ = new QCheckBox(tr("Border"), hotspot);
  border_->setObjectName(QStringLiteral("border"));
  border_->setToolTip(
      tr("Darken the context at the hotspot's rim (between 0.95 and 1 of its size, §3.2.4). "
         "Default: on."));
  hotspotForm->addRow(QString(), border_);
  layout->addWidget(hotspot);

  // --- Shading ---
  auto* shading = new QGroupBox(tr("Shading"), this);
  auto* shadingForm = new QFormLayout(shading);
  contextShader_ = makeShaderBox(shading, "contextShader");
  contextShader_->setToolTip(
      tr("The context layer's shader (§3.2.5-3.2.7): diffuse, cool to warm, skin or bone. "
         "Default: skin."));
  shadingForm->addRow(tr("Context shader"), contextShader_);
  focusShader_ = makeShaderBox(shading, "focusShader");
  focusShader_->setToolTip(
      tr("The focus layer's shader: diffuse, cool to warm, skin or bone. Default: bone."));
  shadingForm->addRow(tr("Focus shader"), focusShader_);
  ambient_ = makeDoubleBox(shading, "ambient", 0.0, 1.0, 2, 0.05);
  ambient_->setToolTip(
      tr("The ambient term of the diffuse and cool-to-warm shaders, 0..1 (unitless). "
         "Default: 0.15."));
  shadingForm->addRow(tr("Ambient"), ambient_);
  light_ = new QComboBox(shading);
  light_->setObjectName(QStringLiteral("light"));
  light_->addItem(tr("At the camera"), true);
  light_->addItem(tr("The scene's light"), false);
  light_->setToolTip(
      tr("Where the light is: at the camera (a headlight, the paper's choice and the default: "
         "best contrast) or the scene's point light."));
  shadingForm->addRow(tr("Light"), light_);
  layout->addWidget(shading);

  reset_ = new QPushButton(tr("Scene defaults"), this);
  reset_->setObjectName(QStringLiteral("reset"));
  reset_->setToolTip(
      tr("Every setting back to its default for this scene (as `visopt render --clearview` "
         "chooses them)."));
  layout->addWidget(reset_);
  optimiseAround_ = new QPushButton(tr("Optimise around the hotspot"), this);
  optimiseAround_->setObjectName(QStringLiteral("optimiseAround"));
  optimiseAround_->setToolTip(
      tr("Makes the importance a smooth ball about the last focus point, of the hotspot's "
         "radius (1 within half of it, 0 beyond it), and runs the visibility optimisation "
         "(Himmler & Günther 2026) for it: the context opens where you pointed. Needs a "
         "ClearView frame whose cursor saw the focus layer."));
  optimiseAround_->setEnabled(false);
  layout->addWidget(optimiseAround_);

  problem_ = new QLabel(this);
  problem_->setObjectName(QStringLiteral("problem"));
  problem_->setWordWrap(true);
  problem_->setStyleSheet(QStringLiteral("color: #e06060;"));
  problem_->hide();
  layout->addWidget(problem_);
  stats_ = new QLabel(this);
  stats_->setObjectName(QStringLiteral("stats"));
  stats_->setWordWrap(true);
  stats_->setToolTip(
      tr("The last ClearView frame: the layers are extracted when the view or the layers "
         "change; moving the hotspot or changing the other settings only composites."));
  layout->addWidget(stats_);
  layout->addStretch(1);

  setSettings(ClearViewSettings{});

  for (HotspotLayerEditor* e : {context_, focus_, deeper_, secondFocus_})
    connect(e, &HotspotLayerEditor::edited, this, &HotspotPanel::onEdited);
  for (QCheckBox* box : {deeperOn_, secondFocusOn_})
    connect(box, &QCheckBox::toggled, this, [this] {
      deeper_->setEnabled(deeperOn_->isChecked());
      secondFocus_->setEnabled(secondFocusOn_->isChecked());
      onEdited();
    });
  for (QComboBox* box : {measure_, contextShader_, focusShader_, light_})
    connect(box, &QComboBox::currentIndexChanged, this, &HotspotPanel::onEdited);
  for (QDoubleSpinBox* box : {size_, weight_, distanceScale_, ambient_})
    connect(box, &QDoubleSpinBox::valueChanged, this, &HotspotPanel::onEdited);
  for (QCheckBox* box : {border_, volumeLayer_})
    connect(box, &QCheckBox::toggled, this, &HotspotPanel::onEdited);
  connect(reset_, &QPushButton::clicked, this, &HotspotPanel::resetRequested);
  connect(optimiseAround_, &QPushButton::clicked, this, &HotspotPanel::optimiseAroundRequested);
}

void HotspotPanel::setScene(const std::vector<ContextSurfaceSpec>& surfaces, double valueMin,
                            double valueMax, float sceneRadius) {
  updating_ = true;
  for (HotspotLayerEditor* e : {context_, focus_, deeper_, secondFocus_}) {
    e->setSurfaces(surfaces);
    e->setValueRange(valueMin, valueMax);
  }
  // A second layer not in use starts as the data's isosurface three quarters up its range
  // (denser matter, usually deeper inside), so that switching it on shows something.
  for (auto [on, editor] : {std::pair{deeperOn_, deeper_}, std::pair{secondFocusOn_, secondFocus_}})
    if (!on->isChecked())
      editor->setLayer(
          {ClearViewLayerKind::Isosurface, valueMin + 0.75 * (valueMax - valueMin), 0});
  const double radius = std::isfinite(sceneRadius) && sceneRadius > 0.f ? sceneRadius : 1.0;
  const double size = size_->value();
  size_->setRange(0.0, std::max(4.0 * radius, size));
  size_->setSingleStep(radius / 20.0);
  distanceScale_->setSingleStep(radius / 20.0);
  updating_ = false;
}

void HotspotPanel::setHistogram(std::shared_ptr<const Histogram> histogram) {
  for (HotspotLayerEditor* e : {context_, focus_, deeper_}) e->setHistogram(histogram);
  secondFocus_->setHistogram(std::move(histogram));
}

void HotspotPanel::setSettings(const ClearViewSettings& s) {
  updating_ = true;
  context_->setLayer(s.context);
  focus_->setLayer(s.focus);
  deeperOn_->setChecked(!s.deeperContexts.empty());
  if (!s.deeperContexts.empty()) deeper_->setLayer(s.deeperContexts.front());
  deeper_->setEnabled(!s.deeperContexts.empty());
  secondFocusOn_->setChecked(!s.moreFoci.empty());
  if (!s.moreFoci.empty()) secondFocus_->setLayer(s.moreFoci.front());
  secondFocus_->setEnabled(!s.moreFoci.empty());
  selectData(measure_, int(s.measure));
  selectData(contextShader_, int(s.contextShader));
  selectData(focusShader_, int(s.focusShader));
  if (double(s.size) > size_->maximum()) size_->setMaximum(double(s.size));
  showExact(size_, double(s.size));
  showExact(weight_, double(s.weight));
  showExact(distanceScale_, double(s.distanceScale));
  border_->setChecked(s.border);
  showExact(ambient_, double(s.ambient));
  light_->setCurrentIndex(s.headlight ? 0 : 1);
  volumeLayer_->setChecked(s.volumeLayer);
  given_ = s;
  updating_ = false;
}

ClearViewSettings HotspotPanel::settings() const {
  ClearViewSettings s;
  s.context = context_->layer();
  s.focus = focus_->layer();
  // The second layers as shown, then any further ones as they were given.
  auto layers = [](QCheckBox* on, HotspotLayerEditor* editor,
                   const std::vector<ClearViewLayer>& given) {
    std::vector<ClearViewLayer> out;
    if (!on->isChecked()) return out;
    out.push_back(editor->layer());
    if (given.size() > 1) out.insert(out.end(), given.begin() + 1, given.end());
    return out;
  };
  s.deeperContexts = layers(deeperOn_, deeper_, given_.deeperContexts);
  s.moreFoci = layers(secondFocusOn_, secondFocus_, given_.moreFoci);
  s.measure = ClearViewMeasure(measure_->currentData().toInt());
  s.contextShader = ClearViewShader(contextShader_->currentData().toInt());
  s.focusShader = ClearViewShader(focusShader_->currentData().toInt());
  s.size = float(exactValue(size_));
  s.weight = float(exactValue(weight_));
  s.distanceScale = float(exactValue(distanceScale_));
  s.border = border_->isChecked();
  s.ambient = float(exactValue(ambient_));
  s.headlight = light_->currentData().toBool();
  s.volumeLayer = volumeLayer_->isChecked();
  s.contextColor = given_.contextColor;
  s.focusColor = given_.focusColor;
  s.background = given_.background;
  return s;
}

void HotspotPanel::setProblem(const QString& message) {
  problem_->setText(message);
  problem_->setVisible(!message.isEmpty());
}

QString HotspotPanel::problem() const {
  return problem_->text();
}

void HotspotPanel::setStats(const ClearViewStats& st) {
  QString text = st.extracted ? tr("Layers extracted in %1 ms").arg(st.extractMs, 0, 'f', 0)
                              : tr("Layers reused");
  text += tr(" · composited in %1 ms · %2 extractions")
              .arg(st.compositeMs, 0, 'f', 1)
              .arg(qlonglong(st.extractions));
  optimiseAround_->setEnabled(st.hasFocusPoint);
  if (st.hasFocusPoint)
    text += tr("\nFocus point (%1, %2, %3), radius %4")
                .arg(double(st.focusPoint.x), 0, 'f', 1)
                .arg(double(st.focusPoint.y), 0, 'f', 1)
                .arg(double(st.focusPoint.z), 0, 'f', 1)
                .arg(double(st.size), 0, 'f', 1);
  else
    text += tr("\nNo focus under the hotspot: the context stays opaque");
  stats_->setText(text);
}

QString HotspotPanel::statsText() const {
  return stats_->text();
}

void HotspotPanel::onEdited() {
  if (updating_) return;
  emit settingsEdited(settings());
}

}  // namespace visopt::ws
