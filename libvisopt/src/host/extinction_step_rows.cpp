#include "host/extinction_step_rows.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "core/field_access.h"
#include "core/frustum_field.h"
#include "core/min_max.h"
#include "exec/parallel.h"
#include "host/simd_gather.h"

namespace visopt {
namespace {

constexpr int kLanes = 16;

// FrustumMap::toGrid with its "behind the eye" return as a select, so that a loop over lanes
// vectorises: the same operations in the same order for a point in front of the eye.
VISOPT_INLINE glm::vec3 toGridSelect(const FrustumMap& f, glm::vec3 x) {
  const glm::vec3 d = x - f.eye;
  const float z = glm::dot(d, f.forward);
  const float s = glm::length(d);
  const float u = glm::dot(d, f.right) / (z * f.tanX);
  const float v = glm::dot(d, f.up) / (z * f.tanY);
  // Every value computed, then selected: arithmetic on one side of a ?: alone keeps g++ from
  // if-converting the loop (it might raise a floating-point exception the other side avoids).
  const float gx = (u + 1.f) * 0.5f * float(f.dims.x) - 0.5f;
  const float gy = (v + 1.f) * 0.5f * float(f.dims.y) - 0.5f;
  const float gz = (s - f.sNear) / f.ds - 0.5f;
  const bool front = z > 0.f;
  return glm::vec3(front ? gx : -1e30f, front ? gy : -1e30f, front ? gz : -1e30f);
}

// FrustumFieldView::inside and ::sample at kLanes positions (0 outside the grid and in lanes
// n and up), in sample's order of operations; the eight corners of all lanes are gathered
// together (host/simd_gather.h).
template <class Storage>
void sampleLanes(const FrustumFieldView& d, const float* x, const float* y, const float* z, int n,
                 float* out) {
  const glm::ivec3 dims = d.dims;
  const int nz = dims.z, tilesX = d.tilesX;
  const float hx = float(dims.x) - 0.5f, hy = float(dims.y) - 0.5f, hz = float(dims.z) - 0.5f;
  alignas(64) int corner[8][kLanes], in[kLanes];
  alignas(64) float fx[kLanes], fy[kLanes], fz[kLanes], v[8][kLanes];
  auto index = [&](int i, int j, int k) {
    return ((j * tilesX + i / kTileRays) * nz + k) * kTileRays + i % kTileRays;
  };
  for (int l = 0; l < kLanes; ++l) {
    in[l] = (l < n) & (x[l] >= -0.5f) & (y[l] >= -0.5f) & (z[l] >= -0.5f) & (x[l] <= hx) &
            (y[l] <= hy) & (z[l] <= hz);
    // Lanes outside sample the grid's first cell (maxOf(NaN, 0) is 0) and are discarded below.
    const float px = in[l] ? minOf(maxOf(x[l], 0.f), float(dims.x - 1)) : 0.f;
    const float py = in[l] ? minOf(maxOf(y[l], 0.f), float(dims.y - 1)) : 0.f;
    const float pz = in[l] ? minOf(maxOf(z[l], 0.f), float(dims.z - 1)) : 0.f;
    const int i0 = int(px), j0 = int(py), k0 = int(pz);
    const int i1 = i0 + 1 < dims.x ? i0 + 1 : i0, j1 = j0 + 1 < dims.y ? j0 + 1 : j0;
    const int dk = k0 + 1 < dims.z ? kTileRays : 0;
    fx[l] = px - float(i0), fy[l] = py - float(j0), fz[l] = pz - float(k0);
    corner[0][l] = index(i0, j0, k0), corner[1][l] = index(i1, j0, k0);
    corner[2][l] = index(i0, j1, k0), corner[3][l] = index(i1, j1, k0);
    for (int c = 0; c < 4; ++c) corner[c + 4][l] = corner[c][l] + dk;
  }
  for (int c = 0; c < 8; ++c) gatherLanes<Storage>(d.storage.data, corner[c], v[c]);
  for (int l = 0; l < kLanes; ++l) {
    const float a00 = v[0][l] + fx[l] * (v[1][l] - v[0][l]);
    const float a10 = v[2][l] + fx[l] * (v[3][l] - v[2][l]);
    const float a01 = v[4][l] + fx[l] * (v[5][l] - v[4][l]);
    const float a11 = v[6][l] + fx[l] * (v[7][l] - v[6][l]);
    const float a0 = a00 + fy[l] * (a10 - a00), a1 = a01 + fy[l] * (a11 - a01);
    out[l] = in[l] ? a0 + fz[l] * (a1 - a0) : 0.f;
  }
}

// Whether a frustum field's cells can be gathered with 32-bit indices.
bool gathersInLanes(const FrustumFieldView& d) {
  return d.storage.size() < (size_t(1) << 31);
}

// One row's chunk of n <= kLanes voxels starting at voxel index v0 = (j, k) row's i0.
template <class A, bool kAdemamix>
struct RowStep {
  const ExtinctionStep& step;
  A mu, m1, m2, rms;

