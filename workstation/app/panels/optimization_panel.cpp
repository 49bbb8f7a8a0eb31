#include "panels/optimization_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QVBoxLayout>

#include "widgets/spin_boxes.h"

namespace visopt::ws {

namespace {

QSpinBox* makeIntBox(QWidget* parent, const char* name, int lo, int hi) {
  auto* box = new QSpinBox(parent);
  box->setObjectName(QString::fromLatin1(name));
  box->setRange(lo, hi);
  box->setKeyboardTracking(false);
  return box;
}

}  // namespace

OptimizationPanel::OptimizationPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);

  // --- Extinction (Eqs. 10-14) ---
  auto* energyGroup = new QGroupBox(tr("Extinction energy"), this);
  auto* energyForm = new QFormLayout(energyGroup);

  rhoAuto_ = new QCheckBox(tr("auto = 1/μ_max"), energyGroup);
  rhoAuto_->setObjectName(QStringLiteral("rhoAuto"));
  rho_ = makeDoubleBox(energyGroup, "rho", 0.0, 1e6, 4, 0.1);
  rho_->setValue(1.0);
  const QString rhoTip =
      tr("ρ weights the fidelity term ρ/2 ∫(μ − μ̄)², which pulls the extinction back to the "
         "transfer function's. Larger values keep the rendering closer to the original; 'auto' "
         "uses 1/μ_max so that ρ(μ − μ̄) lies in [−1, 1].");
  rho_->setToolTip(rhoTip);
  rhoAuto_->setToolTip(rhoTip);
  auto* rhoRow = new QHBoxLayout;
  rhoRow->addWidget(rho_, 1);
  rhoRow->addWidget(rhoAuto_);
  energyForm->addRow(tr("ρ (fidelity)"), rhoRow);

  q_ = makeDoubleBox(energyGroup, "q", 0.0, 1e6, 3, 1.0);
  q_->setToolTip(
      tr("q weights the view visibility term −q ∫ g μ T_V: how strongly matter that hides "
         "important structures from the camera is made transparent. Larger values clear the view "
         "more aggressively."));
  energyForm->addRow(tr("q (view visibility)"), q_);

  r_ = makeDoubleBox(energyGroup, "r", 0.0, 1e6, 3, 1.0);
  r_->setToolTip(
      tr("r weights the light visibility term −r ∫ g μ T_L: it removes matter that shadows "
         "important structures from the light (default 40, equal to q: the paper's joint "
         "optimisation from view and light). 0 disables the term and, without context surfaces, "
         "allocates no light-space grids."));
  energyForm->addRow(tr("r (light visibility)"), r_);
  layout->addWidget(energyGroup);

  // --- Level set (Eq. 23) ---
  auto* surfaceGroup = new QGroupBox(tr("Context surfaces"), this);
  auto* surfaceForm = new QFormLayout(surfaceGroup);
  lambda_ = makeDoubleBox(surfaceGroup, "lambda", 0.0, 10.0, 3, 0.05);
  lambda_->setToolTip(
      tr("λ pulls the context surfaces back to their original shape wherever the accumulated "
         "importance is below λ (Eq. 23). Lower values remove more occluding geometry; higher "
         "values preserve more of it."));
  surfaceForm->addRow(tr("λ (return to shape)"), lambda_);
  redistance_ = makeIntBox(surfaceGroup, "redistanceIterations", 0, 10000);
  redistance_->setToolTip(
      tr("Maximum number of redistancing iterations (Eq. 18) after each level-set step, which "
         "keep φ a signed distance field. More iterations are more accurate but slower; it stops "
         "early once converged."));
  surfaceForm->addRow(tr("Redistancing iterations"), redistance_);
  integrator_ = new QComboBox(surfaceGroup);
  integrator_->setObjectName(QStringLiteral("levelSetIntegrator"));
  integrator_->addItem(tr("Semi-implicit (default)"), 1);
  integrator_->addItem(tr("Explicit Euler (reference)"), 0);
  integrator_->setToolTip(
      tr("How each iteration moves the context surfaces (Eq. 23). Semi-implicit: one stable step "
         "per half voxel of motion, several times faster on real scans. Explicit Euler: the "
         "paper's small substeps (Eq. 25), the reference the semi-implicit step is tested "
         "against."));
  surfaceForm->addRow(tr("Level-set integrator"), integrator_);
  layout->addWidget(surfaceGroup);

  // --- Solver ---
  auto* solverGroup = new QGroupBox(tr("Solver"), this);
  auto* solverForm = new QFormLayout(solverGroup);
  optimizer_ = new QComboBox(solverGroup);
  optimizer_->setObjectName(QStringLiteral("optimizer"));
  optimizer_->addItem(QStringLiteral("AdEMAMix"), static_cast<int>(OptimizerKind::AdEMAMix));
  optimizer_->addItem(QStringLiteral("Adam"), static_cast<int>(OptimizerKind::Adam));
  optimizer_->setToolTip(
      tr("The gradient optimiser of the extinction. AdEMAMix adds a slow moving average of past "
         "gradients to Adam and usually converges a little faster."));
  solverForm->addRow(tr("Optimiser"), optimizer_);

  learningRate_ = makeDoubleBox(solverGroup, "learningRate", 0.0001, 10.0, 4, 0.01);
  learningRate_->setToolTip(
      tr("Step size of the optimiser, in units of μ_max per step. Larger steps converge faster "
         "but may oscillate; smaller ones are smoother and slower."));
  solverForm->addRow(tr("Learning rate"), learningRate_);

  levels_ = makeIntBox(solverGroup, "levels", 1, 8);
  levels_->setToolTip(
      tr("Number of coarse-to-fine multigrid levels: the optimisation starts at low resolution "
         "and is upsampled level by level. More levels converge faster on large volumes."));
  solverForm->addRow(tr("Multigrid levels"), levels_);

  iterations_ = makeIntBox(solverGroup, "iterationsPerLevel", 1, 100000);
  iterations_->setToolTip(
      tr("Maximum number of optimisation iterations on each multigrid level; a level also ends "
         "early when the energy stops changing."));
  solverForm->addRow(tr("Iterations per level"), iterations_);

  precisionBox_ = new QComboBox(solverGroup);
  precisionBox_->setObjectName(QStringLiteral("precision"));
  precisionBox_->addItem(QStringLiteral("fp32"), static_cast<int>(Precision::FP32));
  precisionBox_->addItem(QStringLiteral("fp16"), static_cast<int>(Precision::FP16));
  precisionBox_->setToolTip(
      tr("Storage precision of the fields (arithmetic is always fp32). fp16 halves the memory so "
         "that larger volumes fit, with negligible visual difference; changing it reloads the "
         "scene."));
  solverForm->addRow(tr("Precision"), precisionBox_);
  precisionNote_ = new QLabel(tr("Changing the precision reloads the scene."), solverGroup);
  precisionNote_->setWordWrap(true);
  precisionNote_->setEnabled(false);
  solverForm->addRow(QString(), precisionNote_);
  layout->addWidget(solverGroup);

  reset_ = new QPushButton(tr("Reset to defaults"), this);
  reset_->setObjectName(QStringLiteral("reset"));
  reset_->setToolTip(tr("Restore the library's default optimisation settings."));
  layout->addWidget(reset_);

  // --- Run controls ---
  auto* runGroup = new QGroupBox(tr("Optimisation"), this);
  auto* runLayout = new QVBoxLayout(runGroup);
  run_ = new QPushButton(runGroup);
  run_->setObjectName(QStringLiteral("run"));
  run_->setCheckable(true);
  run_->setToolTip(
      tr("Start or pause the optimisation. While it runs it follows the camera, warm-started "
         "from the current result."));
  freeze_ = new QPushButton(tr("Freeze this result"), runGroup);
  freeze_->setObjectName(QStringLiteral("freeze"));
  freeze_->setCheckable(true);
  freeze_->setToolTip(
      tr("Keep the current optimised extinction and surfaces fixed while the camera moves, "
         "instead of re-optimising for each view."));
  restart_ = new QPushButton(tr("Restart from transfer function"), runGroup);
  restart_->setObjectName(QStringLiteral("restart"));
  restart_->setToolTip(
      tr("Discard the optimised result and start again from the transfer function's extinction "
         "and the original surfaces, coarse to fine."));
  runLayout->addWidget(run_);
  runLayout->addWidget(freeze_);
  runLayout->addWidget(restart_);
  layout->addWidget(runGroup);
  layout->addStretch(1);

  showSettings();
  updateRunText();

  for (QDoubleSpinBox* box : {rho_, q_, r_, lambda_, learningRate_})
    connect(box, &QDoubleSpinBox::valueChanged, this, &OptimizationPanel::onEdited);
  for (QSpinBox* box : {levels_, iterations_, redistance_})
    connect(box, &QSpinBox::valueChanged, this, &OptimizationPanel::onEdited);
  connect(optimizer_, &QComboBox::currentIndexChanged, this, &OptimizationPanel::onEdited);
  connect(integrator_, &QComboBox::currentIndexChanged, this, &OptimizationPanel::onEdited);
  connect(rhoAuto_, &QCheckBox::toggled, this, [this](bool) {
    rho_->setEnabled(!rhoAuto_->isChecked());
    onEdited();
  });
  connect(precisionBox_, &QComboBox::currentIndexChanged, this, [this](int) {
    if (updating_) return;
    precision_ = static_cast<Precision>(precisionBox_->currentData().toInt());
    emit precisionChangeRequested(precision_);
  });
  connect(reset_, &QPushButton::clicked, this, &OptimizationPanel::resetToDefaults);
  connect(run_, &QPushButton::toggled, this, [this](bool on) {
    updateRunText();
    emit runToggled(on);
  });
  connect(freeze_, &QPushButton::toggled, this, &OptimizationPanel::freezeToggled);
  connect(restart_, &QPushButton::clicked, this, &OptimizationPanel::restartRequested);
}

