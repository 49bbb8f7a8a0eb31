#include "io/scalar_type.h"

#include <algorithm>
#include <cctype>
#include <map>

namespace visopt::io {

const char* scalarTypeName(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
      return "int8";
    case ScalarType::UInt8:
      return "uint8";
    case ScalarType::Int16:
      return "int16";
    case ScalarType::UInt16:
      return "uint16";
    case ScalarType::Int32:
      return "int32";
    case ScalarType::UInt32:
      return "uint32";
    case ScalarType::Int64:
      return "int64";
    case ScalarType::UInt64:
      return "uint64";
    case ScalarType::Float32:
      return "float32";
    case ScalarType::Float64:
      break;
  }
  return "float64";
}

size_t scalarTypeSize(ScalarType type) {
  return visitScalarType(type, [](auto v) { return sizeof(v); });
}

std::optional<ScalarType> parseScalarTypeName(const std::string& name) {
  static const std::map<std::string, ScalarType> names = {
      {"int8", ScalarType::Int8},
      {"char", ScalarType::Int8},
      {"signed char", ScalarType::Int8},
      {"uint8", ScalarType::UInt8},
      {"uchar", ScalarType::UInt8},
      {"unsigned char", ScalarType::UInt8},
      {"int16", ScalarType::Int16},
      {"short", ScalarType::Int16},
      {"uint16", ScalarType::UInt16},
      {"ushort", ScalarType::UInt16},
      {"unsigned short", ScalarType::UInt16},
      {"int32", ScalarType::Int32},
      {"int", ScalarType::Int32},
      {"uint32", ScalarType::UInt32},
      {"uint", ScalarType::UInt32},
      {"unsigned int", ScalarType::UInt32},
      {"int64", ScalarType::Int64},
      {"uint64", ScalarType::UInt64},
      {"float32", ScalarType::Float32},
      {"float", ScalarType::Float32},
      {"float64", ScalarType::Float64},
      {"double", ScalarType::Float64},
  };
  std::string key = name;
  std::transform(key.begin(), key.end(), key.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  auto it = names.find(key);
  if (it == names.end()) return std::nullopt;
  return it->second;
}

}  // namespace visopt::io
