// MetaImage (.mha with the data after the header, .mhd with the data in a separate file).
// Geometry: DimSize, ElementSpacing, Offset (or Origin / Position) and TransformMatrix (or
// Rotation / Orientation), whose 9 numbers list the world direction of index axis i, then j,
// then k (as ITK writes them). Parsed here rather than through vtkMetaImageReader so that the
// orientation is kept, a lying header is caught before allocation, and nothing is printed.
#include <map>

#include "io/file_util.h"
#include "io/text_header.h"
#include "io/volume_source.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

std::optional<ScalarType> metaElementType(const std::string& name) {
  static const std::map<std::string, ScalarType> types = {
      {"MET_CHAR", ScalarType::Int8},       {"MET_UCHAR", ScalarType::UInt8},
      {"MET_SHORT", ScalarType::Int16},     {"MET_USHORT", ScalarType::UInt16},
      {"MET_INT", ScalarType::Int32},       {"MET_UINT", ScalarType::UInt32},
      {"MET_LONG", ScalarType::Int32},      {"MET_ULONG", ScalarType::UInt32},
      {"MET_LONG_LONG", ScalarType::Int64}, {"MET_ULONG_LONG", ScalarType::UInt64},
      {"MET_FLOAT", ScalarType::Float32},   {"MET_DOUBLE", ScalarType::Float64},
  };
  auto it = types.find(name);
  if (it == types.end()) return std::nullopt;
  return it->second;
}

bool isTrue(const std::string& v) {
  std::string l = toLower(v);
  return l == "true" || l == "1" || l == "yes";
}

}  // namespace

VolumeLayout metaImageLayout(const std::string& path, bool wholeInMemory) {
  const uint64_t fileSize = checkedFileSize(path);
  const std::string text = readFilePrefix(path, 1 << 20);

  std::map<std::string, std::string> fields;
  uint64_t dataOffset = 0;
  bool sawDataFile = false;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t eol = text.find('\n', pos);
    const size_t lineEnd = eol == std::string::npos ? text.size() : eol;
    const std::string line = text.substr(pos, lineEnd - pos);
    pos = eol == std::string::npos ? text.size() : eol + 1;
    if (trim(line).empty()) continue;
    size_t eq = line.find('=');
    if (eq == std::string::npos)
      throwBadInput(path, "not a MetaImage header (expected 'Key = Value' lines)");
    std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
    fields[key] = value;
    if (key == "ElementDataFile") {
      sawDataFile = true;
      dataOffset = pos;
      break;
    }
  }
  if (!sawDataFile) throwBadInput(path, "not a MetaImage header (no ElementDataFile line)");

  auto numbers = [&](const std::string& key, size_t n) -> std::optional<std::vector<double>> {
    auto it = fields.find(key);
    if (it == fields.end()) return std::nullopt;
    auto v = parseNumbers(it->second);
    if (!v || v->size() < n)
      throwBadInput(path, key + " must hold " + std::to_string(n) + " numbers");
    v->resize(n);
    return v;
  };

  int ndims = 3;
  if (auto v = numbers("NDims", 1)) ndims = int(headerInteger(path, "NDims", (*v)[0], 0, 64));
  if (ndims < 1 || ndims > 3)
    throwBadInput(path, "NDims = " + std::to_string(ndims) + " is not supported (need 1 to 3)");
  const size_t nd = size_t(ndims);

  VolumeHeader h;
  auto dims = numbers("DimSize", nd);
  if (!dims) throwBadInput(path, "missing DimSize");
  h.dims = {1, 1, 1};
  for (size_t a = 0; a < nd; ++a)
    h.dims[a] = headerInteger(path, "DimSize", (*dims)[a], 0, int64_t(1) << 40);
  auto spacing = numbers("ElementSpacing", nd);
  if (!spacing) spacing = numbers("ElementSize", nd);
  if (spacing)
    for (size_t a = 0; a < nd; ++a) h.spacing[a] = (*spacing)[a];
  for (const char* key : {"Offset", "Origin", "Position"})
    if (auto o = numbers(key, nd)) {
      for (size_t a = 0; a < nd; ++a) h.origin[a] = (*o)[a];
      break;
    }
  for (const char* key : {"TransformMatrix", "Rotation", "Orientation"})
    if (auto m = numbers(key, nd * nd)) {
      for (size_t c = 0; c < nd; ++c)
        for (size_t r = 0; r < nd; ++r) h.direction[c][r] = (*m)[c * nd + r];
      break;
    }
  if (auto c = numbers("ElementNumberOfChannels", 1))
    h.components = int(headerInteger(path, "ElementNumberOfChannels", (*c)[0], 0, 1 << 20));
  auto typeIt = fields.find("ElementType");
  if (typeIt == fields.end()) throwBadInput(path, "missing ElementType");
  auto type = metaElementType(typeIt->second);
  if (!type) throwBadInput(path, "unsupported ElementType " + typeIt->second);
  h.type = *type;

  bool bigEndian = false;
  for (const char* key : {"BinaryDataByteOrderMSB", "ElementByteOrderMSB"})
    if (fields.count(key)) bigEndian = isTrue(fields[key]);
  const bool compressed = fields.count("CompressedData") && isTrue(fields["CompressedData"]);

  VolumeLayout layout;
  layout.format = "metaimage";
  layout.headerPath = path;
  layout.header = h;
  layout.grid = checkHeader(path, h, wholeInMemory);
  const size_t count = layout.grid.voxelCount();

  std::string dataFile = fields["ElementDataFile"];
  if (dataFile == "LOCAL") {
    dataFile = path;
    if (dataOffset > fileSize) throwBadInput(path, "truncated: no data after the header");
  } else {
    if (dataFile == "LIST" || dataFile.find('%') != std::string::npos ||
        dataFile.find(' ') != std::string::npos)
      throwBadInput(path, "ElementDataFile \"" + dataFile + "\": file lists are not supported");
    dataFile = siblingPath(path, dataFile);
    dataOffset = 0;
    if (auto hs = numbers("HeaderSize", 1)) {
      if ((*hs)[0] >= 0) {
        dataOffset = uint64_t(headerInteger(path, "HeaderSize", (*hs)[0], 0, int64_t(1) << 62));
      } else if (!compressed) {  // -1: the data is at the end of the file
        uint64_t dataSize = checkedFileSize(dataFile), need = count * scalarTypeSize(h.type);
        if (dataSize < need)
          throwBadInput(dataFile, "truncated: header describes " + std::to_string(need) +
                                      " bytes of data, file has only " + std::to_string(dataSize));
        dataOffset = dataSize - need;
      }
    }
  }
  layout.dataPath = dataFile;
  layout.dataOffset = dataOffset;
  layout.bigEndian = bigEndian;
  layout.compressed = compressed;
  return layout;
}

LoadedVolume readMetaImage(const std::string& path, const ProgressCallback& progress) {
  const VolumeLayout layout = metaImageLayout(path);
  LoadedVolume out;
  out.format = layout.format;
  out.grid = layout.grid;
  reportProgress(progress, path, 0.1f, "header");
  const ScalarType type = layout.header.type;
  const size_t count = out.grid.voxelCount();
  out.scalars =
      layout.compressed
          ? readCompressedPayload(layout.dataPath, layout.dataOffset, type, count, layout.bigEndian)
          : readPayload(layout.dataPath, layout.dataOffset, type, count, layout.bigEndian);
  return out;
}

}  // namespace visopt::io