  void chunk(size_t v0, int i0, int j, int k, int n, double energy[kLanes],
             double step2[kLanes]) const {
    const ExtinctionGradient& grad = step.gradient;
    const OptimizerCoefficients& c = step.coefficients;
    // The voxels' positions in the frusta (vectorised).
    alignas(64) float vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {}, lx[kLanes] = {},
                      ly[kLanes] = {}, lz[kLanes] = {};
    for (int l = 0; l < n; ++l) {
      const glm::vec3 x = grad.volume.toWorld(glm::vec3(float(i0 + l), float(j), float(k)));
      const glm::vec3 yv = toGridSelect(grad.view, x), yl = toGridSelect(grad.light, x);
      vx[l] = yv.x, vy[l] = yv.y, vz[l] = yv.z;
      lx[l] = yl.x, ly[l] = yl.y, lz[l] = yl.z;
    }
    // d_V and d_L (gatherFrustum's rules; a term that is off has d = 0) and mu_bar.
    alignas(64) float dv[kLanes] = {}, dl[kLanes] = {}, mbar[kLanes];
    const bool viewOn = grad.q != 0.f && grad.dView.valid();
    const bool lightOn = grad.r != 0.f && grad.dLight.valid();
    gather(grad.dView, viewOn, vx, vy, vz, n, dv);
    gather(grad.dLight, lightOn, lx, ly, lz, n, dl);
    for (int l = 0; l < n; ++l) mbar[l] = grad.base.at(v0 + size_t(l));
    // The gradient (ExtinctionGradient::at; a term that is off has d = 0 and adds nothing) and
    // the optimiser step (kernels/optimizer_update.h), vectorised. The sums go to local lanes
    // first: the caller's arrays might alias the fields as far as the compiler can tell.
    double e[kLanes] = {}, s2[kLanes] = {};
    for (int l = 0; l < n; ++l) {
      const size_t v = v0 + size_t(l);
      const float m = mu.load(v);
      const float g = step.gradientScale *
                      extinctionGradient(grad.rho, m, mbar[l], grad.q, dv[l], grad.r, dl[l]);
      const float delta = optimizerStep<kAdemamix>(m1, m2, rms, v, g, c);
      const float next = projectExtinction(m + delta, step.muMax);
      mu.store(v, next);
      const float stored = mu.kept(next);
      const double dm = double(m - mbar[l]);
      e[l] = 0.5 * double(grad.rho) * dm * dm * double(step.voxelVolume);
      s2[l] = double(stored - m) * double(stored - m);
    }
    for (int l = 0; l < kLanes; ++l) {
      energy[l] += e[l];
      step2[l] += s2[l];
    }
  }

  // A frustum field at the lanes' positions: 16 lanes at a time when the field's cells have
  // 32-bit indices, one voxel at a time otherwise.
  static void gather(const FrustumFieldView& d, bool on, const float* x, const float* y,
                     const float* z, int n, float* out) {
    if (!on) return;
    if (!gathersInLanes(d)) {
      for (int l = 0; l < n; ++l) {
        const glm::vec3 p(x[l], y[l], z[l]);
        out[l] = d.inside(p) ? d.sample(p) : 0.f;
      }
    } else if (d.half()) {
      sampleLanes<Half>(d, x, y, z, n, out);
    } else {
      sampleLanes<float>(d, x, y, z, n, out);
    }
  }

  StepSums rows(int64_t first, int64_t last) const {
    const glm::ivec3 dims = step.gradient.volume.dims;
    double energy[kLanes] = {}, step2[kLanes] = {};
    for (int64_t r = first; r < last; ++r) {
      const int j = int(r % dims.y), k = int(r / dims.y);
      const size_t base = size_t(r) * size_t(dims.x);
      for (int i0 = 0; i0 < dims.x; i0 += kLanes)
        chunk(base + size_t(i0), i0, j, k, std::min(kLanes, dims.x - i0), energy, step2);
    }
    StepSums sums;
    for (int l = 0; l < kLanes; ++l) {
      sums.energyRho += energy[l];
      sums.step2 += step2[l];
    }
    return sums;
  }
};

template <class A, bool kAdemamix>
StepSums runRows(const ExtinctionStep& step) {
  const OptimizerState& s = step.state;
  const RowStep<A, kAdemamix> k{step, accessTo<A>(step.gradient.mu), accessTo<A>(s.m1),
                                kAdemamix ? accessTo<A>(s.m2) : A{}, accessTo<A>(s.rms)};
  const glm::ivec3 dims = step.gradient.volume.dims;
  const int64_t rows = int64_t(dims.y) * dims.z;
  return tbb::parallel_reduce(
      tbb::blocked_range<int64_t>(0, rows), StepSums{},
      [&](const tbb::blocked_range<int64_t>& r, StepSums acc) {
        return acc + k.rows(r.begin(), r.end());
      },
      [](const StepSums& a, const StepSums& b) { return a + b; });
}

}  // namespace

StepSums extinctionStepOnHost(const char* name, const ExtinctionStep& step) {
  const ExtinctionGradient& g = step.gradient;
  const OptimizerState& s = step.state;
  const bool ademamix = step.coefficients.ademamix;
  const bool half = g.mu.half;
  const bool oneType = s.m1.half == half && s.rms.half == half && (!ademamix || s.m2.half == half);
  const int64_t voxels = int64_t(g.volume.dims.x) * g.volume.dims.y * g.volume.dims.z;
  if (!oneType || (ademamix && !s.m2.valid()))
    return exec::reduce(name, voxels, StepSums{}, step,
                        [](const StepSums& a, const StepSums& b) { return a + b; });
  exec::LaunchTimer timer(name, double(voxels));
  if (half) return ademamix ? runRows<Fp16Access, true>(step) : runRows<Fp16Access, false>(step);
  return ademamix ? runRows<Fp32Access, true>(step) : runRows<Fp32Access, false>(step);
}

}  // namespace visopt
