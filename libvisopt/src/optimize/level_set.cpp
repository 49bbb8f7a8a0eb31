#include "optimize/level_set.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/field_view.h"
#include "exec/parallel.h"
#include "kernels/level_set_step.h"
#include "kernels/redistance.h"
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

// ---- storage dispatch -------------------------------------------------------------------------

template <class A>
struct Tag {
  using type = A;
};

Fp32Access accessOf(const Field3D& f, Tag<Fp32Access>) {
  return {static_cast<float*>(const_cast<void*>(f.raw()))};
}
Fp16Access accessOf(const Field3D& f, Tag<Fp16Access>) {
  return {static_cast<Half*>(const_cast<void*>(f.raw()))};
}
AnyAccess accessOf(const Field3D& f, Tag<AnyAccess>) {
  return {FieldView(f)};
}

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

void copyField(const Field3D& from, Field3D& to) {
  const FieldView a(from), b(to);
  exec::parallelFor("level set: copy", int64_t(from.size()),
                    [=] VISOPT_HD(int64_t v) { b.store(size_t(v), a.load(size_t(v))); });
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
                       const Field3D* mask, const LevelSetSettings& s, float dt, Field3D& out) {
  const GridSpec& g = phi.grid();
  LevelSetStepKernel<A, Order> k;
  k.phi = accessOf(phi, Tag<A>{});
  k.out = accessOf(out, Tag<A>{});
  k.phi0 = accessOf(phi0, Tag<A>{});
  k.ghat = accessOf(ghat, Tag<A>{});
  k.mask = accessOf(mask ? *mask : ghat, Tag<A>{});
  k.maskThreshold = mask ? 0.5f : 3.4e38f;
  k.dims = g.dims;
  k.spacing = g.spacing;
  k.dt = dt;
  k.lambda = s.lambda;
  k.curvatureEpsilon = s.curvatureEpsilon;
  k.kappaMax = 1.f / g.minSpacing();
  return launchStencil<ChangeSums>("level set: step", k, g.dims);
}

ChangeSums substep(const Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                   const Field3D* mask, const LevelSetSettings& s, float dt, Field3D& out) {
  return dispatch({&phi, &phi0, &ghat, &out, mask ? mask : &phi}, [&](auto tag) {
    using A = typename decltype(tag)::type;
    return s.spatialOrder == 1 ? substepWith<A, 1>(phi, phi0, ghat, mask, s, dt, out)
                               : substepWith<A, 2>(phi, phi0, ghat, mask, s, dt, out);
  });
}

template <class A, int Order>
double redistancePassWith(const Field3D& in, Field3D& out, bool initialise) {
  const GridSpec& g = in.grid();
  RedistanceKernel<A, Order> k;
  k.in = accessOf(in, Tag<A>{});
  k.out = accessOf(out, Tag<A>{});
  k.dims = g.dims;
  k.spacing = g.spacing;
  k.dxMin = g.minSpacing();
  k.dtau = (Order == 2 ? 0.3f : 0.5f) * k.dxMin;
  k.initialise = initialise;
  const ChangeSums c = launchStencil<ChangeSums>("level set: redistance", k, g.dims);
  return c.sumSquared / (double(k.dxMin) * k.dxMin) / double(in.size());
}

double redistancePass(const Field3D& in, Field3D& out, bool initialise, int order) {
  return dispatch({&in, &out}, [&](auto tag) {
    using A = typename decltype(tag)::type;
    return order == 1 ? redistancePassWith<A, 1>(in, out, initialise)
                      : redistancePassWith<A, 2>(in, out, initialise);
  });
}

}  // namespace

// ---- the level-set step (Eq. 23) ------------------------------------------------------------

double levelSetTimeStep(const Field3D& ghat, const LevelSetSettings& s) {
  const float cfl = checkedCfl(s);
  const GridSpec& g = ghat.grid();
  const StepBoundsKernel k{FieldView(ghat), g.dims, g.spacing};
  StepBounds init;
  const StepBounds b = exec::reduce("level set: time step", int64_t(ghat.size()), init, k, Plus{});
  const double h = g.minSpacing();
  double dt = std::numeric_limits<double>::infinity();
  if (b.maxGradG > 0.f) dt = std::min(dt, h / double(b.maxGradG));      // advection
  if (b.maxG > 0.f) dt = std::min(dt, h * h / (6.0 * double(b.maxG)));  // curvature
  const double maxLambda = std::max(0.0, double(s.lambda) - double(b.minG));
  if (maxLambda > 0.0) dt = std::min(dt, 1.0 / maxLambda);  // relaxation
  if (!std::isfinite(dt)) dt = h * h;  // nothing moves: any bounded step will do
  return double(cfl) * dt;
}

