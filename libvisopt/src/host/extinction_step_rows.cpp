#include "host/extinction_step_rows.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "core/field_access.h"
#include "exec/parallel.h"
#include "host/frustum_sample_lanes.h"

namespace visopt {
namespace {

constexpr int kLanes = kFrustumLanes;

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
    if (viewOn) sampleFrustumField(grad.dView, vx, vy, vz, n, dv);
    if (lightOn) sampleFrustumField(grad.dLight, lx, ly, lz, n, dl);
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
