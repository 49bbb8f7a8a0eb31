// Scalar types a volume file may hold, their names as visopt reports them ("uint8", "int16",
// "float32", ...), their sizes, and a dispatcher from the runtime type to a typed callable.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace visopt::io {

enum class ScalarType {
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Int64,
  UInt64,
  Float32,
  Float64
};

const char* scalarTypeName(ScalarType type);
size_t scalarTypeSize(ScalarType type);
// Parses the names above plus common aliases ("short", "float", "double", "uchar", ...).
std::optional<ScalarType> parseScalarTypeName(const std::string& name);

// Calls f(T{}) with T the C++ type of `type`.
template <class F>
decltype(auto) visitScalarType(ScalarType type, F&& f) {
  switch (type) {
    case ScalarType::Int8:
      return f(int8_t{});
    case ScalarType::UInt8:
      return f(uint8_t{});
    case ScalarType::Int16:
      return f(int16_t{});
    case ScalarType::UInt16:
      return f(uint16_t{});
    case ScalarType::Int32:
      return f(int32_t{});
    case ScalarType::UInt32:
      return f(uint32_t{});
    case ScalarType::Int64:
      return f(int64_t{});
    case ScalarType::UInt64:
      return f(uint64_t{});
    case ScalarType::Float32:
      return f(float{});
    case ScalarType::Float64:
      break;
  }
  return f(double{});
}

}  // namespace visopt::io
