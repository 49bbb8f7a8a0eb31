// The core scenario of Himmler & Günther 2026 (Fig. 3): an important disc inside a context sphere
// (a thin shell). The surface opens towards the camera, the disc's visibility rises from ~0 to
// high, the surface returns to its base shape when the importance is removed, and a world mask over
// the occluding cap keeps the cap.
//
// Eq. 23 moves the surface inward by curvature only where ghat > 0 (max(0, .) forbids outward
// motion, and grad ghat . grad phi vanishes on a cap facing the camera): a cap dented inside
// the cone of rays towards the important structure flattens and then stops, so it digs about
// r_cone^2 / (2 R) deep. The disc is therefore wide (radius 9 in a shell of radius 12, shell
// 1.5 thick), as in the paper's figures where the important structures are large.
#include <cmath>

#include <functional>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "occluder_scene.h"
#include "visopt/engine.h"
#include "visopt/exec.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

constexpr int kN = 40;
constexpr float kSphereRadius = 12.f, kShell = 0.75f;

// Calls of the ghat gather (Eq. 19) so far in this process.
long long importanceBehindGathers() {
  for (const StageTiming& t : stageTimings())
    if (t.name == "grid updates: importance behind") return t.calls;
  return 0;
}

// A volume with only a thin disc (value 0.5, radius 9) facing the camera at the centre.
Volume blobVolume(Precision p) {
  OccluderScene s;
  s.n = kN;
  s.slabY0 = 1e9f;  // no slab
  s.slabY1 = -1e9f;
  s.blobCentre = glm::vec3(0.5f, 0.5f, 0.5f);
  s.blobRadius = 9.f;
  s.blobHalfThickness = 0.4f;
  return makeOccluderVolume(s, p);
}

// Thin-shell sphere SDF (Eq. 26) on the volume grid.
Field3D shellSphere(const GridSpec& g) {
  return shellSphereSdf(g, kSphereRadius, kShell);
}

void setup(Engine& e) {
  e.setVolume(blobVolume(e.precision()));
  e.setTransferFunction(occluderTransferFunction());
  e.setImportanceCurve(blobImportance());
  e.setCamera(Camera::orbit({0, 0, 0}, 0.f, 0.f, 90.f));  // on -y
  PointLight light;
  light.position = {0.f, -90.f, 0.f};
  e.setLight(light);
  e.setViewportSize(48, 48);
  ContextSurfaceSpec spec;
  spec.source = "test:shell sphere";
  spec.filled = false;
  spec.shell = kShell;
  Field3D phi0 = shellSphere(e.volume().grid());
  e.addContextSurface(spec, phi0);
  ExtinctionSettings s;
  s.levels = 1;
  s.maxIterationsPerLevel = 120;
  s.minIterationsPerLevel = 120;
  s.frustumScale = 1.f;
  e.setExtinctionSettings(s);
}

// phi - phi0 at the front cap (on the camera side of the sphere, on the axis).
float capChange(const Engine& e) {
  const GridSpec& g = e.volume().grid();
  const glm::vec3 idx = g.worldToIndex({0.5f, -kSphereRadius + 0.5f, 0.5f});
  const size_t v = g.linearIndex(int(idx.x), int(idx.y), int(idx.z));
  return e.contextSurfacePhi(0)->get(v) - e.contextSurfaceBase(0)->get(v);
}

}  // namespace

TEST(ContextSurfaces, SurfaceOpensTowardsTheCamera) {
  Engine e;
  setup(e);
  const auto stats = e.optimize();
  ASSERT_FALSE(stats.empty());
  EXPECT_LT(stats.front().visibilityView, 0.05) << "the shell hides the blob at first";
  EXPECT_GT(stats.back().visibilityView, 0.5) << "the blob must become visible";
  EXPECT_GT(capChange(e), kShell) << "the front cap must have left the shell's place";
  EXPECT_GT(stats.back().maxDeviationVoxels, 0.5) << "the rim of the hole has moved";
}

TEST(ContextSurfaces, SurfaceReturnsToItsBaseWhenTheImportanceIsRemoved) {
  Engine e;
  setup(e);
  e.optimize();
  ASSERT_GT(capChange(e), kShell);
  // Remove the importance: ghat is 0 everywhere and the return term lambda (phi0 - phi) pulls
  // the surface back (the optimisation continues from the opened state).
  e.setImportanceCurve({{0.0, 0.0}, {1.0, 0.0}});
  e.continueOptimization(200);
  EXPECT_LT(std::abs(capChange(e)), 0.3f) << "the cap must return to its base shape";
}

