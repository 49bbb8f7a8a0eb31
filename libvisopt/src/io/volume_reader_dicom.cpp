// A DICOM series given as a folder, through vtkDICOMImageReader (uncompressed transfer syntaxes
// only; one series per folder). The reader sorts the slices by position and flips the rows so
// that row 0 is the bottom one; geometry is rebuilt in DICOM patient space (LPS):
//   direction columns: row direction (IOP[0..2]), column direction (IOP[3..5]) flipped to match
//   the row flip, and their cross product for the slices;
//   origin: the world position of voxel (0,0,0) after the flip.
// Rescale slope/intercept are applied to the values.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <vtkDICOMImageReader.h>
#include <vtkImageData.h>
#include <vtkNew.h>

#include "io/file_util.h"
#include "io/vtk_image_reading.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

// DICOMParser reports some problems straight to std::cerr; keep them off the terminal.
class CerrSilencer {
 public:
  CerrSilencer() : previous_(std::cerr.rdbuf(sink_.rdbuf())) {}
  ~CerrSilencer() { std::cerr.rdbuf(previous_); }
  CerrSilencer(const CerrSilencer&) = delete;
  CerrSilencer& operator=(const CerrSilencer&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* previous_;
};

}  // namespace

LoadedVolume readDicomSeries(const std::string& path, const ProgressCallback& progress) {
  namespace fs = std::filesystem;
  std::error_code ec;
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(path, ec))
    if (entry.is_regular_file(ec)) ++files;
  if (ec) throwBadInput(path, "cannot list the folder (" + ec.message() + ")");
  if (files == 0) throwBadInput(path, "folder holds no files (expected a DICOM series)");

  CerrSilencer silence;
  vtkNew<vtkDICOMImageReader> reader;
  reader->SetDirectoryName(path.c_str());
  VtkImageRead read = runVtkImageReader(path, reader, progress);
  VolumeHeader h = headerFromVtkImage(read);

  const float* iop = reader->GetImageOrientationPatient();
  const float* ipp = reader->GetImagePositionPatient();
  double row[3] = {1, 0, 0}, col[3] = {0, 1, 0};
  if (iop) {
    for (int r = 0; r < 3; ++r) {
      row[r] = iop[r];
      col[r] = iop[r + 3];
    }
  }
  double rowLen = std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
  double colLen = std::sqrt(col[0] * col[0] + col[1] * col[1] + col[2] * col[2]);
  if (rowLen < 0.5 || colLen < 0.5) {  // absent or zero orientation: assume axial
    row[0] = 1, row[1] = 0, row[2] = 0;
    col[0] = 0, col[1] = 1, col[2] = 0;
    rowLen = colLen = 1.0;
  }
  double normal[3] = {row[1] * col[2] - row[2] * col[1], row[2] * col[0] - row[0] * col[2],
                      row[0] * col[1] - row[1] * col[0]};
  // Rows are stored bottom-up, so the j axis runs against the DICOM column direction.
  const double ny = double(h.dims[1] - 1) * h.spacing[1];
  for (int r = 0; r < 3; ++r) {
    h.direction[0][size_t(r)] = row[r] / rowLen;
    h.direction[1][size_t(r)] = -col[r] / colLen;
    h.direction[2][size_t(r)] = normal[r] / (rowLen * colLen);
    h.origin[size_t(r)] = (ipp ? double(ipp[r]) : 0.0) + ny * col[r] / colLen;
  }
  LoadedVolume out;
  out.format = "dicom";
  out.grid = checkHeader(path, h);
  out.scalars = read.scalars;
  const double slope = reader->GetRescaleSlope(), intercept = reader->GetRescaleOffset();
  if (std::isfinite(slope) && slope != 0.0 && std::isfinite(intercept)) {
    out.scalars.slope = slope;
    out.scalars.intercept = intercept;
  }
  return out;
}

}  // namespace visopt::io
