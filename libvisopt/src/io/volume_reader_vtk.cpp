// VTK XML image data (.vti) and legacy VTK structured points (.vtk), through VTK's readers.
// Geometry: spacing, origin and (VTK >= 9) the direction matrix of the vtkImageData.
#include <vtkNew.h>
#include <vtkStructuredPointsReader.h>
#include <vtkXMLImageDataReader.h>

#include "io/file_util.h"
#include "io/vtk_image_reading.h"
#include "io/vtk_quiet.h"
#include "visopt/error.h"

namespace visopt::io {

LoadedVolume readVtkXmlImage(const std::string& path, const ProgressCallback& progress) {
  checkedFileSize(path);
  vtkNew<vtkXMLImageDataReader> reader;
  {
    VtkErrorCapture capture(reader);
    if (!reader->CanReadFile(path.c_str()))
      throwBadInput(path, "not a VTK XML image data file (.vti)");
  }
  reader->SetFileName(path.c_str());
  VtkImageRead read = runVtkImageReader(path, reader, progress);
  LoadedVolume out;
  out.format = "vti";
  out.grid = checkHeader(path, headerFromVtkImage(read));
  out.scalars = read.scalars;
  return out;
}

LoadedVolume readVtkLegacy(const std::string& path, const ProgressCallback& progress) {
  checkedFileSize(path);
  vtkNew<vtkStructuredPointsReader> reader;
  reader->SetFileName(path.c_str());
  {
    VtkErrorCapture capture(reader);
    if (!reader->IsFileStructuredPoints())
      throwBadInput(path, "not a legacy VTK STRUCTURED_POINTS file");
  }
  reader->ReadAllScalarsOn();
  VtkImageRead read = runVtkImageReader(path, reader, progress, /*warningsAreErrors=*/true);
  LoadedVolume out;
  out.format = "vtk-legacy";
  out.grid = checkHeader(path, headerFromVtkImage(read));
  out.scalars = read.scalars;
  return out;
}

}  // namespace visopt::io
