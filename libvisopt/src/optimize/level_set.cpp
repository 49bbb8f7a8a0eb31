#include "optimize/level_set.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "core/device_bit_mask.h"
#include "core/device_buffer.h"
#include "core/field_view.h"
#include "core/voxel_ijk.h"
#include "exec/parallel.h"
#include "kernels/implicit_diffusion.h"
#include "kernels/level_set_step.h"
#include "kernels/redistance.h"
#include "optimize/narrow_band.h"
#include "sdf/fast_sweep.h"
#include "sdf/gaussian_smoothing.h"
#include "visopt/error.h"

namespace visopt {

namespace {

// ---- launching a stencil kernel: one voxel per CUDA thread, one x row per CPU item ----------

template <class K>
struct VoxelOf {
  K k;
  VISOPT_HD auto operator()(int64_t v) const { return k.voxel(v); }
};
template <class K>
struct RowOf {
  K k;
  VISOPT_HD auto operator()(int64_t r) const { return k.row(r); }
};
struct Plus {
  template <class T>
  VISOPT_HD T operator()(const T& a, const T& b) const {
    return a + b;
  }
};

template <class T, class K>
T launchStencil(const char* name, const K& k, const glm::ivec3& dims) {
  const int64_t rows = int64_t(dims.y) * dims.z;
  if (activeBackend() == Backend::CUDA)
    return exec::reduce(name, rows * dims.x, T{}, VoxelOf<K>{k}, Plus{});
  return exec::reduce(name, rows, T{}, RowOf<K>{k}, Plus{});
}

// ---- the narrow band (optimize/narrow_band.h): x-spans of active bricks --------------------
//
// Runs of active bricks along x are one span per voxel row, so the kernels' row sweeps
// (vectorised along x) run over them unchanged. Host data: the band path runs on the CPU
// backend.

using Band = SpanList;

// to = from over the spans.
void copySpans(const Field3D& from, Field3D& to, const Band& spans) {
  const FieldView a(from), b(to);
  const int64_t nx = from.grid().dims.x;
  const RowSpan* list = spans.spans.data();
  tbb::parallel_for(int64_t(0), int64_t(spans.spans.size()), [=](int64_t i) {
    const size_t start = size_t(list[i].row * nx);
    for (int x = list[i].x0; x < list[i].x1; ++x)
      b.store(start + size_t(x), a.load(start + size_t(x)));
  });
}

template <class K>
struct SpanOf {
  K k;
  const RowSpan* spans;
  VISOPT_HD auto operator()(int64_t i) const {
    return k.span(spans[i].row, spans[i].x0, spans[i].x1);
  }
};

template <class T, class K>
T launchBand(const char* name, const K& k, const Band& band) {
  return exec::reduce(name, int64_t(band.spans.size()), T{}, SpanOf<K>{k, band.spans.data()},
                      Plus{});
}

// The band path: CPU backend and a positive half-width.
bool useBand(const LevelSetSettings& s) {
  return s.band > 0.f && activeBackend() == Backend::CPU;
}

// True when phi changes sign between neighbours at a voxel of the spans.
bool interfaceWithin(const Field3D& phi, const Band& spans) {
  const InterfaceCount count{FieldView(phi)};
  const int64_t nx = phi.grid().dims.x;
  const RowSpan* list = spans.spans.data();
  return tbb::parallel_reduce(
             tbb::blocked_range<int64_t>(0, int64_t(spans.spans.size())), int64_t(0),
             [=](const tbb::blocked_range<int64_t>& r, int64_t found) {
               for (int64_t i = r.begin(); i != r.end() && found == 0; ++i)
                 for (int x = list[i].x0; x < list[i].x1 && found == 0; ++x)
                   found += count(list[i].row * nx + x);
               return found;
             },
             [](int64_t a, int64_t b) { return a + b; }) > 0;
}

// ---- storage dispatch -------------------------------------------------------------------------

template <class A>
struct Tag {
  using type = A;
};

// The fast path when every field shares one precision, any mix otherwise.
template <class Fn>
auto dispatch(std::initializer_list<const Field3D*> fields, Fn&& fn) {
  const Precision first = (*fields.begin())->precision();
  const bool same = std::all_of(fields.begin(), fields.end(),
                                [&](const Field3D* f) { return f->precision() == first; });
  if (!same) return fn(Tag<AnyAccess>{});
  return first == Precision::FP16 ? fn(Tag<Fp16Access>{}) : fn(Tag<Fp32Access>{});
}

// ---- checks -----------------------------------------------------------------------------------

void requireSameGrid(const Field3D& a, const Field3D& b, const char* what) {
  if (a.empty() || b.empty())
    throw Error(ErrorKind::Usage, std::string("level set: ") + what + " is empty");
  if (a.grid().dims != b.grid().dims)
    throw Error(ErrorKind::Usage,
                std::string("level set: ") + what + " is not on the level set's grid");
}

void ensureLike(Field3D& scratch, const Field3D& phi) {
  if (scratch.empty() || scratch.grid() != phi.grid() || scratch.precision() != phi.precision())
    scratch = Field3D("level-set-scratch", phi.grid(), phi.precision(), nullptr);
}

// The result of a ping-pong loop back into phi: over the band only when there is one (nothing
// else was written).
void copyResult(const Field3D& from, Field3D& phi, const Band* band) {
  if (band)
    copySpans(from, phi, *band);
  else
    copyField(from, phi);
}

// Up to `passes` passes between phi and scratch, each reading one buffer and writing the other,
// the result back in phi (over the band only when there is one). pass(from, to, n) returns true
// to stop after pass n. Returns the number of passes run.
template <class Pass>
int pingPong(Field3D& phi, Field3D& scratch, int passes, const Band* band, Pass&& pass) {
  Field3D* from = &phi;
  Field3D* to = &scratch;
  int done = 0;
  for (int n = 0; n < passes; ++n) {
    const bool stop = pass(*from, *to, n);
    std::swap(from, to);
    done = n + 1;
    if (stop) break;
  }
  if (from != &phi) copyResult(*from, phi, band);
  return done;
}

void checkOrder(const LevelSetSettings& s) {
  if (s.spatialOrder != 1 && s.spatialOrder != 2)
    throw Error(ErrorKind::Usage, "level set: the spatial order must be 1 or 2");
}

float checkedCfl(const LevelSetSettings& s) {
  if (!(s.cfl > 0.f) || !std::isfinite(s.cfl))
    throw Error(ErrorKind::Usage, "level set: the CFL factor must be a positive number");
  return std::min(s.cfl, 1.f);
}

// ---- kernels per storage ----------------------------------------------------------------------

template <class A, int Order>
ChangeSums substepWith(const Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                       const DeviceBitMask* mask, const LevelSetSettings& s, float dt, Field3D& out,
                       const Band* band) {
  const GridSpec& g = phi.grid();
  LevelSetStepKernel<A, Order> k;
  k.phi = accessTo<A>(FieldView(phi));
  k.out = accessTo<A>(FieldView(out));
  k.phi0 = accessTo<A>(FieldView(phi0));
  k.ghat = accessTo<A>(FieldView(ghat));
  if (mask) k.mask = mask->view();
  k.dims = g.dims;
  k.spacing = g.spacing;
  k.dt = dt;
  k.lambda = s.lambda;
  k.curvatureEpsilon = s.curvatureEpsilon;
  k.kappaMax = 1.f / g.minSpacing();
  k.nearBand = kNearSurfaceBand * g.minSpacing();
  if (band) return launchBand<ChangeSums>("level set: step (band)", k, *band);
  return launchStencil<ChangeSums>("level set: step", k, g.dims);
}

ChangeSums substep(const Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                   const DeviceBitMask* mask, const LevelSetSettings& s, float dt, Field3D& out,
                   const Band* band = nullptr) {
  return dispatch({&phi, &phi0, &ghat, &out}, [&](auto tag) {
    using A = typename decltype(tag)::type;
    return s.spatialOrder == 1 ? substepWith<A, 1>(phi, phi0, ghat, mask, s, dt, out, band)
                               : substepWith<A, 2>(phi, phi0, ghat, mask, s, dt, out, band);
  });
}

// What a band pass's mean change divides by beyond the voxels it ran over: the band's voxels
// (0: those it ran over) and, for the mean near the surface, the near voxels it skipped.
struct BandMean {
  int64_t voxels = 0;
  double idleNear = 0.0;
};

template <class A, int Order>
double redistancePassWith(const Field3D& in, Field3D& out, bool initialise, const Field3D* base,
                          float stopBand, const Band* band, const BandMean& mean) {
  const GridSpec& g = in.grid();
  RedistanceKernel<A, Order> k;
  k.in = accessTo<A>(FieldView(in));
  k.out = accessTo<A>(FieldView(out));
  if (base) {
    k.base = accessTo<A>(FieldView(*base));
    k.keepWithin = kRedistanceKeepsBaseWithin * g.minSpacing();
  } else {
    k.withoutBase();
  }
  k.dims = g.dims;
  k.spacing = g.spacing;
  k.dxMin = g.minSpacing();
  k.dtau = (Order == 2 ? 0.3f : 0.5f) * k.dxMin;
  k.initialise = initialise;
  if (stopBand > 0.f) k.nearBand = stopBand * k.dxMin;
  const ChangeSums c = band ? launchBand<ChangeSums>("level set: redistance (band)", k, *band)
                            : launchStencil<ChangeSums>("level set: redistance", k, g.dims);
  if (stopBand > 0.f) {
    const double near = c.nearCount + mean.idleNear;
    return near > 0.0 ? c.nearSumSquared / (double(k.dxMin) * k.dxMin) / near : 0.0;
  }
  const double voxels =
      band ? double(std::max<int64_t>(std::max(band->voxels, mean.voxels), 1)) : double(in.size());
  return c.sumSquared / (double(k.dxMin) * k.dxMin) / voxels;
}

double redistancePass(const Field3D& in, Field3D& out, bool initialise, int order,
                      const Field3D* base = nullptr, float stopBand = 0.f,
                      const Band* band = nullptr, const BandMean& mean = {}) {
  auto run = [&](auto tag) {
    using A = typename decltype(tag)::type;
    return order == 1 ? redistancePassWith<A, 1>(in, out, initialise, base, stopBand, band, mean)
                      : redistancePassWith<A, 2>(in, out, initialise, base, stopBand, band, mean);
  };
  return base ? dispatch({&in, &out, base}, run) : dispatch({&in, &out}, run);
}

}  // namespace

void copyField(const Field3D& from, Field3D& to) {
  const FieldView a(from), b(to);
  exec::parallelFor("level set: copy", int64_t(from.size()),
                    [=] VISOPT_HD(int64_t v) { b.store(size_t(v), a.load(size_t(v))); });
}

// ---- the level-set step (Eq. 23) ------------------------------------------------------------

namespace {

// dt from the bounds of ghat (the formula levelSetStep documents).
double timeStepFrom(const StepBounds& b, const GridSpec& g, const LevelSetSettings& s) {
  const float cfl = checkedCfl(s);
  const double h = g.minSpacing();
  double dt = std::numeric_limits<double>::infinity();
  if (b.maxGradG > 0.f) dt = std::min(dt, h / double(b.maxGradG));      // advection
  if (b.maxG > 0.f) dt = std::min(dt, h * h / (6.0 * double(b.maxG)));  // curvature
  const double maxLambda = std::max(0.0, double(s.lambda) - double(b.minG));
  if (maxLambda > 0.0) dt = std::min(dt, 1.0 / maxLambda);  // relaxation
  if (!std::isfinite(dt)) dt = h * h;  // nothing moves: any bounded step will do
  return double(cfl) * dt;
}

// The bounds over the band's voxels only: stability matters only where phi is updated.
StepBounds stepBoundsWithin(const Field3D& ghat, const Band& band) {
  const GridSpec& g = ghat.grid();
  const StepBoundsKernel k{FieldView(ghat), g.dims, g.spacing};
  const int64_t nx = g.dims.x;
  const RowSpan* list = band.spans.data();
  return tbb::parallel_reduce(
      tbb::blocked_range<int64_t>(0, int64_t(band.spans.size())), StepBounds{},
      [=](const tbb::blocked_range<int64_t>& r, StepBounds b) {
        for (int64_t i = r.begin(); i != r.end(); ++i)
          for (int x = list[i].x0; x < list[i].x1; ++x) b = b + k(list[i].row * nx + x);
        return b;
      },
      [](const StepBounds& a, const StepBounds& b) { return a + b; });
}

// ---- the semi-implicit step (kernels/implicit_diffusion.h) -----------------------------------

static_assert(kImplicitLanes == kBrick, "a group of lines is one brick wide");

// The groups of lines along `axis` (0 x, 1 y, 2 z) through the bricks flagged in `work` (per
// brick, x fastest; empty: every brick, the dense path), each run of consecutive flagged bricks
// along the axis one segment. Lanes run along x for y and z lines, along y for x lines.
// `floats` is set to the coefficient floats all groups need together (2 n lanes each).
std::vector<ImplicitLines> implicitLinesAlong(const glm::ivec3& dims, int axis,
                                              const std::vector<uint8_t>& work, int64_t& floats) {
  const glm::ivec3 nb = (dims + (kBrick - 1)) / kBrick;
  const int64_t stride[3] = {1, int64_t(dims.x), int64_t(dims.x) * dims.y};
  const int laneAxis = axis == 0 ? 1 : 0;
  const int groupAxis = 3 - axis - laneAxis;
  auto flagged = [&](const glm::ivec3& b) {
    return work.empty() ||
           work[(size_t(b.z) * size_t(nb.y) + size_t(b.y)) * size_t(nb.x) + size_t(b.x)] != 0;
  };
  std::vector<ImplicitLines> lines;
  floats = 0;
  glm::ivec3 b(0);
  for (int q = 0; q < nb[groupAxis]; ++q)
    for (int p = 0; p < nb[laneAxis]; ++p) {
      b[groupAxis] = q;
      b[laneAxis] = p;
      for (int start = 0; start < nb[axis];) {
        b[axis] = start;
        if (!flagged(b)) {
          ++start;
          continue;
        }
        int end = start + 1;
        for (; end < nb[axis]; ++end) {
          b[axis] = end;
          if (!flagged(b)) break;
        }
        const int v0 = start * kBrick, v1 = std::min(end * kBrick, dims[axis]);
        const int lane0 = p * kBrick, g0 = q * kBrick;
        const int g1 = std::min(g0 + kBrick, dims[groupAxis]);
        for (int g = g0; g < g1; ++g) {
          ImplicitLines L;
          L.first = v0 * stride[axis] + lane0 * stride[laneAxis] + g * stride[groupAxis];
          L.step = stride[axis];
          L.laneStep = stride[laneAxis];
          L.n = v1 - v0;
          L.lanes = std::min(kBrick, dims[laneAxis] - lane0);
          L.lowFace = v0 == 0;
          L.highFace = v1 == dims[axis];
          L.coefficients = floats;
          floats += 2 * int64_t(L.n) * kImplicitLanes;
          lines.push_back(L);
        }
        start = end;
      }
    }
  return lines;
}

// One LOD solve along one axis over the groups of lines: on the CPU each task keeps its
// coefficients in a buffer of its own (one line's worth, cache-resident), on CUDA each group
// has its slice of one buffer.
template <class A>
void solveImplicitAxis(const Field3D& delta, const Field3D& ghat, const Field3D& before, int axis,
                       bool firstAxis, const std::vector<ImplicitLines>& lines, int64_t floats,
                       float r) {
  if (lines.empty()) return;
  const A d = accessTo<A>(FieldView(delta));
  const A g = accessTo<A>(FieldView(ghat));
  const A b = accessTo<A>(FieldView(before));
  const bool unitLanes = axis != 0;
  const int64_t n = int64_t(lines.size());
  if (activeBackend() == Backend::CUDA) {
    DeviceBuffer<ImplicitLines> list(lines.size());
    std::copy(lines.begin(), lines.end(), list.data());
    DeviceBuffer<float> coefficients{size_t(floats)};
    const ImplicitLines* l = list.data();
    float* w = coefficients.data();
    exec::parallelFor("level set: semi-implicit solve", n, [=] VISOPT_HD(int64_t i) {
      if (unitLanes)
        solveImplicitLines<A, true>(d, g, b, l[i], r, w, firstAxis);
      else
        solveImplicitLines<A, false>(d, g, b, l[i], r, w, firstAxis);
    });
    return;
  }
  int32_t longest = 0;
  for (const ImplicitLines& L : lines) longest = std::max(longest, L.n);
  exec::LaunchTimer timer("level set: semi-implicit solve", double(n));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, n, 8),
                    [&](const tbb::blocked_range<int64_t>& range) {
                      std::vector<float> w(size_t(2) * size_t(longest) * kImplicitLanes);
                      for (int64_t i = range.begin(); i != range.end(); ++i) {
                        ImplicitLines L = lines[size_t(i)];
                        L.coefficients = 0;
                        if (unitLanes)
                          solveImplicitLines<A, true>(d, g, b, L, r, w.data(), firstAxis);
                        else
                          solveImplicitLines<A, false>(d, g, b, L, r, w.data(), firstAxis);
                      }
                    });
}

