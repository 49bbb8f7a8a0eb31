#include "optimize/extinction_optimizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <span>
#include <utility>

#include "core/brick_order.h"
#include "core/device_buffer.h"
#include "core/field_view.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "host/extinction_step_rows.h"
#include "host/importance_behind_rows.h"
#include "host/visibility_scan_tiles.h"
#include "kernels/extinction_step.h"
#include "kernels/importance_behind.h"
#include "kernels/visibility_scan_fast.h"
#include "optimize/level_end.h"
#include "optimize/level_set.h"
#include "optimize/multigrid_transfer.h"
#include "optimize/narrow_band.h"
#include "optimize/optimizer_level.h"
#include "optimize/scan_skip_grid.h"
#include "visopt/error.h"

namespace visopt {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

TransferLookup lookupOf(const DeviceBuffer<glm::vec4>* t) {
  return TransferLookup{t->data(), int(t->size())};
}

float voxelVolume(const GridSpec& g) {
  return g.spacing.x * g.spacing.y * g.spacing.z;
}

// Runs the visibility scan of one frustum grid into `d` (allocated or resized as needed), and
// the running maximum of g behind each cell into `behindMax` when that is requested.
ScanSums scanGrid(const char* name, const FrustumGrid& frustum, const GridSpec& grid,
                  const Field3D& mu, const Field3D& importance, std::optional<Field3D>& d,
                  const char* fieldName, Precision precision, MemoryLedger* ledger,
                  const SurfaceSet& surfaces = {}, const ScreenWeights& weights = {},
                  std::optional<Field3D>* behindMax = nullptr, const char* maxName = nullptr,
                  const ScanSkipGrid& skip = {}) {
  auto ensure = [&](std::optional<Field3D>& f, const char* fname) {
    const glm::ivec3 storage = frustumStorageDims(frustum.dims);
    if (!f || f->grid().dims != storage) {
      f.reset();
      GridSpec fg;
      fg.dims = storage;
      f.emplace(fname, fg, precision, ledger);
    }
  };
  ensure(d, fieldName);
  VisibilityScan scan;
  scan.frustum = FrustumMap(frustum);
  scan.volume = GridMap(grid);
  scan.mu = FieldView(mu);
  scan.importance = FieldView(importance);
  scan.out = FrustumFieldView(*d, frustum.dims);
  scan.surfaces = surfaces;
  scan.weights = weights;
  scan.skip = skip;
  if (behindMax) {
    ensure(*behindMax, maxName);
    scan.behindMax = FrustumFieldView(**behindMax, frustum.dims);
  }
  const int64_t rays = int64_t(frustum.dims.x) * frustum.dims.y;
  auto sum = [] VISOPT_HD(const ScanSums& a, const ScanSums& b) { return a + b; };
  if (frustum.dims.z > kScanBufferCells)
    return exec::reduce(name, rays, ScanSums{}, FastVisibilityScan<0>{scan}, sum);
  if (activeBackend() == Backend::CPU) return scanTilesOnHost(name, scan);
  return exec::reduce(name, rays, ScanSums{}, FastVisibilityScan<kScanBufferCells>{scan}, sum);
}

ExtinctionGradient gradientOf(const ExtinctionProblem& p, const Field3D* dView,
                              const Field3D* dLight) {
  ExtinctionGradient g;
  g.volume = GridMap(p.grid);
  g.mu = FieldView(*p.mu);
  if (p.baseField) g.base.field = FieldView(*p.baseField);
  if (p.scalars) g.base.scalars = FieldView(*p.scalars);
  if (p.transfer) g.base.transfer = lookupOf(p.transfer);
  g.rho = p.rho;
  g.q = dView ? p.q : 0.f;
  g.r = dLight ? p.r : 0.f;
  g.view = FrustumMap(p.view);
  g.light = FrustumMap(p.light);
  if (dView) g.dView = FrustumFieldView(*dView, p.view.dims);
  if (dLight) g.dLight = FrustumFieldView(*dLight, p.light.dims);
  return g;
}

struct ScanResult {
  ScanSums view, light;
  std::optional<Field3D> dView, dLight;
};

ScanResult scanProblem(const ExtinctionProblem& p, Precision precision) {
  ScanResult r;
  if (p.q != 0.f)
    r.view = scanGrid("grid updates: view", p.view, p.grid, *p.mu, *p.importance, r.dView,
                      "view-derivative", precision, nullptr);
  if (p.r != 0.f)
    r.light = scanGrid("grid updates: light", p.light, p.grid, *p.mu, *p.importance, r.dLight,
                       "light-derivative", precision, nullptr);
  return r;
}

}  // namespace