TEST(ContextSurfaces, WorldMaskKeepsTheCap) {
  Engine e;
  setup(e);
  // Mask every voxel on the camera side of the sphere (y < -6).
  Field3D mask("mask", e.volume().grid(), Precision::FP32);
  const GridSpec& g = e.volume().grid();
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i)
        mask.set(g.linearIndex(i, j, k),
                 g.indexToWorld(glm::vec3(float(i), float(j), float(k))).y < -6.f ? 1.f : 0.f);
  e.setWorldMask(std::move(mask));
  const auto stats = e.optimize();
  EXPECT_LT(std::abs(capChange(e)), 0.3f) << "deviation ~0 under the mask";
  EXPECT_LT(stats.back().visibilityView, 0.05) << "the cap stays, so the blob stays hidden";
}

// A lens of strength 0 over the disc (Himmler & Günther 2026, §III-F) removes the importance along
// exactly those rays: the shell keeps its cap and the disc stays hidden; the same lens elsewhere on
// the screen changes nothing. A screen-space windowing mask of zeros over the disc does the same.
TEST(ContextSurfaces, LensAndScreenMaskModulateTheImportanceAlongTheirRays) {
  auto run = [](auto configure) {
    Engine e;
    setup(e);
    configure(e);
    const auto stats = e.optimize();
    return std::make_pair(stats.back().visibilityView, capChange(e));
  };
  ImportanceLens over;  // the disc is at the image centre, about a third of the width across
  over.x = 0.5f;
  over.y = 0.5f;
  over.radius = 0.3f;
  over.strength = 0.f;
  const auto blocked = run([&](Engine& e) { e.setLens(over); });
  EXPECT_LT(blocked.first, 0.05) << "no importance under the lens: nothing opens";
  EXPECT_LT(std::abs(blocked.second), 0.3f);

  ImportanceLens aside = over;
  aside.x = 0.08f;
  aside.radius = 0.05f;
  const auto open = run([&](Engine& e) { e.setLens(aside); });
  EXPECT_GT(open.first, 0.5) << "a lens elsewhere leaves the disc's rays alone";

  const auto masked = run([](Engine& e) {
    std::vector<float> w(32 * 32, 1.f);
    for (int y = 8; y < 24; ++y)
      for (int x = 8; x < 24; ++x) w[size_t(y) * 32 + size_t(x)] = 0.f;
    e.setScreenMask(w, 32, 32);
  });
  EXPECT_LT(masked.first, 0.05) << "a zero window over the disc keeps it hidden";
}

// ghat (Eq. 19) depends on the importance, the frusta and the screen weights only, so a run
// computes it once per level (ExtinctionOptimizer::Level::ghatFor). The premise, checked on
// a path that recomputes it every iteration (setting the same lens again counts as a change of
// the screen weights): after 19 more iterations that opened the surface and changed mu, ghat is
// bit for bit what a whole run kept from its first iteration.
TEST(ContextSurfaces, TheImportanceBehindDoesNotChangeAsTheSurfaceOpens) {
  Engine kept;
  setup(kept);
  ExtinctionSettings s = kept.extinctionSettings();
  s.maxIterationsPerLevel = s.minIterationsPerLevel = 20;
  kept.setExtinctionSettings(s);
  kept.optimize();
  Engine recomputed;
  setup(recomputed);
  s.maxIterationsPerLevel = s.minIterationsPerLevel = 1;
  recomputed.setExtinctionSettings(s);
  recomputed.optimize();
  const Field3D* phi = recomputed.contextSurfacePhi(0);
  std::vector<float> phiBefore(phi->size());
  for (size_t v = 0; v < phi->size(); ++v) phiBefore[v] = phi->get(v);
  const long long gathers = importanceBehindGathers();
  for (int i = 0; i < 19; ++i) {
    recomputed.setLens(recomputed.lens());
    recomputed.continueOptimization(1);
  }
  EXPECT_EQ(importanceBehindGathers(), gathers + 19) << "recomputed every iteration";
  size_t moved = 0;
  const float h = recomputed.volume().grid().minSpacing();
  for (size_t v = 0; v < phi->size(); ++v)
    moved += std::abs(phi->get(v) - phiBefore[v]) > 0.1f * h && std::abs(phi->get(v)) < 2.f * h;
  EXPECT_GT(moved, 50u) << "the surface moved meanwhile";
  const Field3D* a = kept.importanceBehind();
  const Field3D* b = recomputed.importanceBehind();
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->size(), b->size());
  double sum = 0.0;
  for (size_t v = 0; v < a->size(); ++v) {
    ASSERT_EQ(a->get(v), b->get(v)) << "voxel " << v;
    sum += a->get(v);
  }
  EXPECT_GT(sum, 0.0);
  // A new camera gives a new ghat at once on the continuing path (the workstation's).
  kept.setCamera(Camera::orbit({0, 0, 0}, 90.f, 0.f, 90.f));
  kept.continueOptimization(1);
  size_t changed = 0;
  for (size_t v = 0; v < b->size(); ++v) changed += kept.importanceBehind()->get(v) != b->get(v);
  EXPECT_GT(changed, b->size() / 100);
}