double levelSetSubstep(const Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                       const Field3D* mask, const LevelSetSettings& s, double dt, Field3D& out) {
  return double(substep(phi, phi0, ghat, mask, s, float(dt), out).maxAbs);
}

LevelSetStepStats levelSetStep(Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                               const Field3D* mask, const LevelSetSettings& s, Field3D& scratch) {
  requireSameGrid(phi, phi, "phi");
  requireSameGrid(phi, phi0, "the base SDF phi0");
  requireSameGrid(phi, ghat, "ghat");
  if (mask) requireSameGrid(phi, *mask, "the world mask");
  if (s.substeps < 0) throw Error(ErrorKind::Usage, "level set: substeps must be >= 0");
  checkOrder(s);
  ensureLike(scratch, phi);

  LevelSetStepStats stats;
  stats.timeStep = levelSetTimeStep(ghat, s);
  stats.substeps = s.substeps;
  Field3D* from = &phi;
  Field3D* to = &scratch;
  for (int n = 0; n < s.substeps; ++n) {
    const ChangeSums c = substep(*from, phi0, ghat, mask, s, float(stats.timeStep), *to);
    stats.maxChange = std::max(stats.maxChange, double(c.maxAbs));
    stats.meanChange += c.sumAbs / double(phi.size()) / double(s.substeps);
    std::swap(from, to);
  }
  if (from != &phi) copyField(*from, phi);
  return stats;
}

// ---- redistancing (Eq. 18) --------------------------------------------------------------------

double redistanceIteration(const Field3D& in, Field3D& out, int spatialOrder) {
  requireSameGrid(in, out, "the redistancing output");
  return redistancePass(in, out, false, spatialOrder);
}

RedistanceStats redistance(Field3D& phi, const LevelSetSettings& s, Field3D& scratch) {
  requireSameGrid(phi, phi, "phi");
  checkOrder(s);
  ensureLike(scratch, phi);
  RedistanceStats stats;
  const int64_t band = exec::reduce("level set: interface", int64_t(phi.size()), int64_t(0),
                                    InterfaceCount{FieldView(phi)}, Plus{});
  if (band == 0) {
    stats.converged = true;
    return stats;
  }
  Field3D* from = &phi;
  Field3D* to = &scratch;
  for (int n = 0; n < s.redistanceIterations; ++n) {
    // The first pass also sets the interface band to its subcell distance (kept afterwards).
    stats.meanSquaredChange = redistancePass(*from, *to, n == 0, s.spatialOrder);
    stats.iterations = n + 1;
    std::swap(from, to);
    if (stats.meanSquaredChange < double(s.redistanceTolerance)) {
      stats.converged = true;
      break;
    }
  }
  if (from != &phi) copyField(*from, phi);
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
    const int i = int(v % nx), j = int((v / nx) % ny), k = int(v / (nx * ny));
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
                        const LevelSetSettings& s, Precision p, MemoryLedger* ledger) {
  if (volume.normalized.empty())
    throw Error(ErrorKind::Usage, "SDF from an isovalue: the volume is empty");
  if (!std::isfinite(isovalue))
    throw Error(ErrorKind::Usage, "SDF from an isovalue: the isovalue is not a number");
  const GridSpec& g = volume.grid();
  const float iso = volume.toNormalized(isovalue);
  IsoGradientKernel gk{FieldView(volume.normalized), iso, g.spacing, false};
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
    const FieldView src(volume.normalized), dst(phi);
    exec::parallelFor("sdf: from isovalue", int64_t(g.voxelCount()), [=] VISOPT_HD(int64_t v) {
      const float d = sign * (src.load(size_t(v)) - iso) * scale;
      dst.store(size_t(v), fminf(fmaxf(d, -far), far));
    });
  }
  // Converge everywhere: the corrections travel half a voxel per iteration from the interface.
  LevelSetSettings r = s;
  const int crossing = int(std::ceil(2.0 * double(g.diagonal()) / double(g.minSpacing()))) + 8;
  r.redistanceIterations = std::max(s.redistanceIterations, crossing);
  r.redistanceTolerance = std::min(s.redistanceTolerance, 1e-6f);
  Field3D scratch("sdf-scratch", g, p, ledger);
  redistance(phi, r, scratch);
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
