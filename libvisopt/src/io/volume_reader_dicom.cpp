// A DICOM series given as a folder (uncompressed transfer syntaxes, one series per folder).
// Each file is opened with vtkDICOMImageReader on its own, so the slice geometry is ours to
// check: every slice must have the same size, type, pixel spacing and orientation; slices are
// sorted by their position along the normal (row x column direction) and must be evenly
// spaced. Geometry is DICOM patient space (LPS):
//   vtkDICOMImageReader stores each slice bottom row first, so index j runs against the DICOM
//   column direction: direction = (row, -column, normal), origin = the position of the first
//   slice's bottom-left pixel.
// The reader applies the rescale slope/intercept itself. It also takes the first value of
// PixelSpacing (the spacing between rows, along j) as the x spacing; the DICOM meaning is
// restored here.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <utility>
#include <vector>

#include <vtkDICOMImageReader.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include "io/dicom_elements.h"
#include "io/file_util.h"
#include "io/vtk_image_reading.h"
#include "io/vtk_quiet.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

// A gap between neighbouring slices may differ from the series' median gap by this fraction
// of it (a missing slice doubles a gap, an extra one halves it); within it the series loads on
// its mean spacing, with a warning once the gaps vary by more than kSliceJitterWarning mm
// (Slicer's default tolerance for irregular geometry).
constexpr double kSliceGapTolerance = 0.25;
constexpr double kSliceJitterWarning = 0.01;

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

struct Slice {
  std::string file;
  int width = 0, height = 0;
  double spacing[2] = {1, 1};  // along i (columns), along j (rows)
  double row[3] = {1, 0, 0}, col[3] = {0, 1, 0};
  double position[3] = {0, 0, 0};
  double along = 0;  // position . normal
};

double dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

bool near(double a, double b, double tol) {
  return std::abs(a - b) <= tol * std::max(1.0, std::abs(a));
}

}  // namespace

