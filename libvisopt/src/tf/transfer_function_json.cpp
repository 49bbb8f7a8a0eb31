// The visopt transfer-function file format (see visopt/transfer_function.h), dispatch to the
// ParaView importer, and atomic file load/save.
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <nlohmann/json.hpp>

#include "tf/json_read.h"
#include "visopt/error.h"
#include "visopt/transfer_function.h"

namespace visopt {

namespace {

constexpr const char* kFormat = "visopt-transfer-function";
constexpr int kVersion = 1;
constexpr std::uintmax_t kMaxFileBytes = 64u << 20;

// Shortest text that reads back to the same double / float.
template <class T>
std::string shortest(T v, const std::string& name) {
  if (!std::isfinite(v))
    throw Error(ErrorKind::BadInput,
                "transfer function '" + name + "': cannot write a non-finite number");
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}

// parse_error messages start with "[json.exception.parse_error.101] "; keep the readable part.
std::string jsonMessage(const nlohmann::json::exception& e) {
  std::string msg = e.what();
  if (!msg.empty() && msg.front() == '[') {
    auto close = msg.find("] ");
    if (close != std::string::npos) msg = msg.substr(close + 2);
  }
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  return msg;
}

TransferFunction fromVisopt(const nlohmann::json& doc, const std::string& origin) {
  using tfjson::readNumber;
  if (!doc["format"].is_string() || doc["format"].get<std::string>() != kFormat)
    throwBadInput(origin, std::string("\"format\" is not \"") + kFormat + "\"");
  if (doc.contains("version")) {
    const double version = readNumber(doc["version"], origin, "\"version\"");
    if (version > kVersion)
      throwBadInput(origin, "format version " + shortest(version, "") +
                                " is newer than this visopt reads (" + std::to_string(kVersion) +
                                ")");
  }
  TransferFunction tf;
  if (doc.contains("name")) {
    if (!doc["name"].is_string()) throwBadInput(origin, "\"name\" is not a string");
    tf.name = doc["name"].get<std::string>();
  }
  if (doc.contains("unitDistance"))
    tf.unitDistance =
        static_cast<float>(readNumber(doc["unitDistance"], origin, "\"unitDistance\""));
  for (const char* key : {"opacity", "color"}) {
    if (!doc.contains(key)) throwBadInput(origin, std::string("missing \"") + key + "\"");
    if (!doc[key].is_array()) throwBadInput(origin, std::string("\"") + key + "\" is not a list");
  }
  const auto& opacity = doc["opacity"];
  for (size_t i = 0; i < opacity.size(); ++i) {
    const std::string what = "opacity[" + std::to_string(i) + "]";
    const auto& p = opacity[i];
    if (!p.is_array() || p.size() != 2) throwBadInput(origin, what + ": expected [value, alpha]");
    tf.opacity.push_back(OpacityPoint{readNumber(p[0], origin, what),
                                      static_cast<float>(readNumber(p[1], origin, what))});
  }
  const auto& color = doc["color"];
  for (size_t i = 0; i < color.size(); ++i) {
    const std::string what = "color[" + std::to_string(i) + "]";
    const auto& p = color[i];
    if (!p.is_array() || p.size() != 4) throwBadInput(origin, what + ": expected [value, r, g, b]");
    glm::vec3 rgb;
    for (int c = 0; c < 3; ++c)
      rgb[c] = static_cast<float>(readNumber(p[static_cast<size_t>(c + 1)], origin, what));
    tf.color.push_back(ColorPoint{readNumber(p[0], origin, what), rgb});
  }
  tf.validate(origin);
  return tf;
}

}  // namespace

namespace tfjson {

double readNumber(const nlohmann::json& j, const std::string& origin, const std::string& what) {
  if (!j.is_number()) throwBadInput(origin, what + ": expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throwBadInput(origin, what + ": number is not finite");
  return v;
}

}  // namespace tfjson

std::string TransferFunction::toJson() const {
  std::ostringstream out;
  out << "{\n  \"format\": \"" << kFormat << "\",\n  \"version\": " << kVersion
      << ",\n  \"name\": " << nlohmann::json(name).dump()
      << ",\n  \"unitDistance\": " << shortest(unitDistance, name) << ",\n  \"opacity\": [";
  for (size_t i = 0; i < opacity.size(); ++i)
    out << (i ? ",\n    [" : "\n    [") << shortest(opacity[i].value, name) << ", "
        << shortest(opacity[i].opacity, name) << "]";
  out << "\n  ],\n  \"color\": [";
  for (size_t i = 0; i < color.size(); ++i) {
    const auto& p = color[i];
    out << (i ? ",\n    [" : "\n    [") << shortest(p.value, name) << ", "
        << shortest(p.rgb.r, name) << ", " << shortest(p.rgb.g, name) << ", "
        << shortest(p.rgb.b, name) << "]";
  }
  out << "\n  ]\n}\n";
  return out.str();
}

TransferFunction TransferFunction::fromJson(const std::string& json, const std::string& origin) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json);
  } catch (const nlohmann::json::exception& e) {
    throwBadInput(origin, "invalid JSON: " + jsonMessage(e));
  }
  try {
    if (doc.is_array() || (doc.is_object() && doc.contains("RGBPoints")))
      return tfjson::fromParaView(doc, origin);
    if (doc.is_object() && doc.contains("format")) return fromVisopt(doc, origin);
  } catch (const nlohmann::json::exception& e) {
    throwBadInput(origin, "unexpected JSON structure: " + jsonMessage(e));
  }
  throwBadInput(origin,
                "neither a visopt transfer function nor a ParaView colour map (no \"format\" or "
                "\"RGBPoints\")");
}

TransferFunction TransferFunction::load(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throwBadInput(path, "no such file");
  if (fs::is_directory(st)) throwBadInput(path, "is a directory, not a transfer-function file");
  // A device or FIFO has no size and would be read without end (/dev/zero) or block.
  if (!fs::is_regular_file(st))
    throwBadInput(path, "is a device, pipe or socket, not a transfer-function file");
  const auto bytes = fs::file_size(path, ec);
  if (ec) throwBadInput(path, "cannot read its size (" + ec.message() + ")");
  if (bytes > kMaxFileBytes) throwBadInput(path, "file too large for a transfer function");
  std::ifstream in(path, std::ios::binary);
  if (!in) throwBadInput(path, "cannot open for reading");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throwBadInput(path, "read error");
  TransferFunction tf = fromJson(text, path);
  if (tf.name.empty()) tf.name = fs::path(path).stem().string();
  return tf;
}

void TransferFunction::save(const std::string& path) const {
  namespace fs = std::filesystem;
  const std::string text = toJson();
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throwBadInput(path, "directory does not exist");
  // A temporary next to the target, so the final rename stays on one file system (atomic).
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  std::string tmpName = target.filename().string();
  tmpName.insert(0, 1, '.');
  tmpName.append(".tmp");
  tmpName.append(std::to_string(stamp));
  const fs::path tmp = dir / tmpName;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throwBadInput(path, "cannot create a temporary file in " + dir.string());
    out << text;
    out.flush();
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      throwBadInput(path, "write failed");
    }
  }
  if (std::rename(tmp.c_str(), target.c_str()) != 0) {
    fs::remove(tmp, ec);
    throwBadInput(path, "cannot replace the file");
  }
}

}  // namespace visopt