namespace {

std::vector<float> valuesOf(const Field3D& f) {
  std::vector<float> v(f.size());
  for (size_t i = 0; i < f.size(); ++i) v[i] = f.get(i);
  return v;
}

// Runs `body` on one thread, so that parallel sums (and what depends on them) repeat bit for bit
// from run to run.
template <class F>
void singleThreaded(F body) {
  tbb::task_arena arena(1);
  arena.execute(body);
}

}  // namespace

namespace {

void runOneIteration(Engine& e) {
  ExtinctionSettings s = e.extinctionSettings();
  s.maxIterationsPerLevel = s.minIterationsPerLevel = 1;
  e.setExtinctionSettings(s);
  e.optimize();
}

}  // namespace

// The workstation's path (Engine::continueOptimization, one iteration per call) keeps ghat while
// the camera, the light, the importance and the screen weights stay as they are: the same mu and
// phi, bit for bit, as recomputing it every iteration, without the gather. Each change of its
// inputs gives at once the ghat a fresh engine computes for the changed scene.
TEST(ContextSurfaces, TheContinuingPathKeepsTheImportanceBehindUntilItsInputsChange) {
  singleThreaded([] {
    Engine kept, recomputed;
    for (Engine* e : {&kept, &recomputed}) {
      setup(*e);
      runOneIteration(*e);
    }
    const long long before = importanceBehindGathers();
    for (int i = 0; i < 4; ++i) ASSERT_EQ(kept.continueOptimization(1).size(), 1u);
    EXPECT_EQ(importanceBehindGathers(), before) << "ghat kept: no gather";
    for (int i = 0; i < 4; ++i) {
      recomputed.setLens(recomputed.lens());  // the same weights, counted as a change
      ASSERT_EQ(recomputed.continueOptimization(1).size(), 1u);
    }
    EXPECT_EQ(importanceBehindGathers(), before + 4);
    EXPECT_EQ(valuesOf(*kept.optimizedExtinction()), valuesOf(*recomputed.optimizedExtinction()));
    EXPECT_EQ(valuesOf(*kept.contextSurfacePhi(0)), valuesOf(*recomputed.contextSurfacePhi(0)));
  });

  // Each input of ghat, changed on the continuing engine, against a fresh engine set up with the
  // change (ghat does not depend on mu or phi, so one iteration of it gives the same field).
  const std::vector<std::pair<const char*, std::function<void(Engine&)>>> changes = {
      {"camera",
       [](Engine& e) {
         e.setCamera(Camera::orbit({0, 0, 0}, 40.f, 10.f, 90.f));
       }},
      {"light",
       [](Engine& e) {
         PointLight l = e.light();
         l.position = {60.f, -60.f, 20.f};
         e.setLight(l);
       }},
      {"lens",
       [](Engine& e) {
         ImportanceLens lens;
         lens.x = 0.4f;
         lens.y = 0.5f;
         lens.radius = 0.2f;
         lens.strength = 0.f;
         e.setLens(lens);
       }},
      {"screen mask",
       [](Engine& e) {
         std::vector<float> w(8 * 8, 1.f);
         for (int x = 0; x < 4; ++x)
           for (int y = 0; y < 8; ++y) w[size_t(y * 8 + x)] = 0.f;
         e.setScreenMask(w, 8, 8);
       }},
      {"importance",
       [](Engine& e) {
         e.setImportanceCurve({{0.0, 0.0}, {0.4, 0.0}, {0.5, 0.3}});
       }},
      {"viewport", [](Engine& e) { e.setViewportSize(40, 32); }},
  };
  for (const auto& [what, change] : changes) {
    SCOPED_TRACE(what);
    Engine continuing, fresh;
    setup(continuing);
    runOneIteration(continuing);
    continuing.continueOptimization(2);
    const std::vector<float> ghatBefore = valuesOf(*continuing.importanceBehind());
    change(continuing);
    ASSERT_EQ(continuing.continueOptimization(1).size(), 1u);
    setup(fresh);
    change(fresh);
    runOneIteration(fresh);
    const std::vector<float> ghat = valuesOf(*continuing.importanceBehind());
    EXPECT_NE(ghat, ghatBefore) << "the change matters to ghat";
    EXPECT_EQ(ghat, valuesOf(*fresh.importanceBehind()));
  }
}

