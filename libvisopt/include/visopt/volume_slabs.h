// Reading a volume file by z slabs: the header is parsed (and checked) without reading any data,
// then any range of z slices is read with one offset read (a seek and a read of just its bytes).
// For distributed generation, where each process reads only its part and none may hold the
// whole volume: unlike readVolume, the whole volume need not fit in memory, only a slab.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "visopt/grid.h"

namespace visopt {

// A volume file read by z slabs (slices [zBegin, zEnd) of the index grid), each with one offset
// read of just its bytes. Supported: raw with a JSON sidecar (.raw + .raw.json, as readVolume),
// MetaImage (.mha/.mhd) and NIfTI (.nii), uncompressed. Others (compressed, DICOM, VTK, NRRD...)
// are refused with Error(BadInput) "PATH: ... cannot be read by slabs; supported: ...".
// Header problems are refused as readVolume refuses them (Error(BadInput) "PATH: ..."), except
// that the volume need not fit in memory and data missing from the file is only reported by
// the readSlices call that needs it.
class VolumeSlabReader {
 public:
  explicit VolumeSlabReader(const std::string& path);  // reads and checks the header only

  const std::string& path() const;
  const std::string& format()
      const;                     // as readVolume's loaders name it: "raw", "metaimage", "nifti"
  const GridSpec& grid() const;  // exactly the GridSpec readVolume(path) gives
  const std::vector<std::string>& warnings() const;  // as Volume::warnings

  // Physical values (slope * stored + intercept, in double as readVolume computes them) of
  // slices [zBegin, zEnd), x fastest, (z - zBegin) slowest: value (i, j, k) is the one
  // readVolume(path) normalises at grid().linearIndex(i, j, k). Throws Error(Usage) for a range
  // that is empty or outside [0, dims.z), or a slab that does not fit in the available memory;
  // Error(BadInput) "PATH: ..." when the file is shorter than the slab's bytes (naming the data
  // file) or the slab holds NaN or Inf values (which readVolume refuses too).
  std::vector<double> readSlices(int zBegin, int zEnd) const;

 private:
  struct Layout;
  std::shared_ptr<const Layout> layout_;
};

}  // namespace visopt
