// VolumeSlabReader: the header parsing of the raw, MetaImage and NIfTI readers (their *Layout
// functions, volume_source.h), then one seek + read per slab. Values are computed exactly as
// volume_io.cpp's scanValues / normalizeInto compute them, after the same byte swapping and, for
// NIfTI files VTK reads in reverse slice order (qfac -1, a reflecting sform), the same order.
#include "visopt/volume_slabs.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>

#include "io/file_util.h"
#include "io/volume_source.h"
#include "visopt/error.h"
#include "visopt/volume_io.h"

namespace visopt {

struct VolumeSlabReader::Layout {
  std::string path;
  io::VolumeLayout file;
  uint64_t sliceVoxels = 0;
  uint64_t sliceBytes = 0;
};

namespace {

constexpr const char* kSupported =
    "supported: uncompressed .raw (with a .raw.json sidecar), .mha, .mhd and .nii";

[[noreturn]] void refuse(const std::string& path, const std::string& what) {
  throwBadInput(path, what + " cannot be read by slabs; " + kSupported);
}

// As readVolume: a message about another file (a .mhd's data file, a .raw's sidecar) names the
// file the user opened first.
template <class F>
auto namingPath(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const Error& error) {
    const std::string message = error.what();
    if (error.kind() != ErrorKind::BadInput || message.rfind(path + ":", 0) == 0) throw;
    const bool sidecar = io::endsWithNoCase(path, ".raw");
    throw Error(ErrorKind::BadInput,
                path + (sidecar ? ": its header " : ": its data file ") + message);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorKind::Failure, path + ": out of memory while reading the volume");
  }
}

io::VolumeLayout readLayout(const std::string& path) {
  if (path.empty()) throw Error(ErrorKind::BadInput, "no volume file given");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) refuse(path, "a folder (DICOM series)");
  if (io::endsWithNoCase(path, ".nii.gz")) refuse(path, "compressed NIfTI (.nii.gz)");
  if (io::endsWithNoCase(path, ".nii")) return io::niftiLayout(path, false);
  if (io::endsWithNoCase(path, ".mha") || io::endsWithNoCase(path, ".mhd"))
    return io::metaImageLayout(path, false);
  if (io::endsWithNoCase(path, ".raw")) return io::rawLayout(path, false);
  struct Other {
    const char* suffix;
    const char* name;
  };
  static const Other others[] = {
      {".vti", "VTK XML image data (.vti)"},
      {".vtk", "legacy VTK (.vtk)"},
      {".nrrd", "NRRD (.nrrd)"},
      {".nhdr", "NRRD (.nhdr)"},
      {".inr", "INRIMAGE (.inr)"},
      {".plt", "gOpenMol (.plt)"},
  };
  for (const Other& o : others)
    if (io::endsWithNoCase(path, o.suffix)) refuse(path, o.name);
  if (!std::filesystem::exists(path, ec)) throwBadInput(path, "file not found");
  const std::string ext = std::filesystem::path(path).extension().string();
  refuse(path, "unknown volume format" + (ext.empty() ? std::string() : " '" + ext + "'"));
}

std::string rangeText(int zBegin, int zEnd) {
  return "slices [" + std::to_string(zBegin) + ", " + std::to_string(zEnd) + ")";
}

}  // namespace

VolumeSlabReader::VolumeSlabReader(const std::string& path) {
  auto layout = std::make_shared<Layout>();
  layout->path = path;
  layout->file = namingPath(path, [&] { return readLayout(path); });
  const io::VolumeLayout& f = layout->file;
  if (f.compressed) {
    if (f.format == "metaimage") refuse(path, "compressed MetaImage data (CompressedData = True)");
    refuse(path, "compressed data");
  }
  // Every byte of the data must be addressable by a stream offset.
  const GridSpec& g = f.grid;
  const uint64_t elementSize = io::scalarTypeSize(f.header.type);
  uint64_t dataBytes = 0, end = 0;
  layout->sliceVoxels = uint64_t(g.dims.x) * uint64_t(g.dims.y);
  if (__builtin_mul_overflow(uint64_t(g.voxelCount()), elementSize, &dataBytes) ||
      __builtin_add_overflow(dataBytes, f.dataOffset, &end) ||
      end > uint64_t(std::numeric_limits<std::streamoff>::max()))
    throwBadInput(path, "dimensions " + std::to_string(g.dims.x) + " x " +
                            std::to_string(g.dims.y) + " x " + std::to_string(g.dims.z) +
                            " overflow: the data's byte offsets do not fit in 63 bits");
  layout->sliceBytes = layout->sliceVoxels * elementSize;
  layout_ = std::move(layout);
}