// What the workstation does when the camera moves mid-iteration (Engine::continueOptimization's
// `abandon`): an iteration abandoned after its grid updates changes nothing, bit for bit: not
// mu, not phi, and not the optimiser's moments and step count, which the next iteration would
// show (it matches, bit for bit, the next iteration of a twin engine that never had the
// abandoned one).
TEST(ContextSurfaces, AnAbandonedIterationChangesNothing) {
  singleThreaded([] {
    Engine a, twin;
    for (Engine* e : {&a, &twin}) {
      setup(*e);
      ExtinctionSettings s = e->extinctionSettings();
      s.maxIterationsPerLevel = s.minIterationsPerLevel = 4;
      e->setExtinctionSettings(s);
      e->optimize();
    }
    const std::vector<float> mu = valuesOf(*a.optimizedExtinction());
    const std::vector<float> phi = valuesOf(*a.contextSurfacePhi(0));
    int polls = 0;
    // Polled at the iteration's start, after the view scan and after the light scan: abandon
    // at the third poll, the last before the extinction step.
    const auto stats = a.continueOptimization(1, {}, [&] { return ++polls == 3; });
    EXPECT_TRUE(stats.empty());
    EXPECT_EQ(polls, 3);
    EXPECT_EQ(valuesOf(*a.optimizedExtinction()), mu);
    EXPECT_EQ(valuesOf(*a.contextSurfacePhi(0)), phi);

    const auto next = a.continueOptimization(1);
    const auto twinNext = twin.continueOptimization(1);
    ASSERT_EQ(next.size(), 1u);
    ASSERT_EQ(twinNext.size(), 1u);
    EXPECT_NE(valuesOf(*a.optimizedExtinction()), mu) << "the next iteration did change mu";
    EXPECT_EQ(valuesOf(*a.optimizedExtinction()), valuesOf(*twin.optimizedExtinction()));
    EXPECT_EQ(valuesOf(*a.contextSurfacePhi(0)), valuesOf(*twin.contextSurfacePhi(0)));
    EXPECT_EQ(next[0].energy(), twinNext[0].energy());
  });
}

// Asked to stop during the level-set substeps, an iteration ends at the next chunk with fewer
// substeps and is reported; the call returns after it.
TEST(ContextSurfaces, AnIterationAskedToStopDuringTheSurfaceStepEndsEarly) {
  Engine e;
  setup(e);
  ExtinctionSettings s = e.extinctionSettings();
  s.maxIterationsPerLevel = s.minIterationsPerLevel = 2;
  e.setExtinctionSettings(s);
  const auto full = e.optimize();
  ASSERT_FALSE(full.empty());
  int polls = 0;
  // The fourth poll is the first before a chunk of substeps.
  const auto cut = e.continueOptimization(5, {}, [&] { return ++polls >= 4; });
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_LT(cut[0].levelSetSubsteps, full.back().levelSetSubsteps);
  EXPECT_EQ(e.continueOptimization(1).size(), 1u) << "and the optimisation carries on";
}

// A full frame gives way to a newer camera also while it computes the light transmittance T_L
// (Engine::render's `abandon`, polled between bands of light rays). The preview that answers the
// camera draws with the T_L at hand without computing it, and the next full frame computes it
// whole: bit for bit the frame of a twin engine that never gave way.
TEST(ContextSurfaces, AFullFrameGivesWayWhileItComputesTheLightTransmittance) {
  singleThreaded([] {
    RenderSettings full;
    full.width = full.height = 48;
    Engine a, twin;
    for (Engine* e : {&a, &twin}) {
      setup(*e);
      runOneIteration(*e);
      ASSERT_GT(e->render(full).width, 0);
      ASSERT_EQ(e->continueOptimization(1).size(), 1u);  // mu changed: T_L is of an earlier mu
    }
    int polls = 0;
    // The third poll is the one before the third band of light rays: two bands are new.
    const Image gaveWay = a.render(full, nullptr, [&] { return ++polls == 3; });
    EXPECT_EQ(gaveWay.width, 0);
    EXPECT_EQ(polls, 3);
    RenderSettings preview = full;
    preview.preview = true;
    preview.previewFactor = 2;
    RenderStats stats;
    EXPECT_EQ(a.render(preview, &stats).width, 48);
    EXPECT_EQ(stats.lightMilliseconds, 0.0) << "the preview used the T_L at hand";
    const Image mine = a.render(full, &stats);
    EXPECT_GT(stats.lightMilliseconds, 0.0) << "the full frame computed T_L again";
    EXPECT_EQ(mine.pixels, twin.render(full).pixels);
  });
}