ProblemEvaluation evaluateProblem(const ExtinctionProblem& p, Precision precision) {
  ScanResult scans = scanProblem(p, precision);
  ExtinctionGradient g = gradientOf(p, nullptr, nullptr);
  const float dV = voxelVolume(p.grid);
  const float rho = p.rho;
  double eRho = exec::reduce(
      "energy", int64_t(p.grid.voxelCount()), 0.0,
      [=] VISOPT_HD(int64_t v) {
        const float diff = g.mu.load(size_t(v)) - g.base.at(size_t(v));
        return 0.5 * double(rho) * double(diff) * double(diff) * double(dV);
      },
      [] VISOPT_HD(double a, double b) { return a + b; });
  ProblemEvaluation e;
  e.energyRho = eRho;
  e.energyQ = -double(p.q) * scans.view.gMuT;
  e.energyR = -double(p.r) * scans.light.gMuT;
  e.visibilityView = scans.view.gMu > 0 ? scans.view.gMuT / scans.view.gMu : 0.0;
  e.visibilityLight = scans.light.gMu > 0 ? scans.light.gMuT / scans.light.gMu : 0.0;
  return e;
}

std::vector<float> analyticGradient(const ExtinctionProblem& p, Precision precision) {
  ScanResult scans = scanProblem(p, precision);
  ExtinctionGradient g =
      gradientOf(p, scans.dView ? &*scans.dView : nullptr, scans.dLight ? &*scans.dLight : nullptr);
  DeviceBuffer<float> out(p.grid.voxelCount());
  float* o = out.data();
  exec::parallelFor("gradient", int64_t(out.size()), [=] VISOPT_HD(int64_t v) {
    float mbar;
    o[v] = g.at(v, mbar);
  });
  return std::vector<float>(o, o + out.size());
}

// ---- the optimiser ---------------------------------------------------------------------------

ExtinctionOptimizer::ExtinctionOptimizer(MemoryLedger* ledger, Precision precision,
                                         std::string ledgerSuffix)
    : ledger_(ledger), precision_(precision), ledgerSuffix_(std::move(ledgerSuffix)) {}
ExtinctionOptimizer::~ExtinctionOptimizer() = default;

const Field3D* ExtinctionOptimizer::extinction() const {
  return level_ && level_->finest && level_->mu ? &*level_->mu : nullptr;
}

void ExtinctionOptimizer::reset() {
  level_.reset();
  follower_.reset();
}

std::vector<const Field3D*> ExtinctionOptimizer::surfaces() const {
  std::vector<const Field3D*> out;
  if (level_ && level_->finest)
    for (const auto& p : level_->phi) out.push_back(&p);
  return out;
}

const Field3D* ExtinctionOptimizer::importanceBehind() const {
  return level_ && level_->finest && level_->ghat ? &*level_->ghat : nullptr;
}

namespace {

struct DeviationSums {
  double sum = 0, max = 0, count = 0;
};

// The lens and windowing mask of the view rays (Himmler & Günther 2026, §III-F, Fig. 8).
ScreenWeights screenWeightsOf(const OptimizationInputs& in) {
  ScreenWeights weights;
  if (in.lens.radius > 0.f) {
    weights.lensCentre = glm::vec2(in.lens.x, in.lens.y);
    // The radius is a fraction of the image width; the weights work in [0,1]^2 per axis, so
    // the circle is stretched back to round for non-square images by the aspect below.
    weights.lensRadius = in.lens.radius;
    weights.lensStrength = in.lens.strength;
  }
  if (in.screenMask) weights.mask = FieldView(*in.screenMask);
  return weights;
}

// Substeps of the level-set step per iteration on `level` (LevelSetSettings::reach).
int levelSetSubsteps(const OptimizationInputs& in, const ExtinctionSettings& s,
                     const GridSpec& level, int cap) {
  const LevelSetSettings& ls = in.levelSet;
  const int least = std::max(ls.substeps, 1);
  if (!(ls.reach > 0.f) || !std::isfinite(ls.reach)) return least;
  // The time mean-curvature flow at ghat = 1/2 needs to shrink a sphere of radius
  // reach x R to a point, r^2 = R^2 - 4 ghat t, spread over the coarsest level's iteration
  // cap, in steps of the stable dt = cfl h^2 / 6 (ghat <= 1) of the coarsest grid.
  const GridSpec& fine = in.volume->grid();
  const GridSpec coarsest = levelGrid(fine, 1 << (std::max(s.levels, 1) - 1));
  const double radius = double(ls.reach) * 0.5 * double(fine.diagonal());
  const double h0 = coarsest.minSpacing(), h = level.minSpacing();
  const double cfl = std::clamp(double(ls.cfl), 1e-3, 1.0);
  const double time = radius * radius / 2.0;
  const double dt0 = cfl * h0 * h0 / 6.0;
  const double perIteration = time / dt0 / double(std::max(cap, 1));
  // Finer levels: (h / h0)^2 as many substeps per iteration (each a (h / h0)^2 shorter step).
  const double n = std::ceil(perIteration * (h / h0) * (h / h0));
  return int(std::clamp(n, double(least), 4096.0));
}

}  // namespace

float levelMuMax(const OptimizationInputs& in, const ExtinctionSettings& s, Precision p) {
  float m = s.muMax > 0.f ? s.muMax : in.transferMaxExtinction;
  if (!(m > 0.f)) m = 1.f;
  // fp16 storage cannot hold more than 65504; beyond ~1e4 per world unit every voxel is opaque
  // anyway, so the bound is lowered rather than letting stores saturate.
  return p == Precision::FP16 ? std::min(m, 1e4f) : m;
}

