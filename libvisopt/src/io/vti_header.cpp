#include "io/vti_header.h"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "io/file_util.h"
#include "io/text_header.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

// The XML part of a .vti lies before its appended data; headers are small.
constexpr size_t kMaxXmlBytes = size_t(16) << 20;

struct Tag {
  std::string name;
  std::map<std::string, std::string> attributes;
  size_t end = 0;  // just past '>'
};

// The next start tag named `name` at or after `from` (not a full XML parser: enough to read the
// attributes VTK's reader trusts; whatever else is malformed, expat refuses later).
std::optional<Tag> findTag(const std::string& path, const std::string& xml, const std::string& name,
                           size_t from, size_t until) {
  const std::string open = "<" + name;
  for (size_t at = xml.find(open, from); at != std::string::npos && at < until;
       at = xml.find(open, at + 1)) {
    const size_t after = at + open.size();
    if (after < xml.size() && !std::isspace(static_cast<unsigned char>(xml[after])) &&
        xml[after] != '>' && xml[after] != '/')
      continue;  // <PieceX is not <Piece
    const size_t close = xml.find('>', after);
    if (close == std::string::npos) throwBadInput(path, "truncated: <" + name + " is not closed");
    Tag tag;
    tag.name = name;
    tag.end = close + 1;
    size_t p = after;
    while (p < close) {
      while (p < close && (std::isspace(static_cast<unsigned char>(xml[p])) || xml[p] == '/')) ++p;
      if (p >= close) break;
      const size_t eq = xml.find('=', p);
      if (eq == std::string::npos || eq > close) break;
      const std::string key = trim(xml.substr(p, eq - p));
      size_t q = eq + 1;
      while (q < close && std::isspace(static_cast<unsigned char>(xml[q]))) ++q;
      if (q >= close || (xml[q] != '"' && xml[q] != '\'')) break;
      const size_t endQuote = xml.find(xml[q], q + 1);
      if (endQuote == std::string::npos || endQuote > close) break;
      tag.attributes[key] = xml.substr(q + 1, endQuote - q - 1);
      p = endQuote + 1;
    }
    return tag;
  }
  return std::nullopt;
}

std::vector<double> numbersOf(const std::string& path, const Tag& tag, const std::string& key,
                              size_t count) {
  auto it = tag.attributes.find(key);
  if (it == tag.attributes.end()) return {};
  auto values = parseNumbers(it->second);
  if (!values || values->size() != count)
    throwBadInput(path, "<" + tag.name + "> " + key + "=\"" + it->second + "\" is not " +
                            std::to_string(count) + " numbers");
  return *values;
}

std::array<int64_t, 6> extentOf(const std::string& path, const Tag& tag, const std::string& key) {
  const std::vector<double> v = numbersOf(path, tag, key, 6);
  if (v.empty()) throwBadInput(path, "<" + tag.name + "> has no " + key);
  std::array<int64_t, 6> e{};
  for (size_t i = 0; i < 6; ++i)
    e[i] = headerInteger(path, tag.name + " " + key, v[i], std::numeric_limits<int32_t>::min(),
                         std::numeric_limits<int32_t>::max());
  for (size_t a = 0; a < 3; ++a)
    if (e[2 * a] > e[2 * a + 1])
      throwBadInput(
          path, "<" + tag.name + "> " + key + " runs backwards along axis " + std::to_string(a));
  return e;
}

void checkFinite(const std::string& path, const Tag& tag, const std::string& key, size_t count,
                 bool positive) {
  for (double v : numbersOf(path, tag, key, count)) {
    if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max()))
      throwBadInput(path, "<" + tag.name + "> " + key + " holds " + std::to_string(v) +
                              " (not finite or beyond fp32)");
    if (positive && !(v > 0.0))
      throwBadInput(path, "<" + tag.name + "> " + key + " must be positive");
  }
}

uint64_t readUnsigned(const unsigned char* p, size_t bytes, bool bigEndian) {
  uint64_t v = 0;
  for (size_t i = 0; i < bytes; ++i) {
    const size_t at = bigEndian ? i : bytes - 1 - i;
    v = (v << 8) | p[at];
  }
  return v;
}

std::string decodeBase64Prefix(const std::string& text, size_t wantBytes) {
  static const std::string alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  uint32_t buffer = 0;
  int bits = 0;
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (c == '=') break;
    const size_t v = alphabet.find(c);
    if (v == std::string::npos) break;
    buffer = (buffer << 6) | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(char((buffer >> bits) & 0xFFu));
      if (out.size() >= wantBytes) break;
    }
  }
  return out;
}

// A compressed array's header: [blocks, block size, last block size, compressed sizes...].
void checkCompressionHeader(const std::string& path, const std::string& header, size_t word,
                            bool bigEndian, const std::string& arrayName) {
  if (header.size() < 3 * word)
    throwBadInput(path, "array \"" + arrayName + "\": truncated compressed-data header");
  const auto* p = reinterpret_cast<const unsigned char*>(header.data());
  const uint64_t blocks = readUnsigned(p, word, bigEndian);
  const uint64_t blockSize = readUnsigned(p + word, word, bigEndian);
  const uint64_t lastSize = readUnsigned(p + 2 * word, word, bigEndian);
  if (blocks > 0 && blockSize == 0)
    throwBadInput(path, "array \"" + arrayName + "\": compressed blocks of size 0");
  if (lastSize > blockSize)
    throwBadInput(path, "array \"" + arrayName + "\": last compressed block larger than a block");
  if (blocks > (uint64_t(1) << 32))
    throwBadInput(path,
                  "array \"" + arrayName + "\": " + std::to_string(blocks) + " compressed blocks");
}

}  // namespace

