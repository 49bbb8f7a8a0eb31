// A scalar volume as it flows through visopt: grid geometry from the file and the scalars,
// stored normalised to [0, 1] over [valueMin, valueMax] (so fp16 storage keeps its precision
// whatever the data's units are).
#pragma once

#include <string>
#include <vector>

#include "visopt/field.h"
#include "visopt/grid.h"

namespace visopt {

struct Volume {
  std::string name;        // a short name for display
  std::string sourcePath;  // the file or folder it came from; "builtin:NAME" for scenes
  std::string scalarType;  // type on disk: "uint8", "int16", "float32", ...
  double valueMin = 0.0;
  double valueMax = 1.0;
  Field3D normalized;  // (value - valueMin) / (valueMax - valueMin)
  // What the reader accepted but a user should know, one line each, naming the file (a DICOM
  // series whose slice spacing varies within the tolerance, ...). Shown by the CLI and the
  // workstation; empty for clean data.
  std::vector<std::string> warnings;

  const GridSpec& grid() const { return normalized.grid(); }
  double toValue(float t) const { return valueMin + t * (valueMax - valueMin); }
  float toNormalized(double value) const {
    return valueMax > valueMin ? static_cast<float>((value - valueMin) / (valueMax - valueMin))
                               : 0.f;
  }
};

}  // namespace visopt
