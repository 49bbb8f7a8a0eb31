#include "sdf/fast_sweep.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

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
    // The upwind values sorted with their axes, as a sort of (value, axis) pairs orders them;
    // compare-and-select steps rather than branches, which the data make unpredictable.
    double a0 = ax, a1 = ay, a2 = az;
    int x0 = 0, x1 = 1, x2 = 2;
    auto order = [](double& va, int& ia, double& vb, int& ib) {
      const bool swap = vb < va || (vb == va && ib < ia);
      const double lo = swap ? vb : va, hi = swap ? va : vb;
      const int il = swap ? ib : ia, ih = swap ? ia : ib;
      va = lo;
      vb = hi;
      ia = il;
      ib = ih;
    };
    order(a0, x0, a1, x1);
    order(a1, x1, a2, x2);
    order(a0, x0, a1, x1);
    // One term, then two, then three, while the solution exceeds the next neighbour: all three
    // computed, then the one that applies selected (a square root of a negative discriminant,
    // which only an unselected solution can have, is taken of 0 instead).
    const double w0 = w[x0], w1 = w[x1], w2 = w[x2];
    const double u1 = a0 + hs[x0];
    const double sw1 = w0, swa1 = w0 * a0, swa21 = w0 * a0 * a0;
    const double sw2 = sw1 + w1, swa2 = swa1 + w1 * a1, swa22 = swa21 + w1 * a1 * a1;
    const double disc2 = swa2 * swa2 - sw2 * (swa22 - 1.0);
    const double u2 = (swa2 + std::sqrt(std::max(disc2, 0.0))) / sw2;
    const double sw3 = sw2 + w2, swa3 = swa2 + w2 * a2, swa23 = swa22 + w2 * a2 * a2;
    const double disc3 = swa3 * swa3 - sw3 * (swa23 - 1.0);
    const double u3 = (swa3 + std::sqrt(std::max(disc3, 0.0))) / sw3;
    const bool two = u1 > a1 && !(disc2 < 0.0), three = two && u2 > a2 && !(disc3 < 0.0);
    const double u = three ? u3 : (two ? u2 : u1);
    return std::min(c, float(u));
  }

  // One voxel of a sweep, looked at only when flagged in `todo` (clearing its flag and setting
  // its face neighbours' when it decreases), or always without `todo`; returns its decrease. A
  // voxel none of whose neighbours changed since it was last updated would keep its value
  // (update() is a function of the neighbours and the value, which is already no larger than
  // that function's result), so skipping it changes nothing. Rows on one anti-diagonal share no
  // face, but two of them may flag the same voxel of a row on the next or the previous one
  // (both with 1): the flags of other rows are set atomically.
  float voxel(int64_t i, int64_t j, int64_t k, uint8_t* todo) const {
    constexpr float inf = std::numeric_limits<float>::infinity();
    const int64_t v = i + nx * (j + ny * k);
    if (todo) {
      if (!todo[v]) return 0.f;
      todo[v] = 0;
    }
    if (fixed[v]) return 0.f;
    const float u = update(i, j, k);
    if (!(u < d[v])) return 0.f;
    const float change = std::isinf(d[v]) ? inf : d[v] - u;
    d[v] = u;
    if (todo) {
      auto flag = [&](int64_t at) {
        std::atomic_ref<uint8_t>(todo[at]).store(1, std::memory_order_relaxed);
      };
      if (i > 0) todo[v - 1] = 1;
      if (i + 1 < nx) todo[v + 1] = 1;
      if (j > 0) flag(v - nx);
      if (j + 1 < ny) flag(v + nx);
      if (k > 0) flag(v - nx * ny);
      if (k + 1 < nz) flag(v + nx * ny);
    }
    return change;
  }

  // Rows (j[r], k[r]), r < count <= kRowGroup, of one anti-diagonal, in direction fx; returns
  // the largest decrease. Along a row each voxel waits for the one before it (its new value is
  // the next one's neighbour), a chain of loads, a square root and a division; the rows'
  // voxels are taken in turn, so that the processor overlaps their independent chains. Each
  // row still sees its voxels in the serial order.
  static constexpr int kRowGroup = 4;
  float rows(const int64_t* j, const int64_t* k, int count, bool fx, uint8_t* todo) const {
    float change = 0.f;
    if (count == kRowGroup) {
      for (int64_t ii = 0; ii < nx; ++ii) {
        const int64_t i = fx ? nx - 1 - ii : ii;
        for (int r = 0; r < kRowGroup; ++r) change = std::max(change, voxel(i, j[r], k[r], todo));
      }
      return change;
    }
    for (int r = 0; r < count; ++r)
      for (int64_t ii = 0; ii < nx; ++ii)
        change = std::max(change, voxel(fx ? nx - 1 - ii : ii, j[r], k[r], todo));
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
        for (int64_t jj = 0; jj < s.ny; ++jj) {
          const int64_t j = fy ? s.ny - 1 - jj : jj;
          change = std::max(change, s.rows(&j, &k, 1, fx, nullptr));
        }
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
          for (int64_t kk = r.begin(); kk < r.end(); kk += Sweeper::kRowGroup) {
            int64_t j[Sweeper::kRowGroup], k[Sweeper::kRowGroup];
            const int count = int(std::min<int64_t>(Sweeper::kRowGroup, r.end() - kk));
            for (int g = 0; g < count; ++g) {
              j[g] = fy ? s.ny - 1 - (diag - kk - g) : diag - kk - g;
              k[g] = fz ? s.nz - 1 - (kk + g) : kk + g;
            }
            most = std::max(most, s.rows(j, k, count, fx, todo));
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