std::unique_ptr<ExtinctionOptimizer::Level> ExtinctionOptimizer::newLevel(
    const OptimizationInputs& in, int index, int levels, const std::string& suffix) {
  const GridSpec& fine = in.volume->grid();
  const int factor = 1 << (levels - 1 - index);
  auto next = std::make_unique<Level>();
  next->index = index;
  next->finest = index == levels - 1;
  next->grid = levelGrid(fine, factor);
  next->shrink = factor;
  const GridSpec grid = next->grid;
  const auto name = [&](const char* what) { return what + ledgerSuffix_ + suffix; };
  next->mu.emplace(name("extinction"), grid, precision_, ledger_);
  const GridMap fineMap(fine);
  if (!next->finest) {
    // Coarse mu_bar and g: averages of the fine fields over each coarse voxel (3^3 samples).
    next->base.emplace(name("extinction-base (coarse)"), grid, precision_, ledger_);
    next->importance.emplace(name("importance (coarse)"), grid, precision_, ledger_);
    restrictBaseAndImportance(in.volume->normalized, *in.transfer, *in.importance, fineMap,
                              *next->base, *next->importance);
  }
  // Context surfaces: phi0 restricted onto coarse levels (the finest uses the inputs'). Held
  // surfaces (the baselines' optimisation) take no step and occlude nothing: ghat is all they
  // need, so they get no phi, coarse phi0, scratch or mask (model only what the scene requires).
  for (size_t si = 0; !in.surfacesHeld && si < in.surfaceBases.size(); ++si) {
    if (!next->finest) {
      next->phi0.emplace_back(name("surface-base (coarse)"), grid, precision_, ledger_);
      restrictSdf(*in.surfaceBases[si], fineMap, next->phi0.back());
      // The min-restriction is not a distance field; redistance it once here so that the
      // level's own redistancing does not move its surface (which the next level would inherit
      // as a deviation).
      Field3D scratch("surface-scratch", grid, precision_, nullptr);
      redistance(next->phi0.back(), in.levelSet, scratch);
    }
    next->phi.emplace_back(name("surface"), grid, precision_, ledger_);
  }
  next->bands.resize(next->phi.size());
  if (!in.surfaceBases.empty()) {
    next->ghat.emplace(name("importance-behind"), grid, precision_, ledger_);
    if (!in.surfacesHeld) next->scratch.emplace(name("surface-scratch"), grid, precision_, ledger_);
    if (in.worldMask && !next->finest && !in.surfacesHeld) {
      next->mask.emplace(grid.dims, name("world-mask (coarse)"), ledger_);
      resampleMask(*in.worldMask, fineMap, *next->mask, grid);
    }
  }
  return next;
}

void ExtinctionOptimizer::buildLevel(const OptimizationInputs& in, const ExtinctionSettings& s,
                                     int index, int levels) {
  follower_.reset();  // restricted from a state this replaces
  std::unique_ptr<Level> next = newLevel(in, index, levels);
  const GridSpec grid = next->grid;
  FieldView mu(*next->mu);
  const GridMap map(grid);
  if (level_ && level_->mu) {
    // Prolong the previous level's mu (trilinear).
    FieldView coarse(*level_->mu);
    const GridMap coarseMap(level_->grid);
    exec::parallelFor("multigrid prolong", int64_t(grid.voxelCount()), [=] VISOPT_HD(int64_t v) {
      const auto [i, j, k] = map.ijk(v);
      glm::vec3 x = map.toWorld(glm::vec3(float(i), float(j), float(k)));
      mu.store(size_t(v), coarse.sample(coarseMap.toIndex(x)));
    });
  } else {
    // Start from mu_bar.
    BaseExtinction base;
    if (next->base) base.field = FieldView(*next->base);
    base.scalars = FieldView(in.volume->normalized);
    base.transfer = lookupOf(in.transfer);
    exec::parallelFor("extinction init", int64_t(grid.voxelCount()),
                      [=] VISOPT_HD(int64_t v) { mu.store(size_t(v), base.at(size_t(v))); });
  }
  // phi prolonged from the previous level (its deviation from its base), or phi0 at the first.
  const GridMap fineMap(in.volume->grid());
  for (size_t si = 0; si < next->phi.size(); ++si) {
    const Field3D& base = next->finest ? *in.surfaceBases[si] : next->phi0[si];
    if (level_ && si < level_->phi.size() && si < level_->phi0.size())
      prolongDeviation(level_->phi[si], level_->phi0[si], GridMap(level_->grid), base,
                       next->phi[si]);
    else if (level_ && si < level_->phi.size())
      resample(level_->phi[si], GridMap(level_->grid), next->phi[si]);
    else
      resample(base, next->finest ? fineMap : map, next->phi[si]);
  }
  level_.reset();
  level_ = std::move(next);
  (void)s;
}

