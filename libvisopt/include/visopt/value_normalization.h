// The map from a value in the data's units to the normalised [0, 1] a volume's field stores:
// (value - lo) / (hi - lo), clamped. Every finite range works, including those where the plain
// formula breaks: a subnormal span (1 / span overflows, and 0 * inf is NaN) and a span beyond
// double's range (hi - lo overflows). A NaN value maps to 0, so no NaN reaches a field.
#pragma once

#include <cmath>

namespace visopt {

class ValueNormalization {
 public:
  ValueNormalization(double lo, double hi) {
    if (!(hi > lo)) return;  // one value (or no range): everything maps to 0
    if (std::isfinite(hi - lo)) {
      shift_ = lo;
      span_ = hi - lo;
    } else {  // halve both ends first: finite halves never overflow when subtracted
      halve_ = true;
      shift_ = 0.5 * lo;
      span_ = 0.5 * hi - 0.5 * lo;
    }
  }

  float operator()(double value) const {
    if (!(span_ > 0.0)) return 0.f;
    const double t = ((halve_ ? 0.5 * value : value) - shift_) / span_;
    return t >= 0.0 ? (t <= 1.0 ? static_cast<float>(t) : 1.f) : 0.f;  // a NaN fails t >= 0
  }

 private:
  double shift_ = 0.0, span_ = 0.0;
  bool halve_ = false;
};

}  // namespace visopt
