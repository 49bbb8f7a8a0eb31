#include "io/vtk_image_reading.h"

#include <vtkAlgorithm.h>
#include <vtkDataArray.h>
#include <vtkDataObject.h>
#include <vtkDataSetAttributes.h>
#include <vtkExecutive.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkMatrix3x3.h>
#include <vtkPointData.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkType.h>

#include "io/vtk_quiet.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

std::optional<ScalarType> fromVtkType(int vtkType) {
  switch (vtkType) {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
      return ScalarType::Int8;
    case VTK_UNSIGNED_CHAR:
      return ScalarType::UInt8;
    case VTK_SHORT:
      return ScalarType::Int16;
    case VTK_UNSIGNED_SHORT:
      return ScalarType::UInt16;
    case VTK_INT:
      return ScalarType::Int32;
    case VTK_UNSIGNED_INT:
      return ScalarType::UInt32;
    case VTK_LONG:
      return sizeof(long) == 8 ? ScalarType::Int64 : ScalarType::Int32;
    case VTK_UNSIGNED_LONG:
      return sizeof(long) == 8 ? ScalarType::UInt64 : ScalarType::UInt32;
    case VTK_LONG_LONG:
    case VTK_ID_TYPE:
      return ScalarType::Int64;
    case VTK_UNSIGNED_LONG_LONG:
      return ScalarType::UInt64;
    case VTK_FLOAT:
      return ScalarType::Float32;
    case VTK_DOUBLE:
      return ScalarType::Float64;
    default:
      return std::nullopt;
  }
}

VolumeHeader dimsOnly(const int extent[6], int components) {
  VolumeHeader h;
  for (int a = 0; a < 3; ++a)
    h.dims[size_t(a)] = int64_t(extent[2 * a + 1]) - int64_t(extent[2 * a]) + 1;
  h.components = components;
  return h;
}

}  // namespace

VtkImageRead runVtkImageReader(const std::string& path, vtkAlgorithm* reader,
                               const ProgressCallback& progress, bool warningsAreErrors) {
  VtkErrorCapture capture(reader);
  auto fail = [&](const std::string& what) {
    auto detail = capture.error() ? capture.error() : capture.warning();
    throwBadInput(path, detail ? what + ": " + *detail : what);
  };

  reader->UpdateInformation();
  if (capture.error() || reader->GetErrorCode() != 0) fail("cannot read the header");
  vtkInformation* outInfo = reader->GetOutputInformation(0);
  if (!outInfo || !outInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    fail("cannot read the header (no image extent)");
  int extent[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
  int components = 1;
  if (vtkInformation* scalarInfo = vtkDataObject::GetActiveFieldInformation(
          outInfo, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS)) {
    if (scalarInfo->Has(vtkDataObject::FIELD_NUMBER_OF_COMPONENTS()))
      components = scalarInfo->Get(vtkDataObject::FIELD_NUMBER_OF_COMPONENTS());
  }
  checkHeader(path, dimsOnly(extent, components));  // before any data is allocated
  reportProgress(progress, path, 0.1f, "header");

  reader->Update();
  if (capture.error() || reader->GetErrorCode() != 0) fail("cannot read the data");
  if (warningsAreErrors && capture.warning())
    throwBadInput(path, "truncated or corrupt data: " + *capture.warning());
  VtkImageRead out;
  out.image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
  if (!out.image) fail("reader produced no image");
  vtkDataArray* array = out.image->GetPointData()->GetScalars();
  if (!array && out.image->GetPointData()->GetNumberOfArrays() > 0)
    array = out.image->GetPointData()->GetArray(0);
  if (!array) fail("no scalar values in the file (truncated or empty data)");
  if (array->GetNumberOfComponents() != 1)
    throwBadInput(path, "multi-component data (" + std::to_string(array->GetNumberOfComponents()) +
                            " components per voxel) is not supported; need one scalar per voxel");
  auto type = fromVtkType(array->GetDataType());
  if (!type)
    throwBadInput(path, std::string("unsupported scalar type ") + array->GetDataTypeAsString());

  int dataExtent[6];
  out.image->GetExtent(dataExtent);
  VolumeHeader h = dimsOnly(dataExtent, 1);
  GridSpec grid = checkHeader(path, h);
  const auto tuples = static_cast<size_t>(array->GetNumberOfTuples());
  if (tuples != grid.voxelCount())
    throwBadInput(path, "truncated: header describes " + std::to_string(grid.voxelCount()) +
                            " voxels, file holds " + std::to_string(tuples));
  out.extentMin = {dataExtent[0], dataExtent[2], dataExtent[4]};
  out.scalars.type = *type;
  out.scalars.count = tuples;
  out.scalars.data = array->GetVoidPointer(0);
  out.scalars.owner = std::make_shared<vtkSmartPointer<vtkDataArray>>(array);
  return out;
}

VolumeHeader headerFromVtkImage(const VtkImageRead& read) {
  VolumeHeader h;
  int extent[6];
  read.image->GetExtent(extent);
  for (int a = 0; a < 3; ++a) h.dims[size_t(a)] = int64_t(extent[2 * a + 1]) - extent[2 * a] + 1;
  double spacing[3], origin[3];
  read.image->GetSpacing(spacing);
  read.image->GetOrigin(origin);
  vtkMatrix3x3* m = read.image->GetDirectionMatrix();
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      h.direction[size_t(c)][size_t(r)] = m ? m->GetElement(r, c) : (r == c);
  for (int a = 0; a < 3; ++a) h.spacing[size_t(a)] = spacing[a];
  // World position of the first voxel: origin + D * (extentMin * spacing).
  for (int r = 0; r < 3; ++r) {
    double p = origin[r];
    for (int c = 0; c < 3; ++c)
      p += h.direction[size_t(c)][size_t(r)] * double(read.extentMin[size_t(c)]) * spacing[c];
    h.origin[size_t(r)] = p;
  }
  return h;
}

}  // namespace visopt::io