std::optional<IterationStats> ExtinctionOptimizer::runIteration(Level& L,
                                                                const OptimizationInputs& in,
                                                                const ExtinctionSettings& s,
                                                                int cap) {
  cutShort_ = false;
  if (abandonRequested()) return std::nullopt;
  const int shrink = L.shrink;
  const Bounds bounds = in.volume->grid().worldBounds();
  const float muMax = levelMuMax(in, s, precision_);

  // Frustum grids for this level and the current camera and light.
  const int w = std::max(4, int(float(in.imageWidth) * s.frustumScale) / shrink);
  const int h = std::max(4, int(float(in.imageHeight) * s.frustumScale) / shrink);
  L.view = FrustumGrid::forCamera(in.camera, w, h, bounds,
                                  s.depthCells > 0 ? std::max(2, s.depthCells / shrink) : 0,
                                  L.grid.minSpacing());
  // Light grids for the light term, and for the light half of ghat (Eq. 19) whenever there are
  // context surfaces: a closed surface that gave way only towards the camera leaves what it
  // revealed in its own shadow (T_L = 0 inside it), so it must give way towards the light too.
  const bool lightGrids = s.r != 0.f || !in.surfaceBases.empty();
  if (lightGrids) {
    const int n = std::max(4, s.lightGridSize / shrink);
    L.light = FrustumGrid::forLight(in.light, bounds, glm::ivec3(n, n, 0), L.grid.minSpacing());
  } else {
    L.dLight.reset();  // model only what the scene needs
  }

  ExtinctionProblem p;
  p.grid = L.grid;
  p.mu = &*L.mu;
  p.importance = L.finest ? in.importance : &*L.importance;
  p.baseField = L.base ? &*L.base : nullptr;
  p.scalars = &in.volume->normalized;
  p.transfer = in.transfer;
  p.rho = s.rho < 0.f ? 1.f / muMax : s.rho;
  p.q = s.q;
  p.r = s.r;
  p.view = L.view;
  p.light = L.light;

  IterationStats st;
  st.level = L.index;
  const bool hasSurfaces = !in.surfaceBases.empty();
  const ImportanceBehindInputs ghatInputs{L.view, L.light, in.importanceRevision};
  const bool ghatKept = L.ghatFor && *L.ghatFor == ghatInputs;
  const bool ghatNeeded = hasSurfaces && !ghatKept;
  if (ghatKept) {  // model only what the scene needs: the maxima are in ghat now
    L.viewMax.reset();
    L.lightMax.reset();
  }
  SurfaceSet surfaces;  // held surfaces occlude nothing in the scans
  for (size_t si = 0; si < L.phi.size() && si < size_t(kMaxContextSurfaces); ++si)
    surfaces.phi[surfaces.count++] = FieldView(L.phi[si]);
  const ScreenWeights weights = screenWeightsOf(in);
  auto t0 = Clock::now();
  const bool viewScan = p.q != 0.f || hasSurfaces;
  if (viewScan || lightGrids)
    buildScanSkipGrid(*p.mu, *p.importance, surfaces, L.scanSkip, ledger_);
  ScanSums view, light;
  if (viewScan)
    view = scanGrid("grid updates: view", p.view, p.grid, *p.mu, *p.importance, L.dView,
                    "view-derivative", precision_, ledger_, surfaces, weights,
                    ghatNeeded ? &L.viewMax : nullptr, "view-importance-behind", L.scanSkip.grid);
  else
    L.dView.reset();
  if (abandonRequested()) return std::nullopt;  // nothing but scratch has changed yet
  if (lightGrids)
    light =
        scanGrid("grid updates: light", p.light, p.grid, *p.mu, *p.importance, L.dLight,
                 "light-derivative", precision_, ledger_, surfaces, ScreenWeights{},
                 ghatNeeded ? &L.lightMax : nullptr, "light-importance-behind", L.scanSkip.grid);
  else
    L.lightMax.reset();
  st.gridUpdatesMs = msSince(t0);
  // The last point where the iteration can still be abandoned: nothing but scratch (the frustum
  // fields) has changed yet.
  if (abandonRequested()) return std::nullopt;

  // Optimiser state, allocated on the first step of a level.
  const bool ademamix = s.optimizer == OptimizerKind::AdEMAMix;
  if (!L.m1) {
    L.m1.emplace("optimizer-m1", L.grid, precision_, ledger_);
    L.rms.emplace("optimizer-rms", L.grid, precision_, ledger_);
    L.m1->fill(0.f);
    L.rms->fill(0.f);
    if (ademamix) {
      L.m2.emplace("optimizer-m2", L.grid, precision_, ledger_);
      L.m2->fill(0.f);
    }
  }
  L.t += 1;
  const int t = L.t;
  OptimizerCoefficients c;
  c.ademamix = ademamix && L.m2.has_value();
  c.lr = s.learningRate * muMax;
  c.beta1 = s.beta1;
  c.beta2 = s.beta2;
  c.epsilon = s.epsilon;
  c.biasCorrection1 = 1.f - std::pow(s.beta1, float(t));
  c.biasCorrection2 = std::sqrt(1.f - std::pow(s.beta2, float(t)));
  const int tAlpha = s.alphaWarmup > 0 ? s.alphaWarmup : cap;
  const int tBeta3 = s.beta3Warmup > 0 ? s.beta3Warmup : cap;
  c.alpha = s.alpha * std::min(1.f, float(t) / float(std::max(tAlpha, 1)));
  if (t < tBeta3) {
    // Linear interpolation in half-life space from beta1 to beta3 (docs/methods.md §2).
    auto halfLife = [](float b) { return std::log(0.5f) / std::log(b) - 1.f; };
    const float f = float(t) / float(tBeta3);
    const float hl = (1.f - f) * halfLife(s.beta1) + f * halfLife(s.beta3);
    c.beta3 = std::pow(0.5f, 1.f / (hl + 1.f));
  } else {
    c.beta3 = s.beta3;
  }

  auto t1 = Clock::now();
  ExtinctionStep step;
  step.gradient = gradientOf(p, L.dView ? &*L.dView : nullptr, L.dLight ? &*L.dLight : nullptr);
  step.state.m1 = FieldView(*L.m1);
  step.state.rms = FieldView(*L.rms);
  if (L.m2) step.state.m2 = FieldView(*L.m2);
  step.coefficients = c;
  step.muMax = muMax;
  step.voxelVolume = voxelVolume(L.grid);
  if (t == 1) {
    const ExtinctionGradient grad = step.gradient;
    const double sum2 = exec::reduce(
        "extinction step: gradient scale", int64_t(L.grid.voxelCount()), 0.0,
        [=] VISOPT_HD(int64_t v) {
          float mbar;
          const double g = grad.at(v, mbar);
          return g * g;
        },
        [] VISOPT_HD(double a, double b) { return a + b; });
    const double rms = std::sqrt(sum2 / double(L.grid.voxelCount()));
    L.gradientScale = rms > 1e-30 && std::isfinite(rms) ? float(1.0 / rms) : 1.f;
  }
  step.gradientScale = L.gradientScale;
  // The CPU runs rows of voxels in SIMD lanes (host/extinction_step_rows.h), CUDA one voxel
  // per thread; the tests hold the two to each other.
  StepSums sums =
      activeBackend() == Backend::CPU
          ? extinctionStepOnHost("extinction step", step)
          : exec::reduce("extinction step", int64_t(L.grid.voxelCount()), StepSums{}, step,
                         [] VISOPT_HD(const StepSums& a, const StepSums& b) { return a + b; });
  st.extinctionStepMs = msSince(t1);

  st.iteration = t;
  st.energyRho = sums.energyRho;
  st.energyQ = -double(p.q) * view.gMuT;
  st.energyR = -double(p.r) * light.gMuT;
  st.visibilityView = view.gMu > 0 ? view.gMuT / view.gMu : 0.0;
  st.visibilityViewOccluders = view.visibilityThroughOccluders();
  st.visibilityLight = light.gMu > 0 ? light.gMuT / light.gMu : 0.0;
  st.stepNorm = std::sqrt(sums.step2 / double(L.grid.voxelCount()));
  if (hasSurfaces) {
    L.substeps = levelSetSubsteps(in, s, L.grid, cap);
    surfaceStep(in, L, ghatKept, st);
    L.ghatFor = ghatInputs;  // ghat now holds what these inputs give
  }
  return st;
}

