// Internal interface of the volume readers. Every reader turns one file (or DICOM folder) into a
// LoadedVolume: geometry plus the scalars in their type on disk. Readers validate the header
// with checkHeader() BEFORE they allocate anything for the data; the common code in
// volume_io.cpp then scans the values (range, NaN/Inf) and converts them to a normalised field.
//
// Every failure is a visopt::Error(BadInput) "PATH: problem" (see visopt/error.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/scalar_type.h"
#include "visopt/grid.h"
#include "visopt/progress.h"

namespace visopt::io {

// What a header says, in wide types so absurd values can be reported rather than wrapped.
struct VolumeHeader {
  std::array<int64_t, 3> dims{0, 0, 0};
  ScalarType type = ScalarType::Float32;
  int components = 1;
  std::array<double, 3> spacing{1.0, 1.0, 1.0};
  std::array<double, 3> origin{0.0, 0.0, 0.0};
  // Column-major like glm: direction[c][r] is row r of column c; column c is the world direction
  // of index axis c.
  std::array<std::array<double, 3>, 3> direction{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
};

struct ScalarData {
  ScalarType type = ScalarType::Float32;
  const void* data = nullptr;
  size_t count = 0;
  // Stored values map to physical ones as value = slope * stored + intercept (NIfTI scl_*,
  // DICOM rescale); the identity for most formats.
  double slope = 1.0, intercept = 0.0;
  std::shared_ptr<const void> owner;  // keeps `data` alive (a buffer or a VTK object)
};

struct LoadedVolume {
  std::string format;  // "nifti", "metaimage", "vti", "vtk-legacy", "nrrd", "dicom", "raw", ...
  GridSpec grid;
  ScalarData scalars;
  std::vector<std::string> warnings;  // accepted, but the user should know (Volume::warnings)
};

// Checks dims (> 0, fits in int, product and fp32 bytes do not overflow, fp32 bytes fit in
// availableMemoryBytes()), components (1), spacing (> 0, finite), origin (finite) and direction
// (finite, orthonormal). Throws BadInput naming `path`. Returns the grid it describes.
GridSpec checkHeader(const std::string& path, const VolumeHeader& header);

// Calls progress (if any) and throws Error(Cancelled, "PATH: cancelled") when it returns false.
void reportProgress(const ProgressCallback& progress, const std::string& path, float fraction,
                    const std::string& stage);

// Format readers (each in its own file).
LoadedVolume readRawWithSidecar(const std::string& path, const ProgressCallback& progress);
LoadedVolume readMetaImage(const std::string& path, const ProgressCallback& progress);
LoadedVolume readNrrd(const std::string& path, const ProgressCallback& progress);
LoadedVolume readInrimage(const std::string& path, const ProgressCallback& progress);
LoadedVolume readGOpenMolPlt(const std::string& path, const ProgressCallback& progress);
LoadedVolume readNifti(const std::string& path, const ProgressCallback& progress);
LoadedVolume readVtkXmlImage(const std::string& path, const ProgressCallback& progress);
LoadedVolume readVtkLegacy(const std::string& path, const ProgressCallback& progress);
LoadedVolume readDicomSeries(const std::string& path, const ProgressCallback& progress);

}  // namespace visopt::io
