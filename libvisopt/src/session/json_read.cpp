#include "session/json_read.h"

#include <charconv>
#include <cmath>

#include "visopt/error.h"

namespace visopt::session {

void Where::fail(const std::string& problem) const {
  throwBadInput(origin, path.empty() ? problem : path + ": " + problem);
}

void expectObject(const nlohmann::json& j, const Where& where) {
  if (!j.is_object()) where.fail("expected an object");
}

void expectArray(const nlohmann::json& j, const Where& where) {
  if (!j.is_array()) where.fail("expected an array");
}

void readValue(const nlohmann::json& j, double& out, const Where& where) {
  if (!j.is_number()) where.fail("expected a number");
  out = j.get<double>();
  if (!std::isfinite(out)) where.fail("expected a finite number");
}

void readValue(const nlohmann::json& j, float& out, const Where& where) {
  double v;
  readValue(j, v, where);
  if (std::abs(v) > 3.4e38) where.fail("number out of range");
  out = static_cast<float>(v);
}

void readValue(const nlohmann::json& j, int& out, const Where& where) {
  if (!j.is_number_integer()) where.fail("expected an integer");
  const int64_t v = j.is_number_unsigned() && j.get<uint64_t>() > uint64_t(INT64_MAX)
                        ? INT64_MAX
                        : j.get<int64_t>();
  if (v < INT32_MIN || v > INT32_MAX) where.fail("integer out of range");
  out = static_cast<int>(v);
}

void readValue(const nlohmann::json& j, uint32_t& out, const Where& where) {
  if (!j.is_number_unsigned() || j.get<uint64_t>() > UINT32_MAX)
    where.fail("expected an integer in [0, 4294967295]");
  out = static_cast<uint32_t>(j.get<uint64_t>());
}

void readValue(const nlohmann::json& j, bool& out, const Where& where) {
  if (!j.is_boolean()) where.fail("expected true or false");
  out = j.get<bool>();
}

void readValue(const nlohmann::json& j, std::string& out, const Where& where) {
  if (!j.is_string()) where.fail("expected a string");
  out = j.get<std::string>();
}

void readValue(const nlohmann::json& j, glm::vec3& out, const Where& where) {
  if (!j.is_array() || j.size() != 3) where.fail("expected 3 numbers");
  for (int i = 0; i < 3; ++i) readValue(j[size_t(i)], out[i], where.index(size_t(i)));
}

void readValue(const nlohmann::json& j, glm::dvec2& out, const Where& where) {
  if (!j.is_array() || j.size() != 2) where.fail("expected 2 numbers");
  for (int i = 0; i < 2; ++i) readValue(j[size_t(i)], out[i], where.index(size_t(i)));
}

OrderedJson toJson(float v) {
  if (!std::isfinite(v)) return nullptr;  // never written by visopt; reads back as an error
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v);
  double d = v;
  std::from_chars(buf, res.ptr, d);  // locale-independent, unlike strtod
  return d;
}

OrderedJson toJson(const glm::vec3& v) {
  return {toJson(v.x), toJson(v.y), toJson(v.z)};
}

}  // namespace visopt::session
