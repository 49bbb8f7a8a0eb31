#include "visopt/error.h"
#include "visopt/optimization.h"

namespace visopt {

OptimizerKind parseOptimizerKind(const std::string& text) {
  if (text == "ademamix") return OptimizerKind::AdEMAMix;
  if (text == "adam") return OptimizerKind::Adam;
  throw Error(ErrorKind::Usage, "unknown optimizer '" + text + "' (expected ademamix or adam)");
}

const char* toString(OptimizerKind kind) {
  return kind == OptimizerKind::AdEMAMix ? "ademamix" : "adam";
}

}  // namespace visopt
