#include "visopt/precision.h"

#include "visopt/error.h"

namespace visopt {

Precision parsePrecision(const std::string& text) {
  if (text == "fp32") return Precision::FP32;
  if (text == "fp16") return Precision::FP16;
  throw Error(ErrorKind::Usage, "unknown precision '" + text + "' (expected fp32 or fp16)");
}

}  // namespace visopt
