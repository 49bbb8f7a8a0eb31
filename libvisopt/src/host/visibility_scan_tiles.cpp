#include "host/visibility_scan_tiles.h"

#include <algorithm>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_reduce.h>

#include "exec/parallel.h"
#include "host/visibility_scan_packet.h"
#include "kernels/visibility_scan_fast.h"
#include "visopt/error.h"

namespace visopt {
namespace {

// mu, g and T of a tile's cells, [k][lane].
struct TileBuffer {
  std::vector<float> m, g, t;
  void ensure(size_t n) {
    if (m.size() < n) {
      m.resize(n);
      g.resize(n);
      t.resize(n);
    }
  }
};

// The front-to-back pass ray by ray (kernels/visibility_scan_fast.h) into the tile's rows: for
// fields of mixed precision, which the packet pass does not take.
void frontToBackLanes(const VisibilityScan& scan, const RayPacket& rays, ScanSums& sums, float* bm,
                      float* bg, float* bt) {
  const FrustumFieldView& out = scan.out;
  const int nz = scan.frustum.dims.z;
  for (int lane = 0; lane < kTileRays; ++lane) {
    if (lane >= rays.lanes) {  // past the frustum's edge: zeros, stored into the tile's padding
      for (int k = 0; k < nz; ++k)
        bm[k * kTileRays + lane] = bg[k * kTileRays + lane] = bt[k * kTileRays + lane] = 0.f;
      continue;
    }
    const ScanRay ray{
        rays.o, {rays.dx[lane], rays.dy[lane], rays.dz[lane]}, rays.w[lane], rays.omega[lane]};
    frontToBack(scan, ray, sums, [&](int k, float m, float g, float t) {
      const size_t c = size_t(k) * kTileRays + size_t(lane);
      bm[c] = m;
      bg[c] = g;
      // What the reference reads back from the frustum field (fp16 rounds it).
      bt[c] = out.half() ? halfToFloat(floatToHalf(t)) : t;
    });
  }
}

ScanSums scanTile(const VisibilityScan& scan, int64_t tile, TileBuffer& buf) {
  const FrustumMap& f = scan.frustum;
  const FrustumFieldView& out = scan.out;
  const int nz = f.dims.z;
  const int j = int(tile / out.tilesX), i0 = int(tile % out.tilesX) * kTileRays;
  const int lanes = std::min(kTileRays, f.dims.x - i0);
  buf.ensure(size_t(nz) * kTileRays);
  float* bm = buf.m.data();
  float* bg = buf.g.data();
  float* bt = buf.t.data();

  ScanSums sums;
  RayPacket rays;
  rays.lanes = lanes;
  rays.o = scanRayOf(scan, i0, j).o;  // the eye or the light, the same for every ray
  for (int lane = 0; lane < lanes; ++lane) {
    const ScanRay ray = scanRayOf(scan, i0 + lane, j);
    rays.dx[lane] = ray.d.x;
    rays.dy[lane] = ray.d.y;
    rays.dz[lane] = ray.d.z;
    rays.w[lane] = ray.w;
    rays.omega[lane] = ray.omega;
    rays.active[lane] = 1;
  }
  if (packetScanApplies<float>(scan))
    frontToBackPacket<float>(scan, rays, sums, bm, bg, bt);
  else if (packetScanApplies<Half>(scan))
    frontToBackPacket<Half>(scan, rays, sums, bm, bg, bt);
  else
    frontToBackLanes(scan, rays, sums, bm, bg, bt);
  const float* w = rays.w;
  const float* omega = rays.omega;

  // Back to front, the tile's rays in lanes: G (behind, weighted by s^2) and d = g T - G.
  const float ds = f.ds;
  const bool keepMax = scan.behindMax.valid();
  float behind[kTileRays] = {}, runningMax[kTileRays] = {};
  double gMuT[kTileRays] = {}, gMu[kTileRays] = {};
  for (int k = nz - 1; k >= 0; --k) {
    const float s = f.depthOf(float(k));
    const float s2 = s * s;
    const float* m = bm + size_t(k) * kTileRays;
    const float* gRaw = bg + size_t(k) * kTileRays;
    const float* t = bt + size_t(k) * kTileRays;
    float d[kTileRays], maxBehind[kTileRays];
    for (int l = 0; l < kTileRays; ++l) {
      const float g = minOf(gRaw[l] * w[l], 1.f);
      maxBehind[l] = runningMax[l];
      runningMax[l] = maxOf(runningMax[l], g);
      d[l] = g * t[l] - behind[l] / s2;
      const float gmt = g * m[l] * t[l];
      behind[l] += gmt * s2 * ds;
      const double dV = double(omega[l]) * double(s2) * double(ds);
      gMuT[l] += double(gmt) * dV;
      gMu[l] += double(g * m[l]) * dV;
    }
    const size_t row = out.index(i0, j, k);
    out.storeRow(row, d);
    if (keepMax) scan.behindMax.storeRow(row, maxBehind);
  }
  for (int l = 0; l < kTileRays; ++l) {
    sums.gMuT += gMuT[l];
    sums.gMu += gMu[l];
  }
  return sums;
}

}  // namespace

ScanSums scanTilesOnHost(const char* name, const VisibilityScan& scan) {
  if (scan.frustum.dims.z > kScanBufferCells)
    throw Error(ErrorKind::Failure, "visibility scan: too many depth cells for the tiled scan");
  const int64_t tiles = int64_t(scan.out.tilesX) * scan.frustum.dims.y;
  exec::LaunchTimer timer(name, double(scan.frustum.dims.x) * double(scan.frustum.dims.y));
  tbb::enumerable_thread_specific<TileBuffer> buffers;
  return tbb::parallel_reduce(
      tbb::blocked_range<int64_t>(0, tiles), ScanSums{},
      [&](const tbb::blocked_range<int64_t>& r, ScanSums acc) {
        TileBuffer& buf = buffers.local();
        for (int64_t tile = r.begin(); tile != r.end(); ++tile)
          acc = acc + scanTile(scan, tile, buf);
        return acc;
      },
      [](const ScanSums& a, const ScanSums& b) { return a + b; });
}

}  // namespace visopt
