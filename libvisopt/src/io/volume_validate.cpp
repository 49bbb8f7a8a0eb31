// checkHeader(): everything that can be refused from a header alone, before any allocation.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "io/volume_source.h"
#include "visopt/error.h"
#include "visopt/volume_io.h"

namespace visopt::io {

namespace {

// Bounds of the geometry checkHeader accepts (world units, usually mm): far beyond any scanner
// (a micro-CT voxel is ~1e-3 mm, a planet ~1e10 mm) and well inside fp32.
constexpr double kMinSpacing = 1e-9;
constexpr double kMaxWorldExtent = 1e15;
constexpr double kMaxSpacingRatio = 1e4;  // clinical stacks reach ~30 (0.3 mm pixels, 10 mm slices)

std::string dimsText(const std::array<int64_t, 3>& d) {
  return std::to_string(d[0]) + " x " + std::to_string(d[1]) + " x " + std::to_string(d[2]);
}

std::string humanBytes(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 6) {
    bytes /= 1024.0;
    ++u;
  }
  std::ostringstream s;
  s.precision(3);
  s << bytes << " " << units[u];
  return s.str();
}

}  // namespace

GridSpec checkHeader(const std::string& path, const VolumeHeader& h, bool wholeInMemory) {
  for (int a = 0; a < 3; ++a)
    if (h.dims[a] <= 0)
      throwBadInput(path, "invalid dimensions " + dimsText(h.dims) + " (each must be >= 1)");
  for (int a = 0; a < 3; ++a)
    if (h.dims[a] > std::numeric_limits<int>::max())
      throwBadInput(path, "dimensions " + dimsText(h.dims) +
                              " too large (overflow: an axis exceeds " +
                              std::to_string(std::numeric_limits<int>::max()) + ")");
  size_t voxels = 1, fp32Bytes = 0;
  for (int a = 0; a < 3; ++a)
    if (__builtin_mul_overflow(voxels, static_cast<size_t>(h.dims[a]), &voxels))
      throwBadInput(path, "dimensions " + dimsText(h.dims) +
                              " overflow: the voxel count does not fit in 64 bits");
  if (__builtin_mul_overflow(voxels, sizeof(float), &fp32Bytes))
    throwBadInput(path, "dimensions " + dimsText(h.dims) + " overflow: " + std::to_string(voxels) +
                            " voxels cannot be addressed as fp32");
  // Voxel centres span the volume's box: a single voxel spans none, and no camera can frame it.
  if (h.dims[0] == 1 && h.dims[1] == 1 && h.dims[2] == 1)
    throwBadInput(path,
                  "a single voxel (1 x 1 x 1): nothing to render; a volume needs two voxels "
                  "along at least one axis");
  if (h.components != 1)
    throwBadInput(path, "multi-component data (" + std::to_string(h.components) +
                            " components per voxel) is not supported; need one scalar per voxel");
  const size_t available = availableMemoryBytes();
  if (wholeInMemory && fp32Bytes > available)
    throwBadInput(path, "dimensions " + dimsText(h.dims) + " need " +
                            humanBytes(double(fp32Bytes)) +
                            " as fp32, more than the available memory (" +
                            humanBytes(double(available)) + ")");
  for (int a = 0; a < 3; ++a)
    if (!(std::isfinite(h.spacing[a]) && h.spacing[a] > 0.0)) {
      std::ostringstream s;
      s << "invalid spacing " << h.spacing[0] << " x " << h.spacing[1] << " x " << h.spacing[2]
        << " (each must be finite and > 0)";
      throwBadInput(path, s.str());
    }
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(h.origin[a])) throwBadInput(path, "invalid origin (not finite)");
  // Geometry the renderer and the optimiser can work with in fp32: world positions, their
  // squares and their differences stay finite and distinct (a spacing of 1e30 or an origin of
  // -3e38 made the camera infinite, 1e-30 made every distance 0), and the ray-march step, a
  // fraction of the smallest spacing, crosses the largest axis in a bounded number of steps.
  double smallest = h.spacing[0], largest = h.spacing[0];
  for (int a = 0; a < 3; ++a) {
    smallest = std::min(smallest, h.spacing[a]);
    largest = std::max(largest, h.spacing[a]);
    const double extent = h.spacing[a] * double(h.dims[a]);
    if (!(h.spacing[a] >= kMinSpacing && std::abs(h.origin[a]) + extent <= kMaxWorldExtent)) {
      std::ostringstream s;
      s << "spacing " << h.spacing[0] << " x " << h.spacing[1] << " x " << h.spacing[2]
        << " with origin " << h.origin[0] << ", " << h.origin[1] << ", " << h.origin[2]
        << " is out of range (spacing >= " << kMinSpacing << ", origin and extent within "
        << kMaxWorldExtent << " world units)";
      throwBadInput(path, s.str());
    }
  }
  if (largest / smallest > kMaxSpacingRatio) {
    std::ostringstream s;
    s << "spacing " << h.spacing[0] << " x " << h.spacing[1] << " x " << h.spacing[2]
      << " is too anisotropic (the largest more than " << kMaxSpacingRatio
      << " times the smallest)";
    throwBadInput(path, s.str());
  }
  // Orientation: columns must be finite unit vectors, mutually orthogonal.
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(h.direction[c][r]))
        throwBadInput(path, "invalid orientation matrix (not finite)");
  for (int c = 0; c < 3; ++c)
    for (int d = c; d < 3; ++d) {
      double dot = 0.0;
      for (int r = 0; r < 3; ++r) dot += h.direction[c][r] * h.direction[d][r];
      if (std::abs(dot - (c == d ? 1.0 : 0.0)) > 1e-3)
        throwBadInput(path,
                      "orientation matrix is not orthonormal (sheared or scaled axes are "
                      "not supported)");
    }

  GridSpec grid;
  grid.dims = glm::ivec3(int(h.dims[0]), int(h.dims[1]), int(h.dims[2]));
  grid.spacing = glm::vec3(float(h.spacing[0]), float(h.spacing[1]), float(h.spacing[2]));
  grid.origin = glm::vec3(float(h.origin[0]), float(h.origin[1]), float(h.origin[2]));
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) grid.direction[c][r] = float(h.direction[c][r]);
  if (!(grid.spacing.x > 0.f && grid.spacing.y > 0.f && grid.spacing.z > 0.f))
    throwBadInput(path, "invalid spacing (too small for fp32)");
  return grid;
}

void reportProgress(const ProgressCallback& progress, const std::string& path, float fraction,
                    const std::string& stage) {
  if (progress && !progress(fraction, stage))
    throw Error(ErrorKind::Cancelled, path + ": cancelled");
}

}  // namespace visopt::io