void OptimizationPanel::setSettings(const ExtinctionSettings& extinction,
                                    const LevelSetSettings& levelSet, Precision precision) {
  extinction_ = extinction;
  levelSet_ = levelSet;
  precision_ = precision;
  showSettings();
}

void OptimizationPanel::showSettings() {
  updating_ = true;
  const QSignalBlocker b0(rhoAuto_), b1(rho_), b2(q_), b3(r_), b4(lambda_), b5(learningRate_),
      b6(optimizer_), b7(levels_), b8(iterations_), b9(redistance_), b10(precisionBox_),
      b11(integrator_);
  const bool autoRho = extinction_.rho < 0.f;
  rhoAuto_->setChecked(autoRho);
  if (!autoRho) rho_->setValue(static_cast<double>(extinction_.rho));
  rho_->setEnabled(!autoRho);
  q_->setValue(static_cast<double>(extinction_.q));
  r_->setValue(static_cast<double>(extinction_.r));
  lambda_->setValue(static_cast<double>(levelSet_.lambda));
  learningRate_->setValue(static_cast<double>(extinction_.learningRate));
  optimizer_->setCurrentIndex(optimizer_->findData(static_cast<int>(extinction_.optimizer)));
  levels_->setValue(extinction_.levels);
  iterations_->setValue(extinction_.maxIterationsPerLevel);
  redistance_->setValue(levelSet_.redistanceIterations);
  integrator_->setCurrentIndex(integrator_->findData(levelSet_.semiImplicit ? 1 : 0));
  precisionBox_->setCurrentIndex(precisionBox_->findData(static_cast<int>(precision_)));
  updating_ = false;
}

