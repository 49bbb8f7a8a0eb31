// NRRD (.nrrd with the data after the header, .nhdr with a detached "data file"). Encodings raw
// and gzip. Geometry from "space directions" (spacing = length of each axis vector, direction =
// its unit vector) and "space origin", or from "spacings" / "axis mins" without a space. The
// world frame is kept as the file states it (LPS or RAS alike). A non-spatial first axis
// (4 dimensions, or "kinds" vector/list/RGB...) means multi-component data and is refused.
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "io/file_util.h"
#include "io/text_header.h"
#include "io/volume_source.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

std::optional<ScalarType> nrrdType(std::string name) {
  static const std::map<std::string, ScalarType> types = {
      {"signed char", ScalarType::Int8},
      {"int8", ScalarType::Int8},
      {"int8_t", ScalarType::Int8},
      {"uchar", ScalarType::UInt8},
      {"unsigned char", ScalarType::UInt8},
      {"uint8", ScalarType::UInt8},
      {"uint8_t", ScalarType::UInt8},
      {"short", ScalarType::Int16},
      {"short int", ScalarType::Int16},
      {"signed short", ScalarType::Int16},
      {"signed short int", ScalarType::Int16},
      {"int16", ScalarType::Int16},
      {"int16_t", ScalarType::Int16},
      {"ushort", ScalarType::UInt16},
      {"unsigned short", ScalarType::UInt16},
      {"unsigned short int", ScalarType::UInt16},
      {"uint16", ScalarType::UInt16},
      {"uint16_t", ScalarType::UInt16},
      {"int", ScalarType::Int32},
      {"signed int", ScalarType::Int32},
      {"int32", ScalarType::Int32},
      {"int32_t", ScalarType::Int32},
      {"uint", ScalarType::UInt32},
      {"unsigned int", ScalarType::UInt32},
      {"uint32", ScalarType::UInt32},
      {"uint32_t", ScalarType::UInt32},
      {"longlong", ScalarType::Int64},
      {"long long", ScalarType::Int64},
      {"long long int", ScalarType::Int64},
      {"signed long long", ScalarType::Int64},
      {"signed long long int", ScalarType::Int64},
      {"int64", ScalarType::Int64},
      {"int64_t", ScalarType::Int64},
      {"ulonglong", ScalarType::UInt64},
      {"unsigned long long", ScalarType::UInt64},
      {"unsigned long long int", ScalarType::UInt64},
      {"uint64", ScalarType::UInt64},
      {"uint64_t", ScalarType::UInt64},
      {"float", ScalarType::Float32},
      {"double", ScalarType::Float64},
  };
  auto it = types.find(toLower(trim(name)));
  if (it == types.end()) return std::nullopt;
  return it->second;
}

// "(1,0,0) none (0,0.5,0)" -> vectors (empty for "none").
std::vector<std::vector<double>> parseVectors(const std::string& path, const std::string& text) {
  std::vector<std::vector<double>> out;
  size_t pos = 0;
  while (pos < text.size()) {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    if (pos >= text.size()) break;
    if (text.compare(pos, 4, "none") == 0) {
      out.emplace_back();
      pos += 4;
      continue;
    }
    if (text[pos] != '(') throwBadInput(path, "malformed vector list \"" + text + "\"");
    size_t close = text.find(')', pos);
    if (close == std::string::npos) throwBadInput(path, "malformed vector list \"" + text + "\"");
    std::string inner = text.substr(pos + 1, close - pos - 1);
    for (char& c : inner)
      if (c == ',') c = ' ';
    auto v = parseNumbers(inner);
    if (!v) throwBadInput(path, "malformed vector \"" + text.substr(pos, close - pos + 1) + "\"");
    out.push_back(*v);
    pos = close + 1;
  }
  return out;
}

}  // namespace

