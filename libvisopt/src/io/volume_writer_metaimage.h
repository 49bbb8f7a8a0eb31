// MetaImage writer: float32 little endian, TransformMatrix / Offset / ElementSpacing from the
// grid. .mha holds the data after the header; .mhd names a "STEM.raw" file written next to it.
// Both files are written atomically (temporary sibling, then rename; data file first).
#pragma once

#include <string>

#include "visopt/volume.h"

namespace visopt::io {

void writeMetaImage(const Volume& volume, const std::string& path, bool detached);

}  // namespace visopt::io
