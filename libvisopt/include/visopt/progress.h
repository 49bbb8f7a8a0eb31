#pragma once

#include <functional>
#include <string>

namespace visopt {

// Long work calls this with a fraction in [0, 1] and a short stage name; returning false asks
// the work to stop, which it does by throwing Error(ErrorKind::Cancelled).
using ProgressCallback = std::function<bool(float fraction, const std::string& stage)>;

}  // namespace visopt
