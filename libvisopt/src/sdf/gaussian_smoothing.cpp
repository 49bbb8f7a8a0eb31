#include "sdf/gaussian_smoothing.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/field_view.h"
#include "exec/parallel.h"

namespace visopt {

// Each output voxel sums w[o] x (its neighbour at offset o) for o = -r..r in that order, so the
// result does not depend on how the loops are arranged: along x a row is padded with its edge
// values and summed offset by offset over the whole row (the inner loop runs along x and
// vectorises); along y and z whole x rows are summed the same way.
Field3D gaussianSmoothed(const Field3D& in, float sigma, MemoryLedger* ledger) {
  const exec::LaunchTimer timer("sdf: smoothing", double(in.size()));
  const GridSpec& g = in.grid();
  const int64_t nx = g.dims.x, ny = g.dims.y, nz = g.dims.z;
  const int r = std::max(1, int(std::ceil(3.f * sigma)));
  std::vector<float> w(static_cast<size_t>(2 * r + 1));
  float total = 0.f;
  for (int o = -r; o <= r; ++o)
    total += w[size_t(o + r)] = std::exp(-0.5f * float(o * o) / (sigma * sigma));
  for (float& x : w) x /= total;

  Field3D out("sdf-smoothed-scalar", g, Precision::FP32, ledger);
  std::vector<float> a(in.size()), b(in.size());
  const FieldView src(in), dst(out);
  const int64_t rows = ny * nz;
  tbb::parallel_for(int64_t(0), rows, [&](int64_t row) {
    for (int64_t x = 0; x < nx; ++x) a[size_t(row * nx + x)] = src.load(size_t(row * nx + x));
  });

  // Along x: a padded copy of the row, then the taps.
  if (nx > 1) {
    tbb::parallel_for(
        tbb::blocked_range<int64_t>(0, rows), [&](const tbb::blocked_range<int64_t>& range) {
          std::vector<float> padded(size_t(nx + 2 * r));  // one per task, reused row after row
          for (int64_t row = range.begin(); row != range.end(); ++row) {
            const float* line = &a[size_t(row * nx)];
            for (int64_t q = 0; q < nx + 2 * r; ++q)
              padded[size_t(q)] = line[std::clamp<int64_t>(q - r, 0, nx - 1)];
            float* acc = &b[size_t(row * nx)];
            std::fill(acc, acc + nx, 0.f);
            for (int o = 0; o <= 2 * r; ++o) {
              const float wo = w[size_t(o)];
              const float* p = padded.data() + o;
              for (int64_t q = 0; q < nx; ++q) acc[q] += wo * p[q];
            }
          }
        });
    std::swap(a, b);
  }
  // Along y and z: whole rows, the neighbour row at each offset clamped to the grid.
  auto alongRows = [&](int64_t len, bool alongZ) {
    if (len < 2) return;
    tbb::parallel_for(int64_t(0), rows, [&](int64_t row) {
      const int64_t j = row % ny, k = row / ny;
      float* acc = &b[size_t(row * nx)];
      std::fill(acc, acc + nx, 0.f);
      for (int o = -r; o <= r; ++o) {
        const float wo = w[size_t(o + r)];
        const int64_t jj = alongZ ? j : std::clamp<int64_t>(j + o, 0, ny - 1);
        const int64_t kk = alongZ ? std::clamp<int64_t>(k + o, 0, nz - 1) : k;
        const float* p = &a[size_t((jj + ny * kk) * nx)];
        for (int64_t q = 0; q < nx; ++q) acc[q] += wo * p[q];
      }
    });
    std::swap(a, b);
  };
  alongRows(ny, false);
  alongRows(nz, true);

  tbb::parallel_for(int64_t(0), rows, [&](int64_t row) {
    for (int64_t x = 0; x < nx; ++x) dst.store(size_t(row * nx + x), a[size_t(row * nx + x)]);
  });
  return out;
}

}  // namespace visopt