namespace {

// One bit per voxel: phi < 0.
void recordInside(const Field3D& phi, DeviceBuffer<uint64_t>& bits) {
  const size_t n = phi.size(), words = (n + 63) / 64;
  if (bits.size() != words) bits = DeviceBuffer<uint64_t>(words);
  const FieldView f(phi);
  uint64_t* out = bits.data();
  exec::parallelFor("level set: record sides", int64_t(words), [=] VISOPT_HD(int64_t w) {
    uint64_t word = 0;
    const size_t first = size_t(w) * 64;
    for (size_t b = 0; b < 64 && first + b < n; ++b)
      if (f.load(first + b) < 0.f) word |= uint64_t(1) << b;
    out[w] = word;
  });
}

// Voxels whose side of the surface differs from the recorded one.
int64_t crossedSince(const Field3D& phi, const DeviceBuffer<uint64_t>& bits) {
  const size_t n = phi.size();
  const FieldView f(phi);
  const uint64_t* in = bits.data();
  return exec::reduce(
      "level set: crossed voxels", int64_t(bits.size()), int64_t(0),
      [=] VISOPT_HD(int64_t w) {
        int64_t crossed = 0;
        const size_t first = size_t(w) * 64;
        for (size_t b = 0; b < 64 && first + b < n; ++b)
          crossed += ((in[w] >> b) & 1) != (f.load(first + b) < 0.f ? 1u : 0u);
        return crossed;
      },
      [] VISOPT_HD(int64_t a, int64_t b) { return a + b; });
}

}  // namespace

