// Reading volumes. Formats: NIfTI (.nii, .nii.gz), MetaImage (.mhd/.mha), VTK XML image data
// (.vti), legacy VTK structured points (.vtk), NRRD (.nrrd, .nhdr), a DICOM series given as a
// folder, and raw data described by a JSON sidecar (FILE.json next to FILE.raw, see
// docs in README). Any scalar type is accepted; multi-component data is refused.
//
// Every failure throws visopt::Error(ErrorKind::BadInput) whose message is one line of the
// form "PATH: problem" — truncated data, a header that contradicts the data, dimensions whose
// product overflows or exceeds available memory, unsupported types, NaN/Inf values.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "visopt/grid.h"
#include "visopt/precision.h"
#include "visopt/progress.h"
#include "visopt/volume.h"

namespace visopt {

class MemoryLedger;

struct VolumeInfo {
  std::string path;
  std::string format;      // "nifti", "metaimage", "vti", "vtk-legacy", "nrrd", "dicom", "raw"
  std::string scalarType;  // "uint8", "int16", "float32", ...
  GridSpec grid;
  double valueMin = 0.0, valueMax = 0.0;
  size_t bytesOnDisk = 0;             // of the scalar payload, as stored
  size_t bytesFp32 = 0;               // what visopt needs to hold the scalars as fp32
  size_t bytesFp16 = 0;               // ... and as fp16
  std::vector<std::string> warnings;  // as Volume::warnings
};

// Reads the whole file (values are needed for the range) and describes it.
VolumeInfo probeVolume(const std::string& path, const ProgressCallback& progress = {});

// Reads a volume; scalars are stored normalised at `precision` and registered in `ledger`
// (may be null) as "volume". The field name is "volume".
Volume readVolume(const std::string& path, Precision precision, MemoryLedger* ledger = nullptr,
                  const ProgressCallback& progress = {});

// Writes a volume as VTK XML image data (.vti) or NIfTI (.nii/.nii.gz) or MetaImage
// (.mha/.mhd), chosen by extension, as float32 in original units. Atomic: a temporary file is
// renamed into place.
void writeVolume(const Volume& volume, const std::string& path);

// Bytes of physical memory available to this process now (MemAvailable); used to refuse
// volumes that cannot fit.
size_t availableMemoryBytes();

}  // namespace visopt