// Eq. 23 over time `dt` in one semi-implicit step: phi^n must be in `before` over the voxels
// updated (the work spans on the band path, every voxel otherwise); returns the change sums
// against it.
template <class A>
ChangeSums semiImplicitWith(Field3D& phi, const Field3D& before, const Field3D& phi0,
                            const Field3D& ghat, const DeviceBitMask* mask,
                            const LevelSetSettings& s, double dt, const Band* band,
                            const std::vector<uint8_t>& workBricks) {
  const GridSpec& g = phi.grid();
  // phi holds the increment phi_D - phi^n from the first solve on (over the work bricks).
  bool solved = false;
  for (int axis = 0; axis < 3; ++axis) {
    if (g.dims[axis] < 2) continue;
    int64_t floats = 0;
    const std::vector<ImplicitLines> lines = implicitLinesAlong(g.dims, axis, workBricks, floats);
    const double h = double(g.spacing[axis]);
    solveImplicitAxis<A>(phi, ghat, before, axis, !solved, lines, floats, float(dt / (h * h)));
    solved = true;
  }
  SemiImplicitFinish<A> k;
  k.phi = accessTo<A>(FieldView(phi));
  k.before = accessTo<A>(FieldView(before));
  k.phi0 = accessTo<A>(FieldView(phi0));
  k.ghat = accessTo<A>(FieldView(ghat));
  if (mask) k.mask = mask->view();
  k.dt = float(dt);
  k.lambda = s.lambda;
  k.nearBand = kNearSurfaceBand * g.minSpacing();
  k.nx = g.dims.x;
  k.solved = solved;
  // Over the solved bricks only: the work spans may also cross a fixed brick (narrow_band.h),
  // where phi holds values, not increments.
  if (band) {
    const SpanList solvedSpans = spansOfBricks(workBricks, g.dims);
    return launchBand<ChangeSums>("level set: semi-implicit finish (band)", k, solvedSpans);
  }
  return launchStencil<ChangeSums>("level set: semi-implicit finish", k, g.dims);
}

