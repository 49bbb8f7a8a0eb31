// NIfTI-1/2 (.nii, .nii.gz) through vtkNIFTIImageReader. World geometry comes from the sform
// matrix when the file has one (sform_code > 0), else from the qform, else pixdim alone — the
// precedence nibabel uses. The reader hands both matrices over in VTK data coordinates (pixdim
// factored out, slices reordered when qfac = -1), so world = M * (origin + ijk * spacing); any
// scale left in the matrix columns is folded into the spacing. The world frame stays NIfTI's RAS.
// scl_slope / scl_inter are applied to the values.
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <vtkDataObject.h>
#include <vtkDataSetAttributes.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNew.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include "io/file_util.h"
#include "io/vtk_image_reading.h"
#include "io/vtk_quiet.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

// The header fields vtkNIFTIImageReader trusts, checked before it sees the file: a datatype it
// does not know with bitpix 0, or a dim it multiplies without bounds, crashed it (mutants of a
// valid file, issue 13). NIfTI-1 (348-byte header) and NIfTI-2 (540), either byte order; .nii.gz
// is inflated as far as the header. Throws BadInput naming the field.
template <class T>
T field(const unsigned char* h, size_t offset, bool swap) {
  T v;
  std::memcpy(&v, h + offset, sizeof v);
  if (swap) swapBytesInPlace(&v, 1, sizeof v);
  return v;
}

// A count that may exceed every integer type (a mutated header's dims multiply to 1e24).
std::string wholeNumber(double v) {
  std::ostringstream text;
  text.precision(15);
  text << v;
  return text.str();
}

// What checkNiftiHeader found: where the data lies and how it is stored.
struct NiftiFileHeader {
  bool gz = false;
  bool swap = false;  // the file's byte order is not the host's
  ScalarType type = ScalarType::Int16;
  double offset = 0.0;     // vox_offset
  double bytes = 0.0;      // of the data, all dims (time frames and vector planes included)
  uint64_t available = 0;  // the file's size (inflated, for .gz)
};

std::optional<ScalarType> niftiScalarType(int16_t datatype) {
  switch (datatype) {
    case 2:
      return ScalarType::UInt8;
    case 4:
      return ScalarType::Int16;
    case 8:
      return ScalarType::Int32;
    case 16:
      return ScalarType::Float32;
    case 64:
      return ScalarType::Float64;
    case 256:
      return ScalarType::Int8;
    case 512:
      return ScalarType::UInt16;
    case 768:
      return ScalarType::UInt32;
    default:
      return std::nullopt;
  }
}

