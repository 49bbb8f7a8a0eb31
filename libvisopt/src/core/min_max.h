// fmaxf / fminf without their NaN rules: one instruction each on the CPU (g++ calls libm for
// fmaxf unless math is relaxed), so hot loops stay branch-free and vectorise. maxOf(NaN, b) is b,
// which also keeps a NaN coordinate from reaching an index.
#pragma once

#include "core/hd.h"

namespace visopt {

VISOPT_HD VISOPT_INLINE float maxOf(float a, float b) {
  return a > b ? a : b;
}
VISOPT_HD VISOPT_INLINE float minOf(float a, float b) {
  return a < b ? a : b;
}

}  // namespace visopt