ChangeSums semiImplicitStep(Field3D& phi, const Field3D& before, const Field3D& phi0,
                            const Field3D& ghat, const DeviceBitMask* mask,
                            const LevelSetSettings& s, double dt, const Band* band,
                            const std::vector<uint8_t>& workBricks) {
  return dispatch({&phi, &before, &phi0, &ghat}, [&](auto tag) {
    using A = typename decltype(tag)::type;
    return semiImplicitWith<A>(phi, before, phi0, ghat, mask, s, dt, band, workBricks);
  });
}

}  // namespace

double levelSetTimeStep(const Field3D& ghat, const LevelSetSettings& s) {
  checkedCfl(s);
  const GridSpec& g = ghat.grid();
  const StepBoundsKernel k{FieldView(ghat), g.dims, g.spacing};
  const StepBounds b =
      exec::reduce("level set: time step", int64_t(ghat.size()), StepBounds{}, k, Plus{});
  return timeStepFrom(b, g, s);
}

double levelSetSubstep(const Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                       const DeviceBitMask* mask, const LevelSetSettings& s, double dt,
                       Field3D& out) {
  return double(substep(phi, phi0, ghat, mask, s, float(dt), out).maxAbs);
}

LevelSetStepStats levelSetStep(Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                               const DeviceBitMask* mask, const LevelSetSettings& s,
                               Field3D& scratch, NarrowBand* band) {
  requireSameGrid(phi, phi, "phi");
  requireSameGrid(phi, phi0, "the base SDF phi0");
  requireSameGrid(phi, ghat, "ghat");
  if (mask && mask->dims() != phi.grid().dims)
    throw Error(ErrorKind::Usage, "level set: the world mask is not on the level set's grid");
  if (s.substeps < 0) throw Error(ErrorKind::Usage, "level set: substeps must be >= 0");
  checkOrder(s);
  ensureLike(scratch, phi);

  LevelSetStepStats stats;
  stats.substeps = s.substeps;
  // The band path: the spans of active bricks, fixed for this call. Scratch starts as a copy of
  // phi over the band's halo (as far as the stencils reach) and only the band is written, so the
  // stencils at the spans' edges read the same values whichever buffer is the source.
  NarrowBand own;
  NarrowBand& narrow = band ? *band : own;
  const bool banded = useBand(s) && s.substeps > 0;
  // The band's fixed bricks (narrow_band.h: markFixed) hold for the ghat and phi0 they were
  // marked with only; the kernels then skip them.
  const Band* work = nullptr;
  if (banded) {
    // Without the return term (lambda = 0) phi0 and the region the surface swept need no band.
    narrow.ensure(phi, s.lambda > 0.f ? &phi0 : nullptr, s.band);
    const bool skipFixed = narrow.fixedFor(ghat) && narrow.base() == &phi0;
    work = skipFixed ? &narrow.work() : &narrow.band();
    stats.bandVoxels = narrow.band().voxels;
    stats.workVoxels = work->voxels;
    copySpans(phi, scratch, skipFixed ? narrow.workHalo() : narrow.halo());
    // Over the whole band (fixed bricks have ghat = 0 and grad ghat = 0); with the marks, from
    // bounds kept per brick while ghat stays the same.
    const StepBounds bounds =
        narrow.fixedFor(ghat) ? narrow.workBounds(ghat) : stepBoundsWithin(ghat, narrow.band());
    stats.timeStep = timeStepFrom(bounds, ghat.grid(), s);
  } else {
    stats.timeStep = levelSetTimeStep(ghat, s);
  }
  if (s.semiImplicit && s.substeps > 0) {
    // One step over the substeps' time; the statistics per substep's worth of it, as below.
    // scratch holds phi^n: over the band's halo from above, everywhere on the dense path.
    if (!banded) copyField(phi, scratch);
    std::vector<uint8_t> workBricks;
    if (banded) workBricks = narrow.workBrickFlags(work != &narrow.band());
    const double n = double(s.substeps);
    const ChangeSums c =
        semiImplicitStep(phi, scratch, phi0, ghat, mask, s, stats.timeStep * n, work, workBricks);
    stats.maxChange = double(c.maxAbs) / n;
    stats.insideRise = double(c.insideRiseMax) / n;
    stats.nearMaxChange = double(c.nearMaxAbs) / n;
    stats.meanChange = c.sumAbs / double(phi.size()) / n;
  } else {
    pingPong(phi, scratch, s.substeps, work, [&](const Field3D& from, Field3D& to, int) {
      const ChangeSums c = substep(from, phi0, ghat, mask, s, float(stats.timeStep), to, work);
      stats.maxChange = std::max(stats.maxChange, double(c.maxAbs));
      stats.insideRise = std::max(stats.insideRise, double(c.insideRiseMax));
      stats.nearMaxChange = std::max(stats.nearMaxChange, double(c.nearMaxAbs));
      stats.meanChange += c.sumAbs / double(phi.size()) / double(s.substeps);
      return false;
    });
  }
  if (!banded) {
    stats.hasInterface = hasInterface(phi);
    return stats;
  }
  // Outside the band's halo phi did not change and lies farther than the band from the surface.
  stats.hasInterface = interfaceWithin(phi, narrow.halo());
  narrow.refresh(phi);
  return stats;
}