void ExtinctionOptimizer::surfaceStep(const OptimizationInputs& in, Level& L, bool ghatKept,
                                      IterationStats& st) {
  // ghat (Eq. 19): half the max importance behind x along the view ray, half along the light
  // ray (the light grids exist whenever there are surfaces).
  auto t0 = Clock::now();
  ImportanceBehind behind;
  behind.volume = GridMap(L.grid);
  behind.ghat = FieldView(*L.ghat);
  behind.view = FrustumMap(L.view);
  behind.light = FrustumMap(L.light);
  if (L.viewMax) behind.viewMax = FrustumFieldView(*L.viewMax, L.view.dims);
  if (L.lightMax) behind.lightMax = FrustumFieldView(*L.lightMax, L.light.dims);
  behind.weights = screenWeightsOf(in);
  if (!ghatKept) {
    if (activeBackend() == Backend::CPU) {
      importanceBehindOnHost("grid updates: importance behind", behind);
    } else {
      const BrickOrder order(behind.volume.dims);
      exec::parallelFor("grid updates: importance behind", order.launches(),
                        [=] VISOPT_HD(int64_t n) {
                          int i, j, k;
                          if (order.voxel(n, i, j, k)) behind(i, j, k);
                        });
    }
  }
  if (in.surfacesHeld) {  // ghat only: the surfaces stay at phi0
    st.sdfStepMs = msSince(t0);
    return;
  }
  const DeviceBitMask* mask = L.finest ? in.worldMask : (L.mask ? &*L.mask : nullptr);
  // The bricks of each band that this ghat leaves as they are (narrow_band.h), once per ghat.
  for (size_t si = 0; si < L.phi.size(); ++si)
    if (!ghatKept || !L.bands[si].fixedFor(*L.ghat))
      markFixedBricks(L.phi[si], L.finest ? *in.surfaceBases[si] : L.phi0[si], *L.ghat, in.levelSet,
                      L.bands[si]);
  st.sdfStepMs = msSince(t0);
  // The level-set substeps run in chunks; redistancing (Eq. 18) runs once the steps since the
  // last one may have moved phi by half a voxel somewhere, so |grad phi| stays near 1 while a
  // surface travels several voxels in one iteration. Each redistancing moves the zero level set
  // by a small O(h) amount of its own (the subcell estimate next to the interface); run after
  // every tiny step it would undo slow surface motion, which is what happened with a thin shell
  // whose medial kink lies a voxel from the surface.
  L.insideAtStart.resize(L.phi.size());
  for (size_t si = 0; si < L.phi.size(); ++si) recordInside(L.phi[si], L.insideAtStart[si]);
  const double h = double(L.grid.minSpacing());
  LevelSetSettings chunkSettings = in.levelSet;
  // A chunk is as many substeps as keep the surface's motion under half a voxel at the rate of
  // the last chunk (at least `substeps`, at most 64 explicit ones), and redistancing runs once the
  // motion bound since the last reaches a voxel (two chunks of a fast surface), rather than after
  // every few substeps of a slow one. (At half a voxel, the Cranium CT's skin ran redistancing
  // 6.4 s of a 34.7 s optimisation; at one voxel 3.1 s of 28.8 s with the same V_occ, 0.990, and
  // a final image 37.5 dB from the other.)
  int chunk = std::max(in.levelSet.substeps, 1);
  if (in.levelSet.semiImplicit && L.semiImplicitChunk > 0) chunk = L.semiImplicitChunk;
  LevelSetStepStats ls;
  L.lastMotion = 0.0;
  int substepsDone = 0;
  for (int done = 0; done < std::max(L.substeps, 1); done += chunkSettings.substeps) {
    if (abandonRequested()) {  // cut short: phi after fewer substeps is a consistent state
      cutShort_ = true;
      break;
    }
    chunkSettings.substeps = std::min(chunk, std::max(L.substeps, 1) - done);
    substepsDone += chunkSettings.substeps;
    auto ts = Clock::now();
    double motion = 0.0, insideRise = 0.0, rate = 0.0;
    bool anySurface = false;
    for (size_t si = 0; si < L.phi.size(); ++si) {
      const Field3D& phi0 = L.finest ? *in.surfaceBases[si] : L.phi0[si];
      ls = levelSetStep(L.phi[si], phi0, *L.ghat, mask, chunkSettings, *L.scratch, &L.bands[si]);
      const double n = double(std::max(ls.substeps, 1));
      motion = std::max(motion, ls.nearMaxChange * n);
      insideRise = std::max(insideRise, ls.insideRise * n);
      rate = std::max(rate, ls.nearMaxChange);
      anySurface = anySurface || ls.hasInterface;
    }
    L.motionSinceRedistance += motion;
    L.insideRiseSinceRedistance += insideRise;
    L.lastMotion += motion;
    st.sdfStepMs += msSince(ts);
    auto t1 = Clock::now();
    // Also once a kink of the inside (the medial axis, where the clamped curvature raises phi
    // by up to ghat / dx) may have risen by kNearSurfaceBand voxels: one that lay beyond the
    // near band must not reach zero, which would start a spurious surface away from the real
    // one. Only the inside's rise counts: far from the surface phi elsewhere relaxes towards a
    // phi0 of its own sign or moves away from zero. (The whole field's largest change counted
    // before; near the fixed point of Eq. 23, which is no distance function, the return term
    // pulls voxels a voxel or so outside an opened surface back towards phi0 by ~0.2 voxel per
    // substep while redistancing pushes them out again, which ran redistancing every ten
    // substeps without any surface moving.)
    if (L.motionSinceRedistance >= 1.0 * h ||
        L.insideRiseSinceRedistance >= double(kNearSurfaceBand) * h) {
      for (size_t si = 0; si < L.phi.size(); ++si) {
        const Field3D& phi0 = L.finest ? *in.surfaceBases[si] : L.phi0[si];
        RedistanceStats rs = redistance(L.phi[si], in.levelSet, *L.scratch, &phi0,
                                        kRedistanceStopBandVoxels, &L.bands[si]);
        st.redistanceIterations = std::max(st.redistanceIterations, rs.iterations);
        ++st.redistanceCalls;
        st.redistancePasses += rs.iterations;
        st.redistanceResidual = std::max(st.redistanceResidual, rs.meanSquaredChange);
      }
      L.motionSinceRedistance = 0.0;
      L.insideRiseSinceRedistance = 0.0;
    }
    st.redistanceMs += msSince(t1);
    // Every surface has vanished (ghat >= lambda all over it): there is nothing left to move,
    // and more substeps would only raise phi without bound where no redistancing can reach
    // (there is no interface to measure distance from). The next iteration tries again, so a
    // surface that the return term brings back carries on.
    if (!anySurface) break;
    // Explicit substeps are stable only one by one, so a chunk is bounded by how often the
    // motion is checked; a semi-implicit chunk is one step of any length, bounded by accuracy
    // alone (the half voxel).
    const double most = in.levelSet.semiImplicit ? 4096.0 : 64.0;
    const double fits = rate > 0.0 ? 0.5 * h / rate : most;
    chunk = int(std::clamp(std::floor(fits), double(std::max(in.levelSet.substeps, 1)), most));
    if (in.levelSet.semiImplicit) L.semiImplicitChunk = chunk;
  }
  for (const NarrowBand& b : L.bands) {
    st.bandVoxels += b.band().voxels;
    st.bandWorkVoxels += b.work().voxels;
  }
  st.levelSetTimeStep = ls.timeStep;
  st.levelSetSubsteps = substepsDone;
  st.levelSetMotionVoxels = L.lastMotion / h;
  for (size_t si = 0; si < L.phi.size(); ++si)
    st.levelSetCrossedVoxels += crossedSince(L.phi[si], L.insideAtStart[si]);

  // Deviation of the current surfaces from their base, over voxels on the current surface.
  const float hf = float(h);
  for (size_t si = 0; si < L.phi.size(); ++si) {
    const FieldView phi(L.phi[si]);
    const FieldView base(L.finest ? *in.surfaceBases[si] : L.phi0[si]);
    const DeviationSums d = exec::reduce(
        "surface deviation", int64_t(L.grid.voxelCount()), DeviationSums{},
        [=] VISOPT_HD(int64_t v) {
          DeviationSums r;
          if (fabsf(phi.load(size_t(v))) <= 0.5f * hf) {
            // phi0 - phi at a voxel next to the current surface is phi0 at (about) the
            // nearest surface point: how far the surface has moved from its base there.
            const double dev = fabsf(base.load(size_t(v)) - phi.load(size_t(v))) / hf;
            r.sum = dev;
            r.max = dev;
            r.count = 1;
          }
          return r;
        },
        [] VISOPT_HD(const DeviationSums& a, const DeviationSums& b) {
          return DeviationSums{a.sum + b.sum, a.max > b.max ? a.max : b.max, a.count + b.count};
        });
    st.maxDeviationVoxels = std::max(st.maxDeviationVoxels, d.max);
    if (d.count > 0) st.meanDeviationVoxels = std::max(st.meanDeviationVoxels, d.sum / d.count);
  }
}

