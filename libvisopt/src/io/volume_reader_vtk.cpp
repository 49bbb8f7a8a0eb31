// VTK XML image data (.vti) and legacy VTK structured points (.vtk), through VTK's readers.
// Geometry: spacing, origin and (VTK >= 9) the direction matrix of the vtkImageData.
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <vtkNew.h>
#include <vtkStructuredPointsReader.h>
#include <vtkXMLImageDataReader.h>

#include "io/file_util.h"
#include "io/text_header.h"
#include "io/vti_header.h"
#include "io/vtk_image_reading.h"
#include "io/vtk_quiet.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

// The legacy header, checked line by line before vtkStructuredPointsReader parses it (issue 13:
// a keyword glued to another, "fieldSPACING", sent it into a FIELD block it then dereferenced
// as null). Accepted: the version line, a title, ASCII or BINARY, DATASET STRUCTURED_POINTS,
// then DIMENSIONS, ORIGIN and SPACING (or ASPECT_RATIO) with three numbers each, POINT_DATA
// with the voxel count, SCALARS NAME TYPE [1] and LOOKUP_TABLE NAME (keywords in any case, as
// VTK reads them), and for binary files the bytes those scalars need.
void checkLegacyHeader(const std::string& path, uint64_t fileSize) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  size_t lineNumber = 0;
  auto next = [&] {
    while (std::getline(in, line)) {
      ++lineNumber;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (lineNumber <= 2 || line.find_first_not_of(" \t") != std::string::npos) return true;
    }
    return false;
  };
  auto bad = [&](const std::string& what) {
    std::string shown = line.substr(0, 40);
    for (char& c : shown)
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    throwBadInput(path, "legacy VTK header line " + std::to_string(lineNumber) + " (\"" + shown +
                            "\"): " + what);
  };
  if (!next() || line.rfind("# vtk DataFile Version", 0) != 0) bad("not a legacy VTK file");
  if (!next()) bad("truncated after the version line");  // the title: anything
  if (!next()) bad("truncated before ASCII/BINARY");
  const std::string mode = toLower(trim(line));
  if (mode != "ascii" && mode != "binary") bad("expected ASCII or BINARY");
  if (!next() || toLower(trim(line)) != "dataset structured_points")
    bad("expected DATASET STRUCTURED_POINTS");
  std::array<double, 3> dims{-1, -1, -1};
  for (;;) {
    if (!next()) bad("truncated before POINT_DATA");
    std::istringstream words(line);
    std::string key, rest;
    words >> key;
    key = toLower(key);
    if (key == "dimensions" || key == "origin" || key == "spacing" || key == "aspect_ratio") {
      std::array<double, 3> v{};
      if (!(words >> v[0] >> v[1] >> v[2]) || (words >> rest)) bad("expected three numbers");
      for (double x : v)
        if (!std::isfinite(x)) bad("a number is not finite");
      if (key == "dimensions") dims = v;
    } else if (key == "point_data") {
      double n = -1;
      if (!(words >> n) || (words >> rest)) bad("expected the point count");
      for (double d : dims)
        if (!(d >= 1 && d <= double(1 << 30) && d == std::floor(d)))
          bad("DIMENSIONS must come first, three whole numbers >= 1");
      if (n != dims[0] * dims[1] * dims[2]) bad("the point count differs from DIMENSIONS");
      break;
    } else {
      bad("unexpected keyword (DIMENSIONS, ORIGIN, SPACING, POINT_DATA are read)");
    }
  }
  if (!next()) bad("truncated before SCALARS");
  std::istringstream scalars(line);
  std::string key, name, type, rest;
  int components = 1;
  scalars >> key >> name >> type;
  if (toLower(key) != "scalars" || name.empty() || type.empty())
    bad("expected SCALARS NAME TYPE (one scalar array is read)");
  if ((scalars >> components) && components != 1) bad("only one component per voxel is read");
  static const std::pair<const char*, size_t> kTypes[] = {
      {"bit", 0},          {"unsigned_char", 1}, {"char", 1},   {"unsigned_short", 2},
      {"short", 2},        {"unsigned_int", 4},  {"int", 4},    {"unsigned_long", 8},
      {"long", 8},         {"float", 4},         {"double", 8}, {"vtktypeint64", 8},
      {"vtktypeuint64", 8}};
  size_t bytes = size_t(-1);
  for (const auto& [t, b] : kTypes)
    if (toLower(type) == t) bytes = b;
  if (bytes == size_t(-1) || bytes == 0) bad("unsupported scalar type");
  if (!next()) bad("truncated before LOOKUP_TABLE");
  std::istringstream table(line);
  table >> key >> name;
  if (toLower(key) != "lookup_table" || name.empty()) bad("expected LOOKUP_TABLE NAME");
  if (mode == "binary") {
    const auto at = in.tellg();
    const double need = dims[0] * dims[1] * dims[2] * double(bytes);
    if (at < 0 || double(at) + need > double(fileSize))
      throwBadInput(path, "truncated: the header describes " + std::to_string(uint64_t(need)) +
                              " bytes of scalars, fewer remain");
  }
}

}  // namespace

LoadedVolume readVtkXmlImage(const std::string& path, const ProgressCallback& progress) {
  checkVtiHeader(path);
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
  checkLegacyHeader(path, checkedFileSize(path));
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