const std::string& VolumeSlabReader::path() const {
  return layout_->path;
}
const std::string& VolumeSlabReader::format() const {
  return layout_->file.format;
}
const GridSpec& VolumeSlabReader::grid() const {
  return layout_->file.grid;
}
const std::vector<std::string>& VolumeSlabReader::warnings() const {
  return layout_->file.warnings;
}

std::vector<double> VolumeSlabReader::readSlices(int zBegin, int zEnd) const {
  const Layout& l = *layout_;
  const io::VolumeLayout& f = l.file;
  const int nz = f.grid.dims.z;
  if (zBegin < 0 || zEnd > nz || zBegin >= zEnd)
    throw Error(ErrorKind::Usage, l.path + ": " + rangeText(zBegin, zEnd) +
                                      " is empty or outside the volume's [0, " +
                                      std::to_string(nz) + ")");
  const uint64_t slices = uint64_t(zEnd - zBegin);
  const uint64_t count = slices * l.sliceVoxels, bytes = slices * l.sliceBytes;
  // Slice k of the grid is file slice nz - 1 - k when reversed: the slab is still one
  // contiguous run of file slices, [nz - zEnd, nz - zBegin), read back to front.
  const uint64_t fileSlice = uint64_t(f.reversedSlices ? nz - zEnd : zBegin);
  const uint64_t begin = f.dataOffset + fileSlice * l.sliceBytes;
  return namingPath(l.path, [&] {
    const std::string& data = f.dataPath;
    const uint64_t fileSize = io::checkedFileSize(data);
    auto truncated = [&](uint64_t has) {
      throwBadInput(data, "truncated: " + rangeText(zBegin, zEnd) + " are bytes " +
                              std::to_string(begin) + " to " + std::to_string(begin + bytes) +
                              " of the file, which has only " + std::to_string(has));
    };
    if (begin > fileSize || fileSize - begin < bytes) truncated(fileSize);
    const uint64_t need = bytes + count * sizeof(double);  // the stored slab and its values
    if (need > availableMemoryBytes())
      throw Error(ErrorKind::Usage, l.path + ": " + rangeText(zBegin, zEnd) + " need " +
                                        std::to_string(need) +
                                        " bytes, more than the available memory; read fewer "
                                        "slices");
    return io::visitScalarType(f.header.type, [&](auto zero) {
      using T = decltype(zero);
      std::vector<T> stored(static_cast<size_t>(count));
      std::ifstream in(data, std::ios::binary);
      if (!in) throwBadInput(data, std::string("cannot open: ") + std::strerror(errno));
      in.seekg(std::streamoff(begin));
      in.read(reinterpret_cast<char*>(stored.data()), std::streamsize(bytes));
      if (!in || uint64_t(in.gcount()) != bytes) truncated(begin + uint64_t(in.gcount()));
      if (f.bigEndian != io::hostIsBigEndian())
        io::swapBytesInPlace(stored.data(), stored.size(), sizeof(T));
      std::vector<double> values(static_cast<size_t>(count));
      const double slope = f.slope, intercept = f.intercept;
      uint64_t nonFinite = 0;
      for (uint64_t s = 0; s < slices; ++s) {
        const uint64_t from = (f.reversedSlices ? slices - 1 - s : s) * l.sliceVoxels;
        const T* src = stored.data() + from;
        double* dst = values.data() + s * l.sliceVoxels;
        for (uint64_t v = 0; v < l.sliceVoxels; ++v) {
          const double value = double(src[v]) * slope + intercept;  // as scanValues
          nonFinite += std::isfinite(value) ? 0 : 1;
          dst[v] = value;
        }
      }
      if (nonFinite > 0)
        throwBadInput(l.path, rangeText(zBegin, zEnd) + ": " + std::to_string(nonFinite) + " of " +
                                  std::to_string(count) + " values are NaN or Inf");
      return values;
    });
  });
}

}  // namespace visopt