namespace {
void validate(const OptimizationInputs& in, const ExtinctionSettings& s) {
  if (!in.volume || !in.importance || !in.transfer)
    throw Error(ErrorKind::Usage,
                "optimisation needs a volume, an importance and a transfer function");
  auto finite = [](float v) { return std::isfinite(v); };
  if (!finite(s.q) || !finite(s.r) || !finite(s.rho) || s.q < 0.f || s.r < 0.f)
    throw Error(ErrorKind::Usage, "q and r must be finite and non-negative, rho finite");
  if (!finite(s.muMax) || s.muMax < 0.f) throw Error(ErrorKind::Usage, "mu_max must be >= 0");
  if (!(s.learningRate > 0.f) || !finite(s.learningRate))
    throw Error(ErrorKind::Usage, "the learning rate must be positive");
  if (s.levels < 1 || s.levels > 8) throw Error(ErrorKind::Usage, "levels must be 1..8");
  if (s.maxIterationsPerLevel < 1) throw Error(ErrorKind::Usage, "iterations must be >= 1");
  if (!(s.frustumScale > 0.f) || s.frustumScale > 4.f)
    throw Error(ErrorKind::Usage, "frustum scale must be in (0, 4]");
  if (in.importance->grid().dims != in.volume->grid().dims)
    throw Error(ErrorKind::Usage, "importance and volume grids differ");
  auto require = [](bool ok, const char* message) {
    if (!ok) throw Error(ErrorKind::Usage, message);
  };
  // Every number reaches the kernels: a NaN or an infinity must stop here, not as NaN fields.
  require(finite(s.tolerance) && s.tolerance >= 0.f, "the energy tolerance must be finite, >= 0");
  require(s.beta1 >= 0.f && s.beta1 < 1.f && s.beta2 >= 0.f && s.beta2 < 1.f && s.beta3 >= 0.f &&
              s.beta3 < 1.f,
          "the optimiser's betas must lie in [0, 1)");
  require(finite(s.alpha) && s.alpha >= 0.f, "AdEMAMix's alpha must be finite, >= 0");
  require(finite(s.epsilon) && s.epsilon > 0.f, "the optimiser's epsilon must be finite, > 0");
  require(s.maxIterationsPerLevel <= 1000000, "iterations must be at most 1000000 per level");
  require(s.depthCells >= 0 && s.depthCells <= 8192, "depth cells must be 0 (automatic)..8192");
  require(s.lightGridSize >= 4 && s.lightGridSize <= 8192, "the light grid must be 4..8192 rays");
  const ImportanceLens& lens = in.lens;
  require(finite(lens.x) && finite(lens.y) && finite(lens.radius) && lens.radius >= 0.f &&
              finite(lens.strength) && lens.strength >= 0.f && lens.strength <= 1e3f,
          "the lens needs a finite centre, a radius >= 0 and a strength of 0..1000");
  checkLevelSetSettings(in.levelSet);
}
}  // namespace