LoadedVolume readNrrd(const std::string& path, const ProgressCallback& progress) {
  checkedFileSize(path);
  const std::string text = readFilePrefix(path, 1 << 20);
  if (text.rfind("NRRD", 0) != 0) throwBadInput(path, "not a NRRD file (no NRRD magic)");

  std::map<std::string, std::string> fields;
  uint64_t dataOffset = 0;
  bool headerEnded = false;
  size_t pos = text.find('\n');
  pos = pos == std::string::npos ? text.size() : pos + 1;
  while (pos < text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) break;
    std::string line = text.substr(pos, eol - pos);
    pos = eol + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) {
      headerEnded = true;
      dataOffset = pos;
      break;
    }
    if (line[0] == '#') continue;
    size_t colon = line.find(": ");
    if (colon == std::string::npos) {
      if (line.find(":=") != std::string::npos) continue;  // key/value comments
      throwBadInput(path, "malformed NRRD header line \"" + line.substr(0, 40) + "\"");
    }
    fields[toLower(trim(line.substr(0, colon)))] = trim(line.substr(colon + 2));
  }
  const bool detached = fields.count("data file") || fields.count("datafile");
  if (!headerEnded && !detached) throwBadInput(path, "truncated: NRRD header has no end");

  auto typeIt = fields.find("type");
  if (typeIt == fields.end()) throwBadInput(path, "missing \"type\"");
  auto type = nrrdType(typeIt->second);
  if (!type) throwBadInput(path, "unsupported scalar type \"" + typeIt->second + "\"");

  auto sizesIt = fields.find("sizes");
  if (sizesIt == fields.end()) throwBadInput(path, "missing \"sizes\"");
  auto sizes = parseNumbers(sizesIt->second);
  if (!sizes || sizes->empty()) throwBadInput(path, "malformed \"sizes\"");
  size_t first = 0;  // first spatial axis
  VolumeHeader h;
  h.type = *type;
  std::vector<std::string> kinds;
  if (fields.count("kinds")) {
    std::istringstream k(fields["kinds"]);
    for (std::string s; k >> s;) kinds.push_back(toLower(s));
  }
  const bool firstAxisNonSpatial =
      sizes->size() == 4 || (!kinds.empty() && kinds[0] != "domain" && kinds[0] != "space" &&
                             kinds[0] != "time" && sizes->size() >= 3);
  if (firstAxisNonSpatial) {
    h.components = int(headerInteger(path, "sizes", (*sizes)[0], 0, 1 << 20));
    first = 1;
  }
  const size_t spatial = sizes->size() - first;
  if (spatial < 1 || spatial > 3)
    throwBadInput(path, "dimension " + std::to_string(sizes->size()) + " is not supported");
  h.dims = {1, 1, 1};
  for (size_t a = 0; a < spatial; ++a)
    h.dims[a] = headerInteger(path, "sizes", (*sizes)[first + a], 0, int64_t(1) << 40);

  if (fields.count("space directions")) {
    auto vectors = parseVectors(path, fields["space directions"]);
    if (vectors.size() != sizes->size())
      throwBadInput(path, "\"space directions\" does not match \"sizes\"");
    for (size_t a = 0; a < spatial; ++a) {
      const auto& v = vectors[first + a];
      if (v.size() != 3) throwBadInput(path, "\"space directions\" must hold 3D vectors");
      double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      h.spacing[a] = len;
      for (int r = 0; r < 3; ++r) h.direction[a][r] = len > 0 ? v[size_t(r)] / len : 0.0;
    }
  } else if (fields.count("spacings")) {
    auto s = parseNumbers(fields["spacings"]);  // "nan" entries for non-spatial axes fail here
    if (!s || s->size() != sizes->size()) throwBadInput(path, "malformed \"spacings\"");
    for (size_t a = 0; a < spatial; ++a) h.spacing[a] = (*s)[first + a];
  }
  if (fields.count("space origin")) {
    auto o = parseVectors(path, fields["space origin"]);
    if (o.size() != 1 || o[0].size() != 3) throwBadInput(path, "malformed \"space origin\"");
    for (int a = 0; a < 3; ++a) h.origin[size_t(a)] = o[0][size_t(a)];
  } else if (fields.count("axis mins")) {
    auto m = parseNumbers(fields["axis mins"]);
    if (m && m->size() == sizes->size())
      for (size_t a = 0; a < spatial; ++a) h.origin[a] = (*m)[first + a];
  }

  std::string encoding = toLower(fields.count("encoding") ? fields["encoding"] : "");
  if (encoding.empty()) throwBadInput(path, "missing \"encoding\"");
  const bool gzip = encoding == "gzip" || encoding == "gz";
  if (!gzip && encoding != "raw")
    throwBadInput(path, "unsupported NRRD encoding \"" + encoding + "\" (raw and gzip are)");
  const bool bigEndian = toLower(fields["endian"]) == "big";

  LoadedVolume out;
  out.format = "nrrd";
  out.grid = checkHeader(path, h);
  reportProgress(progress, path, 0.1f, "header");
  const size_t count = out.grid.voxelCount();

  std::string dataFile = path;
  if (detached) {
    std::string name = fields.count("data file") ? fields["data file"] : fields["datafile"];
    if (name.rfind("LIST", 0) == 0 || name.find(' ') != std::string::npos)
      throwBadInput(path, "data file \"" + name + "\": file lists are not supported");
    dataFile = siblingPath(path, name);
    dataOffset = 0;
    checkedFileSize(dataFile);
    if (fields.count("line skip")) {
      int lines = std::atoi(fields["line skip"].c_str());
      std::string prefix = readFilePrefix(dataFile, 1 << 20);
      size_t p = 0;
      for (int l = 0; l < lines && p != std::string::npos; ++l) {
        p = prefix.find('\n', p);
        if (p != std::string::npos) ++p;
      }
      if (p == std::string::npos)
        throwBadInput(dataFile, "truncated: fewer lines than \"line skip\"");
      dataOffset = p;
    }
  }
  if (fields.count("byte skip")) {
    long long skip = std::atoll(fields["byte skip"].c_str());
    if (skip >= 0) {
      dataOffset += uint64_t(skip);
    } else if (!gzip) {
      uint64_t size = checkedFileSize(dataFile), need = count * scalarTypeSize(h.type);
      if (size < need)
        throwBadInput(dataFile, "truncated: header describes " + std::to_string(need) +
                                    " bytes of data, file has only " + std::to_string(size));
      dataOffset = size - need;
    }
  }
  out.scalars = gzip ? readCompressedPayload(dataFile, dataOffset, h.type, count, bigEndian)
                     : readPayload(dataFile, dataOffset, h.type, count, bigEndian);
  return out;
}

}  // namespace visopt::io
