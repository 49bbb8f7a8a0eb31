// Work that gives way to a newer request: items split into bands of whole granules, `abandon`
// polled before each band (the renderer's image and its light transmittance, which a moving
// camera must not wait for).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>

namespace visopt {

// Calls launch(first, count) for consecutive bands covering [0, items), about `bands` of them,
// each a multiple of `granule` items (the last may be shorter). Returns false, having launched
// the bands before, as soon as abandon() returns true before a band.
template <class Launch>
bool launchInBands(int64_t items, int64_t bands, int64_t granule,
                   const std::function<bool()>& abandon, Launch&& launch) {
  const int64_t granules = (items + granule - 1) / granule;
  const int64_t band = std::max<int64_t>((granules + bands - 1) / bands, 1) * granule;
  for (int64_t first = 0; first < items; first += band) {
    if (abandon()) return false;
    launch(first, std::min(band, items - first));
  }
  return true;
}

}  // namespace visopt
