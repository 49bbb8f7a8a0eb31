#include "panels/status_summary.h"

#include <cmath>

#include <QStringList>

namespace visopt::ws {

namespace {
const QChar kMinus(0x2212);
const QString kSeparator = QStringLiteral(" \u00b7 ");
}  // namespace

QString formatSignificant(double value) {
  if (value == 0.0) return QStringLiteral("0");
  if (!std::isfinite(value))
    return std::isnan(value) ? QStringLiteral("nan") : QStringLiteral("inf");
  const bool negative = value < 0.0;
  const double magnitude = std::fabs(value);
  QString text;
  if (magnitude >= 0.01 && magnitude < 10000.0) {
    // Fixed notation with three significant digits (more digits left of the point stay).
    const int digits = static_cast<int>(std::floor(std::log10(magnitude)));
    const int decimals = digits >= 2 ? 0 : 2 - digits;
    text = QString::number(magnitude, 'f', decimals);
  } else {
    int exponent = static_cast<int>(std::floor(std::log10(magnitude)));
    double mantissa = magnitude / std::pow(10.0, exponent);
    // Rounding to two decimals may carry into the next power of ten (9.996e6 -> 1.00e7).
    if (std::round(mantissa * 100.0) >= 1000.0) {
      mantissa /= 10.0;
      ++exponent;
    }
    text = QString::number(mantissa, 'f', 2) + QLatin1Char('e');
    if (exponent < 0) text += kMinus;
    text += QString::number(std::abs(exponent));
  }
  return negative ? kMinus + text : text;
}

QString formatBytes(size_t bytes) {
  const double b = static_cast<double>(bytes);
  if (b < 1e9)
    return QString::number(static_cast<qlonglong>(std::llround(b / 1e6))) + QStringLiteral(" MB");
  return QString::number(b / 1e9, 'f', 2) + QStringLiteral(" GB");
}

QString formatStatus(const visopt::IterationStats* stats, double fps, size_t bytes, bool frozen,
                     bool running) {
  QStringList parts;
  if (stats) {
    parts << QStringLiteral("level %1").arg(stats->level)
          << QStringLiteral("it %1").arg(stats->iteration)
          << QStringLiteral("E ") + formatSignificant(stats->energy())
          << QStringLiteral("V ") + QString::number(stats->visibilityView, 'f', 2);
  }
  if (fps > 0.0) parts << QString::number(fps, 'f', 1) + QStringLiteral(" fps");
  parts << formatBytes(bytes);
  parts << (frozen    ? QStringLiteral("frozen")
            : running ? QStringLiteral("running")
                      : QStringLiteral("paused"));
  return parts.join(kSeparator);
}

}  // namespace visopt::ws