LoadedVolume readDicomSeries(const std::string& path, const ProgressCallback& progress) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(path, ec))
    if (entry.is_regular_file(ec)) files.push_back(entry.path().string());
  if (ec) throwBadInput(path, "cannot list the folder (" + ec.message() + ")");
  if (files.empty()) throwBadInput(path, "folder holds no files (expected a DICOM series)");
  std::sort(files.begin(), files.end());

  CerrSilencer silence;
  std::vector<Slice> slices;
  for (const std::string& file : files) {
    vtkNew<vtkDICOMImageReader> reader;
    VtkErrorCapture capture(reader);
    if (!reader->CanReadFile(file.c_str())) continue;  // DICOMDIR-less extras, notes, ...
    checkDicomElements(path, file);
    reader->SetFileName(file.c_str());
    reader->UpdateInformation();
    if (capture.error() || reader->GetErrorCode() != 0)
      throwBadInput(path, fileName(file) + ": cannot read the DICOM header" +
                              (capture.error() ? ": " + *capture.error() : std::string()));
    int extent[6];
    reader->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
    Slice s;
    s.file = file;
    s.width = extent[1] - extent[0] + 1;
    s.height = extent[3] - extent[2] + 1;
    if (extent[5] != extent[4])
      throwBadInput(path, fileName(file) + ": multi-frame DICOM files are not supported");
    const double* ps = reader->GetPixelSpacing();
    s.spacing[0] = ps[1];  // see the note on PixelSpacing above
    s.spacing[1] = ps[0];
    const float* iop = reader->GetImageOrientationPatient();
    const float* ipp = reader->GetImagePositionPatient();
    for (int r = 0; r < 3; ++r) {
      s.row[r] = iop[r];
      s.col[r] = iop[r + 3];
      s.position[r] = ipp[r];
    }
    const double rl = std::sqrt(dot(s.row, s.row)), cl = std::sqrt(dot(s.col, s.col));
    if (rl < 0.5 || cl < 0.5) {  // no orientation given: assume axial
      s.row[0] = 1, s.row[1] = 0, s.row[2] = 0;
      s.col[0] = 0, s.col[1] = 1, s.col[2] = 0;
    } else {
      for (int r = 0; r < 3; ++r) s.row[r] /= rl, s.col[r] /= cl;
    }
    slices.push_back(s);
  }
  if (slices.empty()) throwBadInput(path, "no DICOM files in the folder");

  const Slice& first = slices.front();
  double normal[3] = {first.row[1] * first.col[2] - first.row[2] * first.col[1],
                      first.row[2] * first.col[0] - first.row[0] * first.col[2],
                      first.row[0] * first.col[1] - first.row[1] * first.col[0]};
  for (Slice& s : slices) {
    if (s.width != first.width || s.height != first.height)
      throwBadInput(path, fileName(s.file) + ": slice size differs from the rest of the series");
    for (int r = 0; r < 3; ++r)
      if (!near(s.row[r], first.row[r], 1e-3) || !near(s.col[r], first.col[r], 1e-3))
        throwBadInput(path, fileName(s.file) + ": slice orientation differs from the series");
    if (!near(s.spacing[0], first.spacing[0], 1e-4) || !near(s.spacing[1], first.spacing[1], 1e-4))
      throwBadInput(path, fileName(s.file) + ": pixel spacing differs from the series");
    s.along = dot(s.position, normal);
  }
  std::sort(slices.begin(), slices.end(),
            [](const Slice& a, const Slice& b) { return a.along < b.along; });
  double sliceSpacing = 1.0;
  std::vector<std::string> warnings;
  if (slices.size() > 1) {
    sliceSpacing = (slices.back().along - slices.front().along) / double(slices.size() - 1);
    for (size_t s = 1; s < slices.size(); ++s)
      if (!(slices[s].along - slices[s - 1].along > 1e-6))
        throwBadInput(path, fileName(slices[s].file) + " and " + fileName(slices[s - 1].file) +
                                ": two slices at the same position");
    // Clinical series carry positions rounded to a few decimals, and a slightly oblique stack
    // projects them unevenly onto the normal: gaps of 6.96-7.07 mm in a 7 mm series are normal.
    // ITK's ImageSeriesReader and Slicer load such series with a warning (Slicer's default
    // tolerance is 0.01 mm) on the mean spacing; so does visopt. Refused is only a real gap, a
    // missing or an extra slice: a gap off the median by more than kSliceGapTolerance of it.
    std::vector<double> gaps;
    for (size_t s = 1; s < slices.size(); ++s)
      gaps.push_back(slices[s].along - slices[s - 1].along);
    std::vector<double> sorted = gaps;
    std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    double lo = gaps.front(), hi = gaps.front();
    for (size_t s = 0; s < gaps.size(); ++s) {
      if (std::abs(gaps[s] - median) > kSliceGapTolerance * median) {
        char message[256];
        std::snprintf(message, sizeof message,
                      "%s and %s are %.4g mm apart where the series' slices are %.4g mm apart "
                      "(a missing or extra slice?)",
                      fileName(slices[s].file).c_str(), fileName(slices[s + 1].file).c_str(),
                      gaps[s], median);
        throwBadInput(path, message);
      }
      lo = std::min(lo, gaps[s]);
      hi = std::max(hi, gaps[s]);
    }
    if (hi - lo > kSliceJitterWarning) {
      char message[256];
      std::snprintf(message, sizeof message,
                    "%s: slice spacing varies from %.4g to %.4g mm (positions rounded in the "
                    "headers, or an oblique stack); using the mean, %.4g mm",
                    path.c_str(), lo, hi, sliceSpacing);
      warnings.push_back(message);
    }
  }

  VolumeHeader h;
  h.dims = {first.width, first.height, int64_t(slices.size())};
  h.spacing = {first.spacing[0], first.spacing[1], sliceSpacing};
  const double columnRun = double(first.height - 1) * first.spacing[1];
  for (int r = 0; r < 3; ++r) {
    h.direction[0][size_t(r)] = first.row[r];
    h.direction[1][size_t(r)] = -first.col[r];
    h.direction[2][size_t(r)] = normal[r];
    h.origin[size_t(r)] = slices.front().position[r] + columnRun * first.col[r];
  }
  LoadedVolume out;
  out.format = "dicom";
  out.warnings = std::move(warnings);
  out.grid = checkHeader(path, h);  // before any pixel data is read
  reportProgress(progress, path, 0.1f, "header");

  const size_t perSlice = size_t(first.width) * size_t(first.height);
  std::shared_ptr<unsigned char[]> buffer;
  for (size_t s = 0; s < slices.size(); ++s) {
    vtkNew<vtkDICOMImageReader> reader;
    reader->SetFileName(slices[s].file.c_str());
    VtkImageRead read = runVtkImageReader(path + "/" + fileName(slices[s].file), reader, {});
    if (read.scalars.count != perSlice)
      throwBadInput(path, fileName(slices[s].file) + ": truncated pixel data");
    if (s == 0) {
      out.scalars.type = read.scalars.type;
      out.scalars.count = perSlice * slices.size();
      buffer = std::make_shared_for_overwrite<unsigned char[]>(out.scalars.count *
                                                               scalarTypeSize(read.scalars.type));
    } else if (read.scalars.type != out.scalars.type) {
      throwBadInput(path, fileName(slices[s].file) + ": pixel type differs from the series");
    }
    const size_t bytes = perSlice * scalarTypeSize(read.scalars.type);
    std::memcpy(buffer.get() + s * bytes, read.scalars.data, bytes);
  }
  out.scalars.data = buffer.get();
  out.scalars.owner = std::shared_ptr<const void>(buffer, buffer.get());
  return out;
}

}  // namespace visopt::io