void markFixedBricks(Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                     const LevelSetSettings& s, NarrowBand& band) {
  if (!useBand(s) || !(s.lambda > 0.f)) return;  // without the return term no phi0 in the band
  requireSameGrid(phi, phi0, "the base SDF phi0");
  requireSameGrid(phi, ghat, "ghat");
  band.ensure(phi, &phi0, s.band);
  band.markFixed(phi, ghat);
}

// ---- redistancing (Eq. 18) --------------------------------------------------------------------

double redistanceIteration(const Field3D& in, Field3D& out, int spatialOrder) {
  requireSameGrid(in, out, "the redistancing output");
  return redistancePass(in, out, false, spatialOrder);
}

bool hasInterface(const Field3D& phi) {
  return exec::reduce("level set: interface", int64_t(phi.size()), int64_t(0),
                      InterfaceCount{FieldView(phi)}, Plus{}) > 0;
}

RedistanceStats redistance(Field3D& phi, const LevelSetSettings& s, Field3D& scratch,
                           const Field3D* base, float stopBand, NarrowBand* band) {
  requireSameGrid(phi, phi, "phi");
  if (base) requireSameGrid(phi, *base, "the base SDF");
  checkOrder(s);
  ensureLike(scratch, phi);
  RedistanceStats stats;
  // The band path as in levelSetStep: spans fixed for the call, scratch a copy of phi over the
  // band's halo. A surface lies within the band, so the band answers whether there is one.
  NarrowBand own;
  NarrowBand& narrow = band ? *band : own;
  const bool banded = useBand(s) && s.redistanceIterations > 0;
  // A band built by the step serves as it is (with phi0 when the return term is on).
  if (banded) narrow.ensure(phi, base, s.band);
  const bool surface = banded ? interfaceWithin(phi, narrow.halo()) : hasInterface(phi);
  if (!surface) {
    stats.converged = true;
    return stats;
  }
  // Fixed bricks equal the base: redistancing against it holds them (narrow_band.h). The mean
  // change still counts them, as 0, so that the early stop does not depend on the skip.
  const Band* work = nullptr;
  BandMean mean;
  if (banded) {
    const bool skipFixed = base && narrow.base() == base && narrow.fixedBricks() > 0;
    work = skipFixed ? &narrow.work() : &narrow.band();
    stats.bandVoxels = narrow.band().voxels;
    stats.workVoxels = work->voxels;
    mean.voxels = narrow.band().voxels;
    if (skipFixed && stopBand > 0.f)
      mean.idleNear = double(narrow.idleNearVoxels(phi, stopBand * phi.grid().minSpacing()));
    copySpans(phi, scratch, skipFixed ? narrow.workHalo() : narrow.halo());
  }
  stats.iterations = pingPong(
      phi, scratch, s.redistanceIterations, work, [&](const Field3D& from, Field3D& to, int n) {
        // The first pass also sets the interface band to its subcell distance (kept afterwards).
        stats.meanSquaredChange = redistancePass(from, to, n == 0, s.spatialOrder, base,
                                                 std::max(stopBand, 0.f), work, mean);
        stats.converged = stats.meanSquaredChange < double(s.redistanceTolerance);
        return stats.converged;
      });
  if (banded) narrow.refresh(phi);
  return stats;
}

