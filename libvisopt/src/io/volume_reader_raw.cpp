// Raw scalars described by a JSON sidecar: FILE.raw with FILE.raw.json or FILE.json next to it.
//   {"dims":[x,y,z], "type":"int16", "spacing":[sx,sy,sz], "origin":[ox,oy,oz],
//    "endian":"little"|"big", "headerBytes":0,
//    "direction":[9 numbers, row-major; column c is the world direction of index axis c]}
// dims and type are required; the rest defaults to unit spacing, zero origin, little endian, no
// header, identity direction. Data is x fastest (linear index (k*ny + j)*nx + i).
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/file_util.h"
#include "io/volume_source.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

using nlohmann::json;

std::string findSidecar(const std::string& path) {
  std::error_code ec;
  std::string candidate = path + ".json";
  if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
  std::filesystem::path p(path);
  candidate = p.replace_extension(".json").string();
  if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
  throwBadInput(path, "no JSON sidecar found (looked for " + fileName(path) + ".json and " +
                          fileName(candidate) + ")");
}

template <size_t N, class T>
std::array<T, N> numberArray(const std::string& sidecar, const json& doc, const char* key,
                             std::array<T, N> fallback, bool required = false) {
  if (!doc.contains(key)) {
    if (required) throwBadInput(sidecar, std::string("missing \"") + key + "\"");
    return fallback;
  }
  const json& v = doc[key];
  if (!v.is_array() || v.size() != N)
    throwBadInput(sidecar, std::string("\"") + key + "\" must be an array of " + std::to_string(N) +
                               " numbers");
  std::array<T, N> out{};
  for (size_t i = 0; i < N; ++i) {
    if (!v[i].is_number())
      throwBadInput(sidecar, std::string("\"") + key + "\" must hold numbers only");
    if constexpr (std::is_integral_v<T>) {
      if (!v[i].is_number_integer())
        throwBadInput(sidecar, std::string("\"") + key + "\" must hold integers");
      out[i] = v[i].is_number_unsigned() && v[i].get<uint64_t>() > uint64_t(INT64_MAX)
                   ? INT64_MAX
                   : v[i].get<T>();
    } else {
      out[i] = v[i].get<T>();
    }
  }
  return out;
}

}  // namespace

VolumeLayout rawLayout(const std::string& path, bool wholeInMemory) {
  checkedFileSize(path);  // missing / empty data file first: the clearest message
  const std::string sidecar = findSidecar(path);
  json doc;
  {
    std::ifstream in(sidecar);
    if (!in) throwBadInput(sidecar, "cannot open sidecar");
    try {
      doc = json::parse(in);
    } catch (const json::exception& e) {
      std::string what = e.what();
      throwBadInput(sidecar, "invalid JSON sidecar: " + what.substr(0, what.find('\n')));
    }
  }
  if (!doc.is_object()) throwBadInput(sidecar, "sidecar must be a JSON object");

  VolumeHeader header;
  header.dims = numberArray<3, int64_t>(sidecar, doc, "dims", {0, 0, 0}, true);
  if (!doc.contains("type") || !doc["type"].is_string())
    throwBadInput(sidecar,
                  "missing \"type\" (int8, uint8, int16, uint16, int32, uint32, float32, "
                  "float64)");
  const std::string typeName = doc["type"].get<std::string>();
  auto type = parseScalarTypeName(typeName);
  if (!type) throwBadInput(sidecar, "unsupported scalar type \"" + typeName + "\"");
  header.type = *type;
  header.spacing = numberArray<3, double>(sidecar, doc, "spacing", {1.0, 1.0, 1.0});
  header.origin = numberArray<3, double>(sidecar, doc, "origin", {0.0, 0.0, 0.0});
  if (doc.contains("direction")) {
    auto d = numberArray<9, double>(sidecar, doc, "direction", {});
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) header.direction[c][r] = d[size_t(r * 3 + c)];
  }
  if (doc.contains("components")) {
    if (!doc["components"].is_number_integer())
      throwBadInput(sidecar, "\"components\" must be an integer");
    header.components = doc["components"].get<int>();
  }
  bool bigEndian = false;
  if (doc.contains("endian")) {
    std::string e = doc["endian"].is_string() ? doc["endian"].get<std::string>() : "";
    if (e == "big")
      bigEndian = true;
    else if (e != "little")
      throwBadInput(sidecar, "\"endian\" must be \"little\" or \"big\"");
  }
  int64_t headerBytes = 0;
  if (doc.contains("headerBytes")) {
    if (!doc["headerBytes"].is_number_integer() || doc["headerBytes"].get<int64_t>() < 0)
      throwBadInput(sidecar, "\"headerBytes\" must be a non-negative integer");
    headerBytes = doc["headerBytes"].get<int64_t>();
  }

  VolumeLayout layout;
  layout.format = "raw";
  layout.headerPath = sidecar;
  layout.header = header;
  layout.grid = checkHeader(sidecar, header, wholeInMemory);
  layout.dataPath = path;
  layout.dataOffset = uint64_t(headerBytes);
  layout.bigEndian = bigEndian;
  return layout;
}

LoadedVolume readRawWithSidecar(const std::string& path, const ProgressCallback& progress) {
  VolumeLayout layout = rawLayout(path);
  LoadedVolume out;
  out.format = layout.format;
  out.grid = layout.grid;
  reportProgress(progress, path, 0.1f, "header");
  out.scalars = readPayload(path, layout.dataOffset, layout.header.type, out.grid.voxelCount(),
                            layout.bigEndian);
  return out;
}

}  // namespace visopt::io