// The checks on the header alone (everything but checkNiftiData's).
NiftiFileHeader parseNiftiHeader(const std::string& path, uint64_t fileSize) {
  unsigned char h[540] = {};
  const bool gz = endsWithNoCase(path, ".gz");
  size_t got = 0;
  // A compressed file is inflated once first, streamed: its CRC checked (VTK's reader stops
  // before the trailer) and its size known before VTK allocates for the data.
  const uint64_t available = gz ? inflatedSize(path) : fileSize;
  if (gz) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (!f) throwBadInput(path, "cannot open");
    const int n = gzread(f, h, sizeof h);
    gzclose(f);
    got = n > 0 ? size_t(n) : 0;
  } else {
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(h), sizeof h);
    got = size_t(in.gcount());
  }
  if (got < 348) throwBadInput(path, "truncated: shorter than a NIfTI header (348 bytes)");
  int32_t size = field<int32_t>(h, 0, false);
  const bool swap = size != 348 && size != 540;
  if (swap) size = field<int32_t>(h, 0, true);
  if (size != 348 && size != 540) throwBadInput(path, "not a NIfTI file (bad header size)");
  const bool two = size == 540;
  if (two && got < 540) throwBadInput(path, "truncated: shorter than a NIfTI-2 header");
  const int16_t datatype = field<int16_t>(h, two ? 12 : 70, swap);
  const int16_t bitpix = field<int16_t>(h, two ? 14 : 72, swap);
  struct Known {
    int16_t type, bits;
  };
  static const Known known[] = {{2, 8},   {4, 16},  {8, 32},   {16, 32},
                                {64, 64}, {256, 8}, {512, 16}, {768, 32}};
  bool supported = false;
  for (const Known& k : known) supported = supported || (k.type == datatype && k.bits == bitpix);
  if (!supported)
    throwBadInput(path, "unsupported NIfTI datatype " + std::to_string(datatype) + " with " +
                            std::to_string(bitpix) +
                            " bits per value (need one scalar of "
                            "8, 16, 32 or 64 bits)");
  int64_t dims[8];
  for (int d = 0; d < 8; ++d)
    dims[d] = two ? field<int64_t>(h, 16 + 8 * size_t(d), swap)
                  : int64_t(field<int16_t>(h, 40 + 2 * size_t(d), swap));
  if (dims[0] < 1 || dims[0] > 7)
    throwBadInput(path, "invalid NIfTI dim[0] " + std::to_string(dims[0]) + " (must be 1..7)");
  double bytes = double(bitpix) / 8.0;
  for (int d = 1; d <= dims[0]; ++d) {
    if (dims[d] < 1)
      throwBadInput(path, "invalid NIfTI dim[" + std::to_string(d) + "] " +
                              std::to_string(dims[d]) + " (each must be >= 1)");
    bytes *= double(dims[d]);
  }
  const double offset =
      two ? double(field<int64_t>(h, 168, swap)) : double(field<float>(h, 108, swap));
  if (!(offset >= double(size)) || !std::isfinite(offset))
    throwBadInput(path, "invalid NIfTI vox_offset (must lie after the header)");
  for (int d = 1; d <= 3; ++d) {
    const double pixdim = two ? field<double>(h, 104 + 8 * size_t(d), swap)
                              : field<float>(h, 76 + 4 * size_t(d), swap);
    if (!std::isfinite(pixdim)) throwBadInput(path, "invalid NIfTI pixdim (not finite)");
  }
  NiftiFileHeader out;
  out.gz = gz;
  out.swap = swap;
  out.type = niftiScalarType(datatype).value_or(ScalarType::Int16);  // known: supported above
  out.offset = offset;
  out.bytes = bytes;
  out.available = available;
  return out;
}

// The data must be in the file before VTK allocates for it.
void checkNiftiData(const std::string& path, const NiftiFileHeader& f) {
  if (f.offset + f.bytes > double(f.available))
    throwBadInput(path, "truncated: the header describes " + wholeNumber(f.bytes) +
                            " bytes of data after offset " + wholeNumber(f.offset) +
                            ", the file has " + wholeNumber(double(f.available)) + " bytes" +
                            (f.gz ? " once inflated" : ""));
}

void checkNiftiHeader(const std::string& path, uint64_t fileSize) {
  checkNiftiData(path, parseNiftiHeader(path, fileSize));
}

// World geometry from the sform (else qform) matrix of a reader that has read the header: `h`
// holds VTK's data geometry (spacing, zero origin, identity direction); see the top of the file.
void applyNiftiMatrix(const std::string& path, vtkNIFTIImageReader* reader, VolumeHeader& h) {
  vtkMatrix4x4* m = reader->GetSFormMatrix();
  if (!m) m = reader->GetQFormMatrix();
  if (m) {
    // vtkImageData origin/direction from the NIfTI reader are identity/zero; compose anyway.
    std::array<double, 3> first{};
    for (int r = 0; r < 3; ++r) {
      double p = m->GetElement(r, 3);
      for (int c = 0; c < 3; ++c) p += m->GetElement(r, c) * h.origin[size_t(c)];
      first[size_t(r)] = p;
    }
    h.origin = first;
    for (int c = 0; c < 3; ++c) {
      double col[3] = {m->GetElement(0, c), m->GetElement(1, c), m->GetElement(2, c)};
      double len = std::sqrt(col[0] * col[0] + col[1] * col[1] + col[2] * col[2]);
      if (!(len > 0.0)) throwBadInput(path, "degenerate orientation matrix (zero column)");
      h.spacing[size_t(c)] *= len;
      for (int r = 0; r < 3; ++r) h.direction[size_t(c)][size_t(r)] = col[r] / len;
    }
  }
}

