// The panels' numeric fields: spin boxes that report one edit per Enter or focus change.
#pragma once

#include <QDoubleSpinBox>
#include <QSpinBox>
#include <QString>

namespace visopt::ws {

inline QDoubleSpinBox* makeDoubleBox(QWidget* parent, const char* name, double lo, double hi,
                                     int decimals, double step) {
  auto* box = new QDoubleSpinBox(parent);
  box->setObjectName(QString::fromLatin1(name));
  box->setRange(lo, hi);
  box->setDecimals(decimals);
  box->setSingleStep(step);
  box->setKeyboardTracking(false);  // one edit per Enter / focus change, not per keystroke
  return box;
}

}  // namespace visopt::ws
