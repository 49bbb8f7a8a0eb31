// writeVolume: float32 in original units (valueMin + t * (valueMax - valueMin)), geometry kept,
// format chosen by extension: .vti (VTK XML), .nii / .nii.gz (NIfTI, sform = direction and
// origin; qform too when the orientation is a proper rotation), .mha / .mhd (MetaImage, written
// in volume_writer_metaimage.cpp). Atomic: written to a temporary sibling, then renamed.
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataWriter.h>

#include "io/file_util.h"
#include "io/volume_writer_metaimage.h"
#include "io/vtk_quiet.h"
#include "visopt/error.h"
#include "visopt/volume_io.h"

namespace visopt {

namespace {

[[noreturn]] void writeFailure(const std::string& path, const std::string& problem) {
  throw Error(ErrorKind::Failure, path + ": " + problem);
}

vtkNew<vtkImageData> toVtkImage(const Volume& volume, bool withGeometry) {
  const GridSpec& g = volume.grid();
  vtkNew<vtkImageData> image;
  image->SetDimensions(g.dims.x, g.dims.y, g.dims.z);
  image->SetSpacing(g.spacing.x, g.spacing.y, g.spacing.z);
  if (withGeometry) {
    image->SetOrigin(g.origin.x, g.origin.y, g.origin.z);
    double d[9];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) d[r * 3 + c] = g.direction[c][r];
    image->SetDirectionMatrix(d);
  }
  vtkNew<vtkFloatArray> values;
  values->SetName("volume");
  values->SetNumberOfComponents(1);
  const size_t n = g.voxelCount();
  values->SetNumberOfTuples(static_cast<vtkIdType>(n));
  float* out = values->GetPointer(0);
  for (size_t i = 0; i < n; ++i) out[i] = float(volume.toValue(volume.normalized.get(i)));
  image->GetPointData()->SetScalars(values);
  return image;
}

void writeVti(const Volume& volume, const std::string& path, const std::string& tmp) {
  vtkNew<vtkImageData> image = toVtkImage(volume, true);
  vtkNew<vtkXMLImageDataWriter> writer;
  io::VtkErrorCapture capture(writer);
  writer->SetInputData(image);
  writer->SetFileName(tmp.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToZLib();
  if (writer->Write() != 1 || capture.error())
    writeFailure(path,
                 "cannot write VTK XML image data: " + capture.error().value_or("write failed"));
}

void writeNifti(const Volume& volume, const std::string& path, const std::string& tmp) {
  const GridSpec& g = volume.grid();
  vtkNew<vtkImageData> image = toVtkImage(volume, false);
  vtkNew<vtkMatrix4x4> m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m->SetElement(r, c, g.direction[c][r]);
    m->SetElement(r, 3, g.origin[r]);
  }
  vtkNew<vtkNIFTIImageWriter> writer;
  io::VtkErrorCapture capture(writer);
  writer->SetInputData(image);
  writer->SetFileName(tmp.c_str());
  writer->SetSFormMatrix(m);
  if (glm::determinant(g.direction) > 0.f) writer->SetQFormMatrix(m);
  writer->Write();
  if (writer->GetErrorCode() != 0 || capture.error())
    writeFailure(path, "cannot write NIfTI: " + capture.error().value_or("write failed"));
}

}  // namespace

void writeVolume(const Volume& volume, const std::string& path) {
  if (volume.normalized.empty()) throw Error(ErrorKind::Usage, path + ": volume holds no data");
  enum class Kind { Vti, Nifti, NiftiGz, Mha, Mhd } kind;
  if (io::endsWithNoCase(path, ".vti"))
    kind = Kind::Vti;
  else if (io::endsWithNoCase(path, ".nii.gz"))
    kind = Kind::NiftiGz;
  else if (io::endsWithNoCase(path, ".nii"))
    kind = Kind::Nifti;
  else if (io::endsWithNoCase(path, ".mha"))
    kind = Kind::Mha;
  else if (io::endsWithNoCase(path, ".mhd"))
    kind = Kind::Mhd;
  else
    throw Error(ErrorKind::Usage,
                path + ": unknown output volume format (use .vti, .nii, .nii.gz, .mha or .mhd)");

  if (kind == Kind::Mha || kind == Kind::Mhd) {
    io::writeMetaImage(volume, path, kind == Kind::Mhd);
    return;
  }
  const std::string suffix = kind == Kind::Vti ? ".vti" : kind == Kind::Nifti ? ".nii" : ".nii.gz";
  const std::string tmp = io::makeTemporarySibling(path, suffix);
  try {
    if (kind == Kind::Vti)
      writeVti(volume, path, tmp);
    else
      writeNifti(volume, path, tmp);
  } catch (...) {
    io::discardTemporary(tmp);
    throw;
  }
  io::commitTemporary(tmp, path);
}

}  // namespace visopt