void checkLevelSetSettings(const LevelSetSettings& ls) {
  auto finite = [](float v) { return std::isfinite(v); };
  auto require = [](bool ok, const char* message) {
    if (!ok) throw Error(ErrorKind::Usage, message);
  };
  require(finite(ls.lambda) && ls.lambda >= 0.f, "lambda must be finite, >= 0");
  require(finite(ls.curvatureEpsilon) && ls.curvatureEpsilon > 0.f,
          "the curvature epsilon must be finite, > 0");
  require(ls.cfl > 0.f && ls.cfl <= 1.f, "the level-set CFL number must lie in (0, 1]");
  require(ls.substeps >= 0 && ls.substeps <= 4096, "level-set substeps must be 0..4096");
  require(finite(ls.reach) && ls.reach >= 0.f && ls.reach <= 100.f,
          "the level-set reach must be 0..100 bounding radii");
  require(ls.redistanceIterations >= 0 && ls.redistanceIterations <= 100000,
          "redistancing iterations must be 0..100000");
  require(finite(ls.redistanceTolerance) && ls.redistanceTolerance >= 0.f,
          "the redistancing tolerance must be finite, >= 0");
  require(ls.spatialOrder == 1 || ls.spatialOrder == 2, "the spatial order must be 1 or 2");
  require(finite(ls.band) && ls.band >= 0.f && ls.band <= 1e4f,
          "the narrow band must be 0 (dense)..10000 voxels");
}

std::vector<IterationStats> ExtinctionOptimizer::runMultigrid(const OptimizationInputs& in,
                                                              const ExtinctionSettings& s,
                                                              const IterationCallback& callback,
                                                              const AbandonCheck& abandon) {
  validate(in, s);
  abandon_ = &abandon;
  struct Clear {
    const AbandonCheck*& p;
    ~Clear() { p = nullptr; }
  } clear{abandon_};
  level_.reset();
  std::vector<IterationStats> all;
  for (int l = 0; l < s.levels; ++l) {
    buildLevel(in, s, l, s.levels);
    const size_t levelStart = all.size();
    for (int it = 0; it < s.maxIterationsPerLevel; ++it) {
      const std::optional<IterationStats> done =
          runIteration(*level_, in, s, s.maxIterationsPerLevel);
      if (!done) return all;
      all.push_back(*done);
      if (callback && !callback(*done)) return all;
      if (cutShort_) return all;
      // optimize/level_end.h: converged, or circling without progress.
      if (levelSettled(std::span(all).subspan(levelStart), s)) break;
    }
  }
  return all;
}

std::vector<IterationStats> ExtinctionOptimizer::iterate(const OptimizationInputs& in,
                                                         const ExtinctionSettings& s,
                                                         int iterations,
                                                         const IterationCallback& callback,
                                                         const AbandonCheck& abandon) {
  validate(in, s);
  abandon_ = &abandon;
  struct Clear {
    const AbandonCheck*& p;
    ~Clear() { p = nullptr; }
  } clear{abandon_};
  if (!level_ || !level_->finest || level_->grid.dims != in.volume->grid().dims)
    buildLevel(in, s, 0, 1);  // start at the finest grid from mu_bar
  std::vector<IterationStats> all;
  for (int it = 0; it < iterations; ++it) {
    std::optional<IterationStats> st =
        runIteration(*level_, in, s, std::max(iterations, s.maxIterationsPerLevel));
    if (!st) break;
    st->level = level_->index;
    all.push_back(*st);
    if (callback && !callback(*st)) break;
    if (cutShort_) break;
  }
  // The finest state moved on: a later follow() restricts it anew rather than correcting it with
  // a coarse level that describes an older one.
  if (!all.empty()) follower_.reset();
  return all;
}

}  // namespace visopt
