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
// availableMemoryBytes() unless !wholeInMemory), components (1), spacing (> 0, finite), origin
// (finite) and direction (finite, orthonormal). Throws BadInput naming `path`. Returns the grid
// it describes. wholeInMemory = false: for readers that never hold the whole volume (slabs).
GridSpec checkHeader(const std::string& path, const VolumeHeader& header,
                     bool wholeInMemory = true);

// Calls progress (if any) and throws Error(Cancelled, "PATH: cancelled") when it returns false.
void reportProgress(const ProgressCallback& progress, const std::string& path, float fraction,
                    const std::string& stage);

// Where a file's scalars lie, from its header alone (no data read), for reading them in parts
// (VolumeSlabReader). Voxel (i, j, k) of the grid is stored at byte
//   dataOffset + ((k' * ny + j) * nx + i) * scalarTypeSize(header.type)  of dataPath,
// with k' = k, or dims.z - 1 - k when reversedSlices; value = slope * stored + intercept.
struct VolumeLayout {
  std::string format;      // as LoadedVolume::format
  std::string headerPath;  // the file the header came from (a raw volume's JSON sidecar)
  VolumeHeader header;
  GridSpec grid;  // checkHeader(headerPath, header, wholeInMemory)
  std::string dataPath;
  uint64_t dataOffset = 0;
  bool bigEndian = false;
  bool compressed = false;      // a zlib/gzip stream from dataOffset: no offset reads
  bool reversedSlices = false;  // NIfTI with qfac -1 or a reflecting sform (VTK's slice order)
  double slope = 1.0, intercept = 0.0;
  std::vector<std::string> warnings;
};

// The header parsing of readRawWithSidecar, readMetaImage and readNifti (each in its reader's
// file), same checks and messages; nothing past the header is read (readNifti's check that the
// data fits in the file is left to whoever reads it).
VolumeLayout rawLayout(const std::string& path, bool wholeInMemory = true);
VolumeLayout metaImageLayout(const std::string& path, bool wholeInMemory = true);
VolumeLayout niftiLayout(const std::string& path, bool wholeInMemory = true);

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
