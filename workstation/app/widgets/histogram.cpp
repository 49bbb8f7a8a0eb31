#include "widgets/histogram.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "visopt/volume.h"

namespace visopt::ws {

double Histogram::maxCount() const {
  double m = 0.0;
  for (double c : counts) m = std::max(m, c);
  return m;
}

double Histogram::total() const {
  double s = 0.0;
  for (double c : counts) s += c;
  return s;
}

Histogram computeHistogram(const visopt::Volume& volume, int bins) {
  bins = std::max(bins, 1);
  Histogram h;
  h.valueMin = volume.valueMin;
  h.valueMax = volume.valueMax;
  h.counts.assign(static_cast<size_t>(bins), 0.0);
  const Field3D& field = volume.normalized;
  if (field.empty()) return h;
  const size_t n = field.size();
  const bool degenerate = !(volume.valueMax > volume.valueMin);
  // Values are stored normalised: t in [0, 1] maps to bin floor(t * bins). Binning in data units
  // (volume.toValue) would give the same bins up to rounding; the normalised value is exact.
  const auto binOf = [bins, degenerate](float t) {
    if (degenerate) return 0;
    const double x = std::floor(static_cast<double>(t) * static_cast<double>(bins));
    return static_cast<int>(std::clamp(x, 0.0, static_cast<double>(bins - 1)));
  };
  tbb::combinable<std::vector<double>> partial(
      [bins] { return std::vector<double>(static_cast<size_t>(bins), 0.0); });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, size_t{1} << 15),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::vector<double>& local = partial.local();
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        const float t = field.get(i);
                        if (std::isnan(t)) continue;
                        local[static_cast<size_t>(binOf(t))] += 1.0;
                      }
                    });
  partial.combine_each([&h](const std::vector<double>& local) {
    for (size_t i = 0; i < local.size(); ++i) h.counts[i] += local[i];
  });
  return h;
}

}  // namespace visopt::ws
