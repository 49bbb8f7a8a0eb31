// gOpenMol PLT (.plt): five int32 (rank = 3, surface type, nz, ny, nx), six float32 extents
// (zmin, zmax, ymin, ymax, xmin, xmax: outer edges of the cell-centred grid), then float32
// values x fastest. Spacing = (max - min) / n; origin = min + spacing / 2 (voxel centres), as
// GridDataFormats reads it. Little-endian files; a big-endian file is recognised by its rank.
#include <cstring>

#include "io/file_util.h"
#include "io/text_header.h"
#include "io/volume_source.h"
#include "visopt/error.h"

namespace visopt::io {

LoadedVolume readGOpenMolPlt(const std::string& path, const ProgressCallback& progress) {
  const uint64_t size = checkedFileSize(path);
  const std::string head = readFilePrefix(path, 44);
  if (size < 44 || head.size() < 44) throwBadInput(path, "truncated: shorter than a PLT header");
  int32_t ints[5];
  float extents[6];
  std::memcpy(ints, head.data(), sizeof(ints));
  std::memcpy(extents, head.data() + 20, sizeof(extents));
  bool bigEndian = hostIsBigEndian();
  if (ints[0] != 3) {
    swapBytesInPlace(ints, 5, 4);
    swapBytesInPlace(extents, 6, 4);
    bigEndian = !bigEndian;
    if (ints[0] != 3) throwBadInput(path, "not a gOpenMol PLT file (rank is not 3)");
  }
  VolumeHeader h;
  h.type = ScalarType::Float32;
  h.dims = {ints[4], ints[3], ints[2]};
  const float mins[3] = {extents[4], extents[2], extents[0]};
  const float maxs[3] = {extents[5], extents[3], extents[1]};
  for (int a = 0; a < 3; ++a) {
    const size_t s = size_t(a);
    h.spacing[s] = h.dims[s] > 0 ? (double(maxs[a]) - double(mins[a])) / double(h.dims[s]) : 0.0;
    h.origin[s] = double(mins[a]) + 0.5 * h.spacing[s];
  }
  LoadedVolume out;
  out.format = "plt";
  out.grid = checkHeader(path, h);
  reportProgress(progress, path, 0.1f, "header");
  out.scalars = readPayload(path, 44, h.type, out.grid.voxelCount(), bigEndian);
  return out;
}

}  // namespace visopt::io