// ---- an SDF from an isovalue ----------------------------------------------------------------

namespace {

struct IsoGradient {
  double sum = 0.0;
  int64_t count = 0;
  VISOPT_HD IsoGradient operator+(const IsoGradient& o) const {
    return {sum + o.sum, count + o.count};
  }
};

// |grad s| (world units, central differences) at voxels next to the isosurface.
struct IsoGradientKernel {
  FieldView s;
  float iso = 0.f;
  glm::vec3 spacing{1.f};
  bool everywhere = false;  // all voxels (when none is next to the isosurface)
  VISOPT_HD IsoGradient operator()(int64_t v) const {
    const int64_t nx = s.dims.x, ny = s.dims.y;
    const auto [i, j, k] = voxelIjk(v, s.dims);
    const StencilAxis ax = stencilAxis(i, s.dims.x, 1, spacing.x);
    const StencilAxis ay = stencilAxis(j, s.dims.y, nx, spacing.y);
    const StencilAxis az = stencilAxis(k, s.dims.z, nx * ny, spacing.z);
    auto at = [&](int64_t off) { return s.load(size_t(v + off)) - iso; };
    const float c = at(0), xm = at(ax.m), xp = at(ax.p), ym = at(ay.m), yp = at(ay.p),
                zm = at(az.m), zp = at(az.p);
    if (!everywhere && !nextToInterface(c, xm, xp, ym, yp, zm, zp)) return {};
    const float gx = (xp - xm) * ax.central, gy = (yp - ym) * ay.central,
                gz = (zp - zm) * az.central;
    return {double(sqrtf(gx * gx + gy * gy + gz * gz)), 1};
  }
};

}  // namespace

