#pragma once

#include <cstddef>
#include <string>

namespace visopt {

// Storage precision of a field. Arithmetic is always fp32; fp16 only halves storage.
enum class Precision { FP32, FP16 };

inline size_t bytesPerValue(Precision p) {
  return p == Precision::FP16 ? 2 : 4;
}
inline const char* toString(Precision p) {
  return p == Precision::FP16 ? "fp16" : "fp32";
}
// Throws Error(Usage) for anything but "fp32" or "fp16".
Precision parsePrecision(const std::string& text);

}  // namespace visopt
