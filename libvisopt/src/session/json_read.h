// Reading and writing session JSON values with one-line BadInput errors that name the file and
// the key ("a.session: camera.eye: expected 3 numbers").
#pragma once

#include <cstdint>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace visopt::session {

// Where a value sits: the file and the key path inside it.
struct Where {
  std::string origin, path;
  Where key(const std::string& name) const {
    return {origin, path.empty() ? name : path + "." + name};
  }
  Where index(size_t i) const { return {origin, path + "[" + std::to_string(i) + "]"}; }
  [[noreturn]] void fail(const std::string& problem) const;
};

void expectObject(const nlohmann::json& j, const Where& where);
void expectArray(const nlohmann::json& j, const Where& where);

void readValue(const nlohmann::json& j, float& out, const Where& where);   // finite
void readValue(const nlohmann::json& j, double& out, const Where& where);  // finite
void readValue(const nlohmann::json& j, int& out, const Where& where);
void readValue(const nlohmann::json& j, uint32_t& out, const Where& where);
void readValue(const nlohmann::json& j, bool& out, const Where& where);
void readValue(const nlohmann::json& j, std::string& out, const Where& where);
void readValue(const nlohmann::json& j, glm::vec3& out, const Where& where);
void readValue(const nlohmann::json& j, glm::dvec2& out, const Where& where);

// Required / optional members of an object.
template <class T>
void readRequired(const nlohmann::json& j, const char* key, T& out, const Where& where) {
  auto it = j.find(key);
  if (it == j.end()) where.fail(std::string("missing \"") + key + "\"");
  readValue(*it, out, where.key(key));
}
template <class T>
void readOptional(const nlohmann::json& j, const char* key, T& out, const Where& where) {
  auto it = j.find(key);
  if (it != j.end()) readValue(*it, out, where.key(key));
}

// Floats are written as the shortest decimal that reads back to the same float (0.05, not
// 0.05000000074505806), so files stay readable and round trips stay exact.
// Written documents keep their keys in insertion order ("format" and "version" first).
using OrderedJson = nlohmann::ordered_json;
OrderedJson toJson(float v);
inline OrderedJson toJson(int v) {
  return v;
}
inline OrderedJson toJson(uint32_t v) {
  return v;
}
inline OrderedJson toJson(bool v) {
  return v;
}
OrderedJson toJson(const glm::vec3& v);

}  // namespace visopt::session