// scl_slope / scl_inter, when usable (a zero or non-finite slope means "not rescaled").
void niftiRescale(vtkNIFTIImageReader* reader, double& slope, double& intercept) {
  const double s = reader->GetRescaleSlope(), i = reader->GetRescaleIntercept();
  if (std::isfinite(s) && s != 0.0 && std::isfinite(i)) {
    slope = s;
    intercept = i;
  }
}

}  // namespace

LoadedVolume readNifti(const std::string& path, const ProgressCallback& progress) {
  checkNiftiHeader(path, checkedFileSize(path));
  vtkNew<vtkNIFTIImageReader> reader;
  {
    VtkErrorCapture capture(reader);
    if (!reader->CanReadFile(path.c_str()))
      throwBadInput(path, "not a NIfTI file (bad header or truncated)");
  }
  reader->SetFileName(path.c_str());
  VtkImageRead read = runVtkImageReader(path, reader, progress);
  VolumeHeader h = headerFromVtkImage(read);
  applyNiftiMatrix(path, reader, h);
  LoadedVolume out;
  out.format = "nifti";
  out.grid = checkHeader(path, h);
  out.scalars = read.scalars;
  niftiRescale(reader, out.scalars.slope, out.scalars.intercept);
  return out;
}

VolumeLayout niftiLayout(const std::string& path, bool wholeInMemory) {
  const NiftiFileHeader file = parseNiftiHeader(path, checkedFileSize(path));
  vtkNew<vtkNIFTIImageReader> reader;
  VtkErrorCapture capture(reader);
  if (!reader->CanReadFile(path.c_str()))
    throwBadInput(path, "not a NIfTI file (bad header or truncated)");
  capture.clear();
  reader->SetFileName(path.c_str());
  reader->UpdateInformation();  // the header only: RequestInformation reads no data
  auto detail = capture.error();
  if (detail || reader->GetErrorCode() != 0)
    throwBadInput(path, "cannot read the header" + (detail ? ": " + *detail : std::string()));
  vtkInformation* info = reader->GetOutputInformation(0);
  if (!info || !info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    throwBadInput(path, "cannot read the header (no image extent)");
  // What headerFromVtkImage gives for the image VTK would read: extent, spacing, origin (zero),
  // identity direction.
  int extent[6];
  info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
  double spacing[3] = {1, 1, 1}, origin[3] = {0, 0, 0};
  if (info->Has(vtkDataObject::SPACING())) info->Get(vtkDataObject::SPACING(), spacing);
  if (info->Has(vtkDataObject::ORIGIN())) info->Get(vtkDataObject::ORIGIN(), origin);
  VolumeHeader h;
  h.type = file.type;
  if (vtkInformation* scalarInfo = vtkDataObject::GetActiveFieldInformation(
          info, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS))
    if (scalarInfo->Has(vtkDataObject::FIELD_NUMBER_OF_COMPONENTS()))
      h.components = scalarInfo->Get(vtkDataObject::FIELD_NUMBER_OF_COMPONENTS());
  for (int a = 0; a < 3; ++a) {
    h.dims[size_t(a)] = int64_t(extent[2 * a + 1]) - extent[2 * a] + 1;
    h.spacing[size_t(a)] = spacing[a];
    h.origin[size_t(a)] = origin[a] + double(extent[2 * a]) * spacing[a];
  }
  applyNiftiMatrix(path, reader, h);

  VolumeLayout layout;
  layout.format = "nifti";
  layout.headerPath = path;
  layout.header = h;
  layout.grid = checkHeader(path, h, wholeInMemory);
  layout.dataPath = path;
  layout.dataOffset = uint64_t(file.offset);  // as VTK's SetHeaderSize(unsigned long(vox_offset))
  layout.bigEndian = file.swap != hostIsBigEndian();
  layout.compressed = file.gz;
  layout.reversedSlices = reader->GetQFac() < 0;  // VTK reads the slices in reverse order
  niftiRescale(reader, layout.slope, layout.intercept);
  return layout;
}

}  // namespace visopt::io
