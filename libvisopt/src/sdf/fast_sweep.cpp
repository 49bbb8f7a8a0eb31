#include "sdf/fast_sweep.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "exec/parallel.h"

namespace visopt {

namespace {

struct Sweeper {
  float* d;
  const uint8_t* fixed;
  int64_t nx, ny, nz;
  double w[3];   // 1 / spacing^2 per axis
  double hs[3];  // spacing per axis

  // The first-order Godunov solution at voxel (i, j, k) from its face neighbours, or its own
  // value when that is no larger. The three axes' upwind values are ordered by (value, axis),
  // as a sort of the pairs would order them, so that ties resolve the same way everywhere.
  float update(int64_t i, int64_t j, int64_t k) const {
    constexpr float inf = std::numeric_limits<float>::infinity();
    const int64_t v = i + nx * (j + ny * k);
    const float c = d[v];
    const float ax = std::min(i > 0 ? d[v - 1] : inf, i + 1 < nx ? d[v + 1] : inf);
    const float ay = std::min(j > 0 ? d[v - nx] : inf, j + 1 < ny ? d[v + nx] : inf);
    const float az = std::min(k > 0 ? d[v - nx * ny] : inf, k + 1 < nz ? d[v + nx * ny] : inf);
    if (!(std::min(ax, std::min(ay, az)) < c)) return c;  // no smaller neighbour
    std::pair<double, int> a[3] = {{ax, 0}, {ay, 1}, {az, 2}};
    if (a[1] < a[0]) std::swap(a[0], a[1]);
    if (a[2] < a[1]) std::swap(a[1], a[2]);
    if (a[1] < a[0]) std::swap(a[0], a[1]);
    // One term, then two, then three, while the solution exceeds the next neighbour.
    double u = a[0].first + hs[a[0].second];
    double sw = 0.0, swa = 0.0, swa2 = 0.0;
    for (int m = 0; m < 3; ++m) {
      if (m > 0 && !(u > a[m].first)) break;
      const double wm = w[a[m].second];
      sw += wm;
      swa += wm * a[m].first;
      swa2 += wm * a[m].first * a[m].first;
      if (m == 0) continue;
      const double disc = swa * swa - sw * (swa2 - 1.0);
      if (disc < 0.0) break;  // cannot happen for sorted finite a; keep the previous u
      u = (swa + std::sqrt(disc)) / sw;
    }
    return std::min(c, float(u));
  }

  // One x row of a sweep in direction fx, voxels flagged in `todo` only (clearing their flags and
  // setting their face neighbours' when a voxel decreases), or every voxel without `todo`;
  // returns the largest decrease. A voxel none of whose neighbours changed since it was last
  // updated would keep its value (update() is a function of the neighbours and the value, which
  // is already no larger than that function's result), so skipping it changes nothing. Rows on
  // one anti-diagonal share no face, but two of them may flag the same voxel of a row on the
  // next or the previous one (both with 1): the flags of other rows are set atomically.
  float row(int64_t j, int64_t k, bool fx, uint8_t* todo = nullptr) const {
    constexpr float inf = std::numeric_limits<float>::infinity();
    float change = 0.f;
    const int64_t plane = nx * ny;
    auto flag = [&](int64_t v) {
      std::atomic_ref<uint8_t>(todo[v]).store(1, std::memory_order_relaxed);
    };
    for (int64_t ii = 0; ii < nx; ++ii) {
      const int64_t i = fx ? nx - 1 - ii : ii;
      const int64_t v = i + nx * (j + ny * k);
      if (todo) {
        if (!todo[v]) continue;
        todo[v] = 0;
      }
      if (fixed[v]) continue;
      const float u = update(i, j, k);
      if (u < d[v]) {
        change = std::max(change, std::isinf(d[v]) ? inf : d[v] - u);
        d[v] = u;
        if (todo) {
          if (i > 0) todo[v - 1] = 1;
          if (i + 1 < nx) todo[v + 1] = 1;
          if (j > 0) flag(v - nx);
          if (j + 1 < ny) flag(v + nx);
          if (k > 0) flag(v - plane);
          if (k + 1 < nz) flag(v + plane);
        }
      }
    }
    return change;
  }
};

Sweeper sweeperFor(std::vector<float>& d, const std::vector<uint8_t>& fixed, glm::ivec3 dims,
                   glm::vec3 spacing) {
  Sweeper s{d.data(), fixed.data(), dims.x, dims.y, dims.z, {}, {}};
  for (int a = 0; a < 3; ++a) {
    s.w[a] = 1.0 / (double(spacing[a]) * spacing[a]);
    s.hs[a] = spacing[a];
  }
  return s;
}

}  // namespace

void fastSweepSerial(std::vector<float>& d, const std::vector<uint8_t>& fixed, glm::ivec3 dims,
                     glm::vec3 spacing, float tolerance, int maxRounds) {
  const Sweeper s = sweeperFor(d, fixed, dims, spacing);
  for (int round = 0; round < maxRounds; ++round) {
    float change = 0.f;
    for (int dir = 0; dir < 8; ++dir) {
      const bool fx = dir & 1, fy = dir & 2, fz = dir & 4;
      for (int64_t kk = 0; kk < s.nz; ++kk) {
        const int64_t k = fz ? s.nz - 1 - kk : kk;
        for (int64_t jj = 0; jj < s.ny; ++jj)
          change = std::max(change, s.row(fy ? s.ny - 1 - jj : jj, k, fx));
      }
    }
    if (change <= tolerance) break;
  }
}

void fastSweep(std::vector<float>& d, const std::vector<uint8_t>& fixed, glm::ivec3 dims,
               glm::vec3 spacing, float tolerance, int maxRounds) {
  const exec::LaunchTimer timer("sdf: fast sweep", double(d.size()));
  const Sweeper s = sweeperFor(d, fixed, dims, spacing);
  const int64_t diagonals = s.ny + s.nz - 1;
  // Every voxel is looked at in the first sweep, then only those next to a change.
  std::vector<uint8_t> flags(d.size(), 1);
  uint8_t* todo = flags.data();
  for (int round = 0; round < maxRounds; ++round) {
    float change = 0.f;
    for (int dir = 0; dir < 8; ++dir) {
      const bool fx = dir & 1, fy = dir & 2, fz = dir & 4;
      for (int64_t diag = 0; diag < diagonals; ++diag) {
        // The rows (jj, kk) with jj + kk = diag, in the sweep's own order of j and k.
        const int64_t kkFirst = std::max<int64_t>(0, diag - (s.ny - 1));
        const int64_t kkEnd = std::min<int64_t>(s.nz, diag + 1);
        auto rows = [&](const tbb::blocked_range<int64_t>& r, float most) {
          for (int64_t kk = r.begin(); kk != r.end(); ++kk) {
            const int64_t jj = diag - kk;
            most =
                std::max(most, s.row(fy ? s.ny - 1 - jj : jj, fz ? s.nz - 1 - kk : kk, fx, todo));
          }
          return most;
        };
        // A few rows per task: a row is one x line of the grid (a few hundred voxels).
        const int64_t grain = std::max<int64_t>(1, 4096 / std::max<int64_t>(s.nx, 1));
        const float most =
            kkEnd - kkFirst <= grain
                ? rows(tbb::blocked_range<int64_t>(kkFirst, kkEnd), 0.f)
                : tbb::parallel_reduce(tbb::blocked_range<int64_t>(kkFirst, kkEnd, grain), 0.f,
                                       rows, [](float a, float b) { return std::max(a, b); });
        change = std::max(change, most);
      }
    }
    if (change <= tolerance) break;
  }
}

}  // namespace visopt
