// The optimisation panel: a form over ExtinctionSettings and LevelSetSettings (Himmler & Günther
// 2026, Eqs. 10-14 and 23), the storage precision, and the run / freeze / restart controls. It
// holds no numerics: every edit emits the complete settings, which the main window passes to the
// engine.
#pragma once

#include <QMetaType>
#include <QWidget>

#include <visopt/level_set.h>
#include <visopt/optimization.h>
#include <visopt/precision.h>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QPushButton;
class QSpinBox;

namespace visopt::ws {

class OptimizationPanel : public QWidget {
  Q_OBJECT
 public:
  explicit OptimizationPanel(QWidget* parent = nullptr);

  // Shows `extinction`, `levelSet` and `precision` in the form; emits nothing. Fields the form
  // does not show (beta1, tolerance, cfl, ...) are kept and returned unchanged by the getters.
  void setSettings(const ExtinctionSettings& extinction, const LevelSetSettings& levelSet,
                   Precision precision);
  ExtinctionSettings extinctionSettings() const;
  LevelSetSettings levelSetSettings() const;
  Precision precision() const;
  bool isRunning() const;
  bool isFrozen() const;

 public slots:
  // Reflect the engine's state in the buttons; emit nothing.
  void setRunning(bool running);
  void setFrozen(bool frozen);
  // Default-constructed ExtinctionSettings and LevelSetSettings (the precision is left alone: it
  // needs a reload); emits settingsEdited.
  void resetToDefaults();

 signals:
  void settingsEdited(const visopt::ExtinctionSettings& extinction,
                      const visopt::LevelSetSettings& levelSet);
  // The user picked another storage precision; the scene must be reloaded for it to apply.
  void precisionChangeRequested(visopt::Precision precision);
  void runToggled(bool running);
  void freezeToggled(bool frozen);
  void restartRequested();

 private:
  void showSettings();  // extinction_/levelSet_/precision_ -> widgets, no signals
  void readForm();      // widgets -> extinction_/levelSet_
  void onEdited();
  void updateRunText();

  ExtinctionSettings extinction_;
  LevelSetSettings levelSet_;
  Precision precision_ = Precision::FP32;
  bool updating_ = false;

  QCheckBox* rhoAuto_ = nullptr;
  QDoubleSpinBox* rho_ = nullptr;
  QDoubleSpinBox* q_ = nullptr;
  QDoubleSpinBox* r_ = nullptr;
  QDoubleSpinBox* lambda_ = nullptr;
  QDoubleSpinBox* learningRate_ = nullptr;
  QComboBox* optimizer_ = nullptr;
  QComboBox* integrator_ = nullptr;  // LevelSetSettings::semiImplicit
  QSpinBox* levels_ = nullptr;
  QSpinBox* iterations_ = nullptr;
  QSpinBox* redistance_ = nullptr;
  QComboBox* precisionBox_ = nullptr;
  QLabel* precisionNote_ = nullptr;
  QPushButton* reset_ = nullptr;
  QPushButton* run_ = nullptr;
  QPushButton* freeze_ = nullptr;
  QPushButton* restart_ = nullptr;
};

}  // namespace visopt::ws

// Guarded so that other workstation headers can declare the same library types.
#ifndef VISOPT_WS_METATYPE_EXTINCTION_SETTINGS
#define VISOPT_WS_METATYPE_EXTINCTION_SETTINGS
Q_DECLARE_METATYPE(visopt::ExtinctionSettings)
#endif
#ifndef VISOPT_WS_METATYPE_LEVEL_SET_SETTINGS
#define VISOPT_WS_METATYPE_LEVEL_SET_SETTINGS
Q_DECLARE_METATYPE(visopt::LevelSetSettings)
#endif
#ifndef VISOPT_WS_METATYPE_PRECISION
#define VISOPT_WS_METATYPE_PRECISION
Q_DECLARE_METATYPE(visopt::Precision)
#endif