void checkVtiHeader(const std::string& path) {
  const uint64_t fileSize = checkedFileSize(path);
  const std::string head = readFilePrefix(path, kMaxXmlBytes);
  const size_t xmlEnd = head.find("<AppendedData");
  const size_t scanEnd = xmlEnd == std::string::npos ? head.size() : xmlEnd;

  const std::optional<Tag> file = findTag(path, head, "VTKFile", 0, scanEnd);
  if (!file) throwBadInput(path, "not a VTK XML file (no <VTKFile>)");
  auto attribute = [](const Tag& t, const std::string& key) {
    auto it = t.attributes.find(key);
    return it == t.attributes.end() ? std::string() : it->second;
  };
  if (attribute(*file, "type") != "ImageData")
    throwBadInput(
        path, "a VTK XML file of type \"" + attribute(*file, "type") + "\", not ImageData (.vti)");
  const std::string order = attribute(*file, "byte_order");
  if (!order.empty() && order != "LittleEndian" && order != "BigEndian")
    throwBadInput(path, "unknown byte_order \"" + order + "\"");
  const bool bigEndian = order == "BigEndian";
  const std::string headerType = attribute(*file, "header_type");
  if (!headerType.empty() && headerType != "UInt32" && headerType != "UInt64")
    throwBadInput(path, "unknown header_type \"" + headerType + "\" (UInt32 or UInt64)");
  const size_t word = headerType == "UInt64" ? 8 : 4;
  const std::string compressor = attribute(*file, "compressor");
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor" &&
      compressor != "vtkLZ4DataCompressor" && compressor != "vtkLZMADataCompressor")
    throwBadInput(path, "unknown compressor \"" + compressor + "\"");

  const std::optional<Tag> image = findTag(path, head, "ImageData", file->end, scanEnd);
  if (!image) throwBadInput(path, "no <ImageData> element");
  const std::array<int64_t, 6> whole = extentOf(path, *image, "WholeExtent");
  checkFinite(path, *image, "Origin", 3, false);
  checkFinite(path, *image, "Spacing", 3, true);
  checkFinite(path, *image, "Direction", 9, false);

  size_t pieces = 0;
  std::array<int64_t, 6> single{};
  for (std::optional<Tag> piece = findTag(path, head, "Piece", image->end, scanEnd); piece;
       piece = findTag(path, head, "Piece", piece->end, scanEnd)) {
    const std::array<int64_t, 6> e = extentOf(path, *piece, "Extent");
    for (size_t a = 0; a < 3; ++a)
      if (e[2 * a] < whole[2 * a] || e[2 * a + 1] > whole[2 * a + 1])
        throwBadInput(path, "a <Piece> Extent reaches outside the WholeExtent");
    single = e;
    ++pieces;
  }
  if (pieces == 0) throwBadInput(path, "no <Piece> element");
  if (pieces == 1 && single != whole)
    throwBadInput(path, "the one <Piece> Extent differs from the WholeExtent (missing data)");

  size_t appendedStart = std::string::npos;
  if (xmlEnd != std::string::npos) {
    const size_t marker = head.find('_', head.find('>', xmlEnd));
    if (marker != std::string::npos) appendedStart = marker + 1;
  }
  static const char* kTypes[] = {"Int8",   "UInt8", "Int16",  "UInt16",  "Int32",
                                 "UInt32", "Int64", "UInt64", "Float32", "Float64"};
  for (std::optional<Tag> array = findTag(path, head, "DataArray", image->end, scanEnd); array;
       array = findTag(path, head, "DataArray", array->end, scanEnd)) {
    const std::string name = attribute(*array, "Name");
    const std::string type = attribute(*array, "type");
    bool known = false;
    for (const char* t : kTypes) known = known || type == t;
    if (!known) throwBadInput(path, "array \"" + name + "\": unknown type \"" + type + "\"");
    const std::vector<double> components = numbersOf(path, *array, "NumberOfComponents", 1);
    if (!components.empty())
      headerInteger(path, "array \"" + name + "\" NumberOfComponents", components[0], 1, 1024);
    const std::string format = attribute(*array, "format");
    if (format != "ascii" && format != "binary" && format != "appended")
      throwBadInput(path, "array \"" + name + "\": unknown format \"" + format + "\"");
    if (compressor.empty() || format == "ascii") continue;
    if (format == "binary") {
      const size_t close = head.find('<', array->end);
      checkCompressionHeader(
          path, decodeBase64Prefix(head.substr(array->end, close - array->end), 3 * word), word,
          bigEndian, name);
    } else {
      const std::vector<double> offset = numbersOf(path, *array, "offset", 1);
      if (offset.empty()) throwBadInput(path, "array \"" + name + "\": appended without offset");
      const int64_t at =
          headerInteger(path, "array \"" + name + "\" offset", offset[0], 0, int64_t(fileSize));
      if (appendedStart == std::string::npos)
        throwBadInput(path, "array \"" + name + "\": appended, but the file has no appended data");
      std::optional<Tag> appended = findTag(path, head, "AppendedData", xmlEnd, head.size());
      if (appended && attribute(*appended, "encoding") == "raw") {
        const uint64_t start = uint64_t(appendedStart) + uint64_t(at);
        if (start + 3 * word > fileSize)
          throwBadInput(path, "array \"" + name + "\": appended offset beyond the file");
        std::string header(3 * word, '\0');
        std::ifstream in(path, std::ios::binary);
        in.seekg(std::streamoff(start));
        in.read(header.data(), std::streamsize(header.size()));
        header.resize(size_t(in.gcount()));
        checkCompressionHeader(path, header, word, bigEndian, name);
      }
    }
  }
}

}  // namespace visopt::io
