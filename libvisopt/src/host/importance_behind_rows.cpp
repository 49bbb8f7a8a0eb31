#include "host/importance_behind_rows.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "exec/parallel.h"
#include "host/frustum_sample_lanes.h"

namespace visopt {
namespace {

constexpr int kLanes = kFrustumLanes;

void chunk(const ImportanceBehind& k, int i0, int j, int kz, int n) {
  alignas(64) float wx[kLanes] = {}, wy[kLanes] = {}, wz[kLanes] = {};
  alignas(64) float vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {};
  alignas(64) float lx[kLanes] = {}, ly[kLanes] = {}, lz[kLanes] = {};
  const bool light = k.lightMax.valid();
  for (int l = 0; l < n; ++l) {
    const glm::vec3 x = k.volume.toWorld(glm::vec3(float(i0 + l), float(j), float(kz)));
    wx[l] = x.x, wy[l] = x.y, wz[l] = x.z;
    const glm::vec3 yv = toGridSelect(k.view, x);
    vx[l] = yv.x, vy[l] = yv.y, vz[l] = yv.z;
    if (light) {
      const glm::vec3 yl = toGridSelect(k.light, x);
      lx[l] = yl.x, ly[l] = yl.y, lz[l] = yl.z;
    }
  }
  alignas(64) float vm[kLanes], lm[kLanes];
  sampleFrustumField(k.viewMax, vx, vy, vz, n, vm);
  sampleFrustumField(k.lightMax, lx, ly, lz, n, lm);
  const glm::ivec3 dims = k.volume.dims;
  const size_t row = (size_t(kz) * size_t(dims.y) + size_t(j)) * size_t(dims.x) + size_t(i0);
  for (int l = 0; l < n; ++l)
    k.ghat.store(row + size_t(l), k.ghatOf(vm[l], lm[l], glm::vec3(wx[l], wy[l], wz[l])));
}

}  // namespace

void importanceBehindOnHost(const char* name, const ImportanceBehind& k) {
  const glm::ivec3 dims = k.volume.dims;
  const int64_t rows = int64_t(dims.y) * dims.z;
  exec::LaunchTimer timer(name, double(rows) * double(dims.x));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows),
                    [&](const tbb::blocked_range<int64_t>& r) {
                      for (int64_t row = r.begin(); row != r.end(); ++row) {
                        const int j = int(row % dims.y), kz = int(row / dims.y);
                        for (int i0 = 0; i0 < dims.x; i0 += kLanes)
                          chunk(k, i0, j, kz, std::min(kLanes, dims.x - i0));
                      }
                    });
}

}  // namespace visopt
