// NIfTI-1/2 (.nii, .nii.gz) through vtkNIFTIImageReader. World geometry comes from the sform
// matrix when the file has one (sform_code > 0), else from the qform, else pixdim alone — the
// precedence nibabel uses. The reader hands both matrices over in VTK data coordinates (pixdim
// factored out, slices reordered when qfac = -1), so world = M * (origin + ijk * spacing); any
// scale left in the matrix columns is folded into the spacing. The world frame stays NIfTI's RAS.
// scl_slope / scl_inter are applied to the values.
#include <cmath>

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNew.h>

#include "io/file_util.h"
#include "io/vtk_image_reading.h"
#include "io/vtk_quiet.h"
#include "visopt/error.h"

namespace visopt::io {

LoadedVolume readNifti(const std::string& path, const ProgressCallback& progress) {
  checkedFileSize(path);
  vtkNew<vtkNIFTIImageReader> reader;
  {
    VtkErrorCapture capture(reader);
    if (!reader->CanReadFile(path.c_str()))
      throwBadInput(path, "not a NIfTI file (bad header or truncated)");
  }
  reader->SetFileName(path.c_str());
  VtkImageRead read = runVtkImageReader(path, reader, progress);
  VolumeHeader h = headerFromVtkImage(read);

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
  LoadedVolume out;
  out.format = "nifti";
  out.grid = checkHeader(path, h);
  out.scalars = read.scalars;
  const double slope = reader->GetRescaleSlope(), intercept = reader->GetRescaleIntercept();
  if (std::isfinite(slope) && slope != 0.0 && std::isfinite(intercept)) {
    out.scalars.slope = slope;
    out.scalars.intercept = intercept;
  }
  return out;
}

}  // namespace visopt::io
