// probeVolume / readVolume: pick the reader by extension (a folder is a DICOM series), then scan
// the scalars once (range, NaN/Inf count) and convert them to the normalised "volume" field.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <new>

#include "core/field_view.h"
#include "exec/parallel.h"
#include "io/file_util.h"
#include "io/volume_source.h"
#include "visopt/error.h"
#include "visopt/value_normalization.h"
#include "visopt/volume_io.h"

namespace visopt {

namespace {

using io::LoadedVolume;

LoadedVolume loadAnyVolume(const std::string& path, const ProgressCallback& progress) {
  if (path.empty()) throw Error(ErrorKind::BadInput, "no volume file given");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return io::readDicomSeries(path, progress);
  struct Entry {
    const char* suffix;
    LoadedVolume (*read)(const std::string&, const ProgressCallback&);
  };
  static const Entry entries[] = {
      {".nii", io::readNifti},     {".nii.gz", io::readNifti},    {".mha", io::readMetaImage},
      {".mhd", io::readMetaImage}, {".vti", io::readVtkXmlImage}, {".vtk", io::readVtkLegacy},
      {".nrrd", io::readNrrd},     {".nhdr", io::readNrrd},       {".raw", io::readRawWithSidecar},
      {".inr", io::readInrimage},  {".plt", io::readGOpenMolPlt},
  };
  for (const Entry& e : entries)
    if (io::endsWithNoCase(path, e.suffix)) {
      try {
        return e.read(path, progress);
      } catch (const Error& error) {
        // A header's data file (scan.mhd -> scan.raw) is not what the user opened: name the
        // opened file first ("scan.mhd: its data file scan.raw: truncated ..."), or the message
        // points at a file the user never chose.
        const std::string message = error.what();
        if (error.kind() != ErrorKind::BadInput || message.rfind(path + ":", 0) == 0) throw;
        const bool sidecar = io::endsWithNoCase(path, ".raw");  // vol.raw's header vol.raw.json
        throw Error(ErrorKind::BadInput,
                    path + (sidecar ? ": its header " : ": its data file ") + message);
      }
    }
  if (!std::filesystem::exists(path, ec)) throwBadInput(path, "file not found");
  std::string ext = std::filesystem::path(path).extension().string();
  throwBadInput(path, "unknown volume format" + (ext.empty() ? std::string() : " '" + ext + "'") +
                          " (supported: .nii .nii.gz .mha .mhd .vti .vtk .nrrd .nhdr .raw+.json "
                          ".inr .plt, or a DICOM folder)");
}

struct Stats {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  uint64_t nonFinite = 0;
};

Stats scanValues(const io::ScalarData& s) {
  return io::visitScalarType(s.type, [&](auto zero) {
    using T = decltype(zero);
    const T* data = static_cast<const T*>(s.data);
    const double slope = s.slope, intercept = s.intercept;
    return exec::reduce(
        "io.scan", int64_t(s.count), Stats{},
        [=](int64_t i) {
          const double v = double(data[i]) * slope + intercept;
          Stats r;
          if (std::isfinite(v))
            r.lo = r.hi = v;
          else
            r.nonFinite = 1;
          return r;
        },
        [](const Stats& a, const Stats& b) {
          return Stats{std::min(a.lo, b.lo), std::max(a.hi, b.hi), a.nonFinite + b.nonFinite};
        });
  });
}

void checkValues(const std::string& path, const Stats& stats, size_t count) {
  if (stats.nonFinite > 0)
    throwBadInput(path, std::to_string(stats.nonFinite) + " of " + std::to_string(count) +
                            " values are NaN or Inf");
}

void normalizeInto(const io::ScalarData& s, double lo, double hi, Field3D& field) {
  FieldView view(field);
  const ValueNormalization normalize(lo, hi);
  io::visitScalarType(s.type, [&](auto zero) {
    using T = decltype(zero);
    const T* data = static_cast<const T*>(s.data);
    const double slope = s.slope, intercept = s.intercept;
    exec::parallelFor("io.normalize", int64_t(s.count), [=](int64_t i) {
      view.store(size_t(i), normalize(double(data[i]) * slope + intercept));
    });
  });
}

std::string scalarTypeText(const io::ScalarData& s) {
  std::string name = io::scalarTypeName(s.type);
  return name;
}

template <class F>
auto guardMemory(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw Error(ErrorKind::Failure, path + ": out of memory while reading the volume");
  }
}

}  // namespace

VolumeInfo probeVolume(const std::string& path, const ProgressCallback& progress) {
  return guardMemory(path, [&] {
    io::reportProgress(progress, path, 0.f, "open");
    LoadedVolume lv = loadAnyVolume(path, progress);
    io::reportProgress(progress, path, 0.6f, "data");
    Stats stats = scanValues(lv.scalars);
    checkValues(path, stats, lv.scalars.count);
    VolumeInfo info;
    info.path = path;
    info.format = lv.format;
    info.scalarType = scalarTypeText(lv.scalars);
    info.grid = lv.grid;
    info.valueMin = stats.lo;
    info.valueMax = stats.hi;
    info.bytesOnDisk = lv.scalars.count * io::scalarTypeSize(lv.scalars.type);
    info.bytesFp32 = lv.scalars.count * 4;
    info.bytesFp16 = lv.scalars.count * 2;
    info.warnings = lv.warnings;
    io::reportProgress(progress, path, 1.f, "converted");
    return info;
  });
}

Volume readVolume(const std::string& path, Precision precision, MemoryLedger* ledger,
                  const ProgressCallback& progress) {
  return guardMemory(path, [&] {
    io::reportProgress(progress, path, 0.f, "open");
    LoadedVolume lv = loadAnyVolume(path, progress);
    io::reportProgress(progress, path, 0.6f, "data");
    Stats stats = scanValues(lv.scalars);
    checkValues(path, stats, lv.scalars.count);
    io::reportProgress(progress, path, 0.7f, "range");
    Volume volume;
    volume.name = io::fileName(path);
    for (const char* ext : {".nii.gz", ".nii", ".mha", ".mhd", ".vti", ".vtk", ".nrrd", ".nhdr",
                            ".raw", ".inr", ".plt"})
      if (io::endsWithNoCase(volume.name, ext) && volume.name.size() > std::string(ext).size()) {
        volume.name.resize(volume.name.size() - std::string(ext).size());
        break;
      }
    volume.sourcePath = path;
    volume.scalarType = scalarTypeText(lv.scalars);
    volume.valueMin = stats.lo;
    volume.valueMax = stats.hi;
    volume.warnings = lv.warnings;
    volume.normalized = Field3D("volume", lv.grid, precision, ledger);
    normalizeInto(lv.scalars, stats.lo, stats.hi, volume.normalized);
    io::reportProgress(progress, path, 1.f, "converted");
    return volume;
  });
}

}  // namespace visopt
