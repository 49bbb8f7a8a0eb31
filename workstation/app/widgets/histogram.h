// Histogram of a volume's data values, drawn behind the transfer-function and importance curves.
// Computed once per volume by the caller and shared read-only (std::shared_ptr<const Histogram>).
#pragma once

#include <vector>

namespace visopt {
struct Volume;
}

namespace visopt::ws {

struct Histogram {
  double valueMin = 0.0;  // data units: the volume's value range
  double valueMax = 1.0;
  // counts[i] is the number of voxels with a value in bin i, the bins splitting [valueMin,
  // valueMax] evenly; bin i covers [valueMin + i w, valueMin + (i + 1) w) and the last bin also
  // holds valueMax. NaN voxels are not counted.
  std::vector<double> counts;

  int bins() const { return static_cast<int>(counts.size()); }
  double binWidth() const {
    return counts.empty() ? 0.0 : (valueMax - valueMin) / static_cast<double>(counts.size());
  }
  double maxCount() const;
  double total() const;
};

// Counts every voxel of `volume` into `bins` (at least 1) bins over [valueMin, valueMax]. A volume
// with valueMax == valueMin puts everything in bin 0. Runs in parallel (oneTBB).
Histogram computeHistogram(const visopt::Volume& volume, int bins = 256);

}  // namespace visopt::ws
