// Runs a VTK image reader under our rules: errors captured (never printed), dimensions checked
// from the pipeline information before the data is read, then the point scalars checked
// (present, one component, as many values as the dimensions say, a supported type).
#pragma once

#include <array>
#include <string>

#include <vtkSmartPointer.h>

#include "io/volume_source.h"

class vtkAlgorithm;
class vtkImageData;

namespace visopt::io {

struct VtkImageRead {
  vtkSmartPointer<vtkImageData> image;
  ScalarData scalars;
  std::array<int, 3> extentMin{0, 0,
                               0};  // index of the first voxel (VTK extents need not start at 0)
};

// warningsAreErrors: for readers that only warn when the data runs short (legacy VTK).
VtkImageRead runVtkImageReader(const std::string& path, vtkAlgorithm* reader,
                               const ProgressCallback& progress, bool warningsAreErrors = false);

// Geometry of a vtkImageData (spacing, origin, direction matrix), with the origin moved to the
// first voxel of the extent, as a header for checkHeader().
VolumeHeader headerFromVtkImage(const VtkImageRead& read);

}  // namespace visopt::io
