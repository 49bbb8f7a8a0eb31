#include "io/volume_writer_metaimage.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>
#include <vector>

#include "io/file_util.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

std::string header(const GridSpec& g, const std::string& dataFile) {
  std::ostringstream h;
  h << std::setprecision(9);
  h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
       "CompressedData = False\nTransformMatrix =";
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) h << ' ' << g.direction[c][r];
  h << "\nOffset = " << g.origin.x << ' ' << g.origin.y << ' ' << g.origin.z;
  h << "\nCenterOfRotation = 0 0 0\nAnatomicalOrientation = ???";
  h << "\nElementSpacing = " << g.spacing.x << ' ' << g.spacing.y << ' ' << g.spacing.z;
  h << "\nDimSize = " << g.dims.x << ' ' << g.dims.y << ' ' << g.dims.z;
  h << "\nElementType = MET_FLOAT\nElementDataFile = " << dataFile << "\n";
  return h.str();
}

void writeValues(std::ofstream& out, const Volume& volume) {
  const size_t n = volume.grid().voxelCount();
  std::vector<float> chunk;
  chunk.reserve(1 << 16);
  for (size_t i = 0; i < n; ++i) {
    float v = float(volume.toValue(volume.normalized.get(i)));
    if (hostIsBigEndian()) swapBytesInPlace(&v, 1, 4);
    chunk.push_back(v);
    if (chunk.size() == chunk.capacity() || i + 1 == n) {
      out.write(reinterpret_cast<const char*>(chunk.data()),
                static_cast<std::streamsize>(chunk.size() * sizeof(float)));
      chunk.clear();
    }
  }
}

void writeFile(const std::string& path, const std::string& suffix,
               const std::function<void(std::ofstream&)>& body) {
  const std::string tmp = makeTemporarySibling(path, suffix);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) body(out);
    out.flush();
    if (!out) {
      discardTemporary(tmp);
      throw Error(ErrorKind::Failure, path + ": cannot write (disk full or no permission?)");
    }
  }
  commitTemporary(tmp, path);
}

}  // namespace

void writeMetaImage(const Volume& volume, const std::string& path, bool detached) {
  const GridSpec& g = volume.grid();
  if (!detached) {
    writeFile(path, ".mha", [&](std::ofstream& out) {
      out << header(g, "LOCAL");
      writeValues(out, volume);
    });
    return;
  }
  std::filesystem::path dataPath(path);
  dataPath.replace_extension(".raw");
  writeFile(dataPath.string(), ".raw", [&](std::ofstream& out) { writeValues(out, volume); });
  writeFile(path, ".mhd",
            [&](std::ofstream& out) { out << header(g, dataPath.filename().string()); });
}

}  // namespace visopt::io