Field3D sdfFromIsovalue(const Volume& volume, double isovalue, bool insideHigh,
                        const LevelSetSettings& s, Precision p, MemoryLedger* ledger,
                        float presmoothSigma) {
  if (volume.normalized.empty())
    throw Error(ErrorKind::Usage, "SDF from an isovalue: the volume is empty");
  if (!std::isfinite(isovalue))
    throw Error(ErrorKind::Usage, "SDF from an isovalue: the isovalue is not a number");
  if (std::isnan(presmoothSigma))
    throw Error(ErrorKind::Usage, "SDF from an isovalue: the smoothing sigma is not a number");
  const GridSpec& g = volume.grid();
  const float iso = volume.toNormalized(isovalue);
  // The isovalue is crossed in the pre-smoothed field (see the header for why and how much).
  Field3D smoothed;
  if (presmoothSigma > 0.f) smoothed = gaussianSmoothed(volume.normalized, presmoothSigma, ledger);
  const Field3D& scalar = smoothed.empty() ? volume.normalized : smoothed;
  IsoGradientKernel gk{FieldView(scalar), iso, g.spacing, false};
  IsoGradient grad =
      exec::reduce("sdf: iso gradient", int64_t(g.voxelCount()), IsoGradient{}, gk, Plus{});
  if (grad.count == 0 || grad.sum <= 0.0) {
    gk.everywhere = true;
    grad = exec::reduce("sdf: iso gradient", int64_t(g.voxelCount()), IsoGradient{}, gk, Plus{});
  }
  const float scale = grad.sum > 0.0 ? float(double(grad.count) / grad.sum) : 1.f;
  const float sign = insideHigh ? -1.f : 1.f;
  const float far = std::max(g.diagonal(), g.minSpacing());

  Field3D phi("context-sdf", g, p, ledger);
  {
    const FieldView src(scalar), dst(phi);
    exec::parallelFor("sdf: from isovalue", int64_t(g.voxelCount()), [=] VISOPT_HD(int64_t v) {
      const float d = sign * (src.load(size_t(v)) - iso) * scale;
      dst.store(size_t(v), fminf(fmaxf(d, -far), far));
    });
  }
  smoothed = Field3D();  // `scalar` is not read after this
  // The distance away from the interface by fast sweeping, then redistancing (Eq. 18) only to
  // polish. Redistancing alone from s - iso needs enough iterations for the front to cross the
  // grid (corrections travel half a voxel per iteration): 800 on a 256^2 x 108 CT. Here:
  //  1. one redistancing pass with the subcell fix sets the voxels next to the interface to
  //     their subcell distance (kernels/redistance.h), exactly as the first iteration would;
  //  2. fast sweeping propagates |phi| from that band to the whole grid (first order, exact for
  //     planes, within a fraction of a voxel elsewhere), the sign is the start field's;
  //  3. up to 64 redistancing iterations from there bring the field near the interface to the
  //     second-order fixed point the long run reached; the band keeps its subcell values
  //     throughout (no re-initialisation). They stop once the voxels within
  //     kRedistanceStopBandVoxels of the surface change by less than 1e-6 voxel^2 (mean square),
  //     as the joint loop's redistancing measures its own: that band is where the level-set step
  //     and the narrow band start from. Farther out the iterations only relax the sweep's
  //     first-order values towards the second-order scheme's, which nothing reads as more than
  //     a sign and a bound (coarse levels redistance their own restriction). Measured to the whole
  //     grid's mean instead, the 64 always ran (2.4 s on the Cranium CT, 0.9 s on the default
  //     scene); to the near band, 12 and 6. A sphere (tests/unit/test_level_set.cpp): worst error
  //     0.61 voxel (0.31 after 64), within 3 voxels of the surface 0.075 either way.
  // Near the grid's faces the sweep measures the distance to the real surface; redistancing
  // lets nothing in through the faces (kernels/redistance.h), so the polish keeps it.
  Field3D scratch("sdf-scratch", g, p, ledger);
  const int64_t band = exec::reduce("level set: interface", int64_t(phi.size()), int64_t(0),
                                    InterfaceCount{FieldView(phi)}, Plus{});
  if (band == 0) return phi;  // no interface: nothing to measure distance from
  checkOrder(s);
  redistancePass(phi, scratch, true, s.spatialOrder);
  {
    const size_t n = phi.size();
    std::vector<float> dist(n);
    std::vector<uint8_t> fixed(n);
    std::vector<uint8_t> negative(n);
    const FieldView start(phi), banded(scratch);
    const InterfaceCount isBand{start};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t v = r.begin(); v != r.end(); ++v) {
        negative[v] = start.load(v) < 0.f;
        fixed[v] = isBand(int64_t(v)) != 0;
        dist[v] = fixed[v] ? std::fabs(banded.load(v)) : std::numeric_limits<float>::infinity();
      }
    });
    fastSweep(dist, fixed, g.dims, g.spacing, 1e-3f * g.minSpacing(), 8);
    const FieldView out(phi);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t v = r.begin(); v != r.end(); ++v) {
        const float d = std::min(dist[v], far);
        out.store(v, negative[v] ? -d : d);
      }
    });
  }
  LevelSetSettings r = s;
  r.redistanceIterations = std::max(s.redistanceIterations, 64);
  r.redistanceTolerance = std::min(s.redistanceTolerance, 1e-6f);
  pingPong(
      phi, scratch, r.redistanceIterations, nullptr, [&](const Field3D& from, Field3D& to, int) {
        return redistancePass(from, to, false, r.spatialOrder, nullptr, kRedistanceStopBandVoxels) <
               double(r.redistanceTolerance);
      });
  return phi;
}

// ---- thin shells (Eq. 26) ---------------------------------------------------------------------

Field3D thinShell(const Field3D& filled, float d, Precision p, MemoryLedger* ledger) {
  if (filled.empty()) throw Error(ErrorKind::Usage, "thin shell: the SDF is empty");
  if (!(d >= 0.f) || !std::isfinite(d))
    throw Error(ErrorKind::Usage, "thin shell: the thickness must be a number >= 0");
  Field3D shell("thin-shell", filled.grid(), p, ledger);
  const FieldView src(filled), dst(shell);
  exec::parallelFor("sdf: thin shell", int64_t(filled.size()), [=] VISOPT_HD(int64_t v) {
    dst.store(size_t(v), fabsf(src.load(size_t(v))) - d);
  });
  return shell;
}

}  // namespace visopt