void OptimizationPanel::readForm() {
  extinction_.rho = rhoAuto_->isChecked() ? -1.f : static_cast<float>(rho_->value());
  extinction_.q = static_cast<float>(q_->value());
  extinction_.r = static_cast<float>(r_->value());
  levelSet_.lambda = static_cast<float>(lambda_->value());
  extinction_.learningRate = static_cast<float>(learningRate_->value());
  extinction_.optimizer = static_cast<OptimizerKind>(optimizer_->currentData().toInt());
  extinction_.levels = levels_->value();
  extinction_.maxIterationsPerLevel = iterations_->value();
  levelSet_.redistanceIterations = redistance_->value();
  levelSet_.semiImplicit = integrator_->currentData().toInt() != 0;
}

void OptimizationPanel::onEdited() {
  if (updating_) return;
  readForm();
  emit settingsEdited(extinction_, levelSet_);
}

ExtinctionSettings OptimizationPanel::extinctionSettings() const {
  return extinction_;
}
LevelSetSettings OptimizationPanel::levelSetSettings() const {
  return levelSet_;
}
Precision OptimizationPanel::precision() const {
  return precision_;
}
bool OptimizationPanel::isRunning() const {
  return run_->isChecked();
}
bool OptimizationPanel::isFrozen() const {
  return freeze_->isChecked();
}

void OptimizationPanel::setRunning(bool running) {
  const QSignalBlocker block(run_);
  run_->setChecked(running);
  updateRunText();
}

void OptimizationPanel::setFrozen(bool frozen) {
  const QSignalBlocker block(freeze_);
  freeze_->setChecked(frozen);
}

void OptimizationPanel::resetToDefaults() {
  extinction_ = ExtinctionSettings{};
  levelSet_ = LevelSetSettings{};
  showSettings();
  emit settingsEdited(extinction_, levelSet_);
}

void OptimizationPanel::updateRunText() {
  run_->setText(run_->isChecked() ? tr("Pause optimisation") : tr("Run optimisation"));
}

}  // namespace visopt::ws
