// INRIMAGE-4 (.inr), as CGAL's sample images use: a text header "#INRIMAGE-4#{" ... "##}\n"
// padded to a multiple of 256 bytes, then the voxels x fastest. Keys XDIM YDIM ZDIM VDIM, TYPE
// (float | unsigned fixed | signed fixed), PIXSIZE ("32 bits"), CPU (decm/pc/alpha: little
// endian; sun/sgi: big), VX VY VZ (spacing), optional XO YO ZO (origin).
#include <cstdlib>
#include <map>

#include "io/file_util.h"
#include "io/text_header.h"
#include "io/volume_source.h"
#include "visopt/error.h"

namespace visopt::io {

LoadedVolume readInrimage(const std::string& path, const ProgressCallback& progress) {
  checkedFileSize(path);
  const std::string text = readFilePrefix(path, 1 << 16);
  if (text.rfind("#INRIMAGE-4#{", 0) != 0)
    throwBadInput(path, "not an INRIMAGE-4 file (no #INRIMAGE-4#{ magic)");
  size_t end = text.find("##}\n");
  if (end == std::string::npos) throwBadInput(path, "truncated: INRIMAGE header has no end");
  const uint64_t headerBytes = end + 4;

  std::map<std::string, std::string> fields;
  size_t pos = text.find('\n') + 1;
  while (pos < end) {
    size_t eol = text.find('\n', pos);
    std::string line = text.substr(pos, eol - pos);
    pos = eol + 1;
    size_t eq = line.find('=');
    if (eq != std::string::npos) fields[trim(line.substr(0, eq))] = trim(line.substr(eq + 1));
  }
  auto number = [&](const char* key, double fallback) {
    auto it = fields.find(key);
    if (it == fields.end()) return fallback;
    char* stop = nullptr;
    double v = std::strtod(it->second.c_str(), &stop);
    if (stop == it->second.c_str()) throwBadInput(path, std::string("malformed ") + key);
    return v;
  };

  VolumeHeader h;
  constexpr int64_t kMaxAxis = int64_t(1) << 40;  // checkHeader refuses what exceeds int
  h.dims = {headerInteger(path, "XDIM", number("XDIM", 0), 0, kMaxAxis),
            headerInteger(path, "YDIM", number("YDIM", 0), 0, kMaxAxis),
            headerInteger(path, "ZDIM", number("ZDIM", 1), 0, kMaxAxis)};
  h.components = int(headerInteger(path, "VDIM", number("VDIM", 1), 0, 1 << 20));
  h.spacing = {number("VX", 1), number("VY", 1), number("VZ", 1)};
  h.origin = {number("XO", 0), number("YO", 0), number("ZO", 0)};
  const std::string typeText = toLower(fields["TYPE"]);
  const int bits = int(headerInteger(path, "PIXSIZE", number("PIXSIZE", 8), 0, 1024));
  if (typeText == "float" && bits == 32)
    h.type = ScalarType::Float32;
  else if (typeText == "float" && bits == 64)
    h.type = ScalarType::Float64;
  else if (typeText == "unsigned fixed" && (bits == 8 || bits == 16 || bits == 32))
    h.type = bits == 8 ? ScalarType::UInt8 : bits == 16 ? ScalarType::UInt16 : ScalarType::UInt32;
  else if (typeText == "signed fixed" && (bits == 8 || bits == 16 || bits == 32))
    h.type = bits == 8 ? ScalarType::Int8 : bits == 16 ? ScalarType::Int16 : ScalarType::Int32;
  else
    throwBadInput(path, "unsupported INRIMAGE type \"" + fields["TYPE"] + "\" with " +
                            std::to_string(bits) + " bits");
  const std::string cpu = toLower(fields["CPU"]);
  const bool bigEndian = cpu == "sun" || cpu == "sgi";

  LoadedVolume out;
  out.format = "inrimage";
  out.grid = checkHeader(path, h);
  reportProgress(progress, path, 0.1f, "header");
  out.scalars = readPayload(path, headerBytes, h.type, out.grid.voxelCount(), bigEndian);
  return out;
}

}  // namespace visopt::io
