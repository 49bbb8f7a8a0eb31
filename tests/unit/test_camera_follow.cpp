// Following a moving camera on the coarsest multigrid level (Engine::followCamera,
// ExtinctionOptimizer::follow; Himmler & Günther 2026, §III-F): the transfer operators against
// analytic fields, and the scenario the workstation meets — a surface optimised for one view, the
// camera turned to the other side, where the coarse iterations must open the surface for the new
// view before the finest level gets to run.
#include <cmath>

#include <algorithm>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "occluder_scene.h"
#include "optimize/multigrid_transfer.h"
#include "visopt/engine.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

GridSpec cube(int n, float spacing) {
  GridSpec g;
  g.dims = glm::ivec3(n);
  g.spacing = glm::vec3(spacing);
  g.origin = glm::vec3(-0.5f * float(n - 1) * spacing);
  return g;
}

float linear(glm::vec3 x) {
  return 0.3f * x.x - 0.2f * x.y + 0.1f * x.z + 1.5f;
}

Field3D linearField(const GridSpec& g, float (*f)(glm::vec3)) {
  Field3D out("linear", g, Precision::FP32);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i)
        out.set(g.linearIndex(i, j, k), f(g.indexToWorld(glm::vec3(float(i), float(j), float(k)))));
  return out;
}

std::vector<float> valuesOf(const Field3D& f) {
  std::vector<float> v(f.size());
  for (size_t i = 0; i < f.size(); ++i) v[i] = f.get(i);
  return v;
}

}  // namespace

// The fast coarse-grid correction (rows, per-axis weights, unchanged rows skipped) against the
// reference (per voxel, world positions sampled twice): random changes confined to a slab of the
// coarse grid, odd grid sizes (levelGrid's rounding), fp32 and fp16 targets, with clamping.
TEST(MultigridTransfer, TheFastCorrectionMatchesTheReference) {
  for (Precision precision : {Precision::FP32, Precision::FP16})
    for (const glm::ivec3 dims : {glm::ivec3(37, 29, 41), glm::ivec3(64, 64, 64)}) {
      GridSpec fine;
      fine.dims = dims;
      fine.spacing = glm::vec3(0.8f, 1.1f, 0.9f);
      fine.origin = glm::vec3(-3.f, 2.f, 5.f);
      const GridSpec coarse = levelGrid(fine, 4);
      Field3D before("before", coarse, Precision::FP32), now("now", coarse, Precision::FP32);
      uint32_t seed = 12345u;
      auto next = [&] {
        seed = seed * 1664525u + 1013904223u;
        return float(seed >> 8) / float(1u << 24);
      };
      for (int k = 0; k < coarse.dims.z; ++k)
        for (int j = 0; j < coarse.dims.y; ++j)
          for (int i = 0; i < coarse.dims.x; ++i) {
            const size_t c = coarse.linearIndex(i, j, k);
            const float b = next();
            before.set(c, b);
            // Changes only in a slab of coarse rows, so that whole fine rows are skipped.
            now.set(c, k >= 3 && k <= 6 ? b + 0.4f * (next() - 0.5f) : b);
          }
      Field3D fast("fast", fine, precision), reference("reference", fine, precision);
      for (size_t v = 0; v < fine.voxelCount(); ++v) {
        // Within [lo, hi], as mu is: a voxel outside would be clamped by the smallest change, and
        // where the reference's change rounds to exactly 0 and the fast one's to 1e-8 they differ.
        const float x = 0.5f + 0.25f * std::sin(0.37f * float(v));
        fast.set(v, x);
        reference.set(v, x);
      }
      const std::vector<float> initial = valuesOf(reference);
      const double mostFast = prolongChange(now, before, GridMap(coarse), fast, 0.2f, 0.8f);
      const double mostRef =
          prolongChangeReference(now, before, GridMap(coarse), reference, 0.2f, 0.8f);
      const float tolerance = precision == Precision::FP16 ? 1e-3f : 1e-5f;
      float worst = 0.f;
      size_t changed = 0;
      for (size_t v = 0; v < fine.voxelCount(); ++v) {
        worst = std::max(worst, std::abs(fast.get(v) - reference.get(v)));
        changed += reference.get(v) != initial[v];
      }
      EXPECT_LT(worst, tolerance) << toString(precision) << " " << dims.x;
      EXPECT_NEAR(mostFast, mostRef, tolerance);
      EXPECT_GT(changed, fine.voxelCount() / 10);     // the slab moved voxels,
      EXPECT_LT(changed, fine.voxelCount() * 2 / 3);  // but not all of them
    }
}

// The restriction samples of an interior coarse voxel lie symmetrically about its centre, so
// their mean of a linear field is the field at the centre and their maximum the uphill corner's
// value; trilinear prolongation reproduces a linear change exactly.
TEST(MultigridTransfer, RestrictionAndCorrectionAreExactOnLinearFields) {
  const GridSpec fine = cube(17, 1.f);
  const GridSpec coarse = levelGrid(fine, 4);
  ASSERT_EQ(coarse.dims, glm::ivec3(5));
  const Field3D f = linearField(fine, linear);
  Field3D c("coarse", coarse, Precision::FP32);
  restrictMean(f, GridMap(fine), c);
  for (int k = 1; k < 4; ++k)
    for (int j = 1; j < 4; ++j)
      for (int i = 1; i < 4; ++i)
        EXPECT_NEAR(c.get(coarse.linearIndex(i, j, k)),
                    linear(coarse.indexToWorld(glm::vec3(float(i), float(j), float(k)))), 1e-5f);

  // fine += P(now - before): the change is linear, so every fine voxel gains it exactly.
  const Field3D before = linearField(coarse, [](glm::vec3) { return 2.f; });
  const Field3D now = linearField(coarse, [](glm::vec3 x) { return 2.f + 0.05f * x.x + 0.1f; });
  Field3D target = linearField(fine, linear);
  const double most = prolongChange(now, before, GridMap(coarse), target, -1e30f, 1e30f);
  double expectedMost = 0.0;
  for (int k = 0; k < fine.dims.z; ++k)
    for (int j = 0; j < fine.dims.y; ++j)
      for (int i = 0; i < fine.dims.x; ++i) {
        const glm::vec3 x = fine.indexToWorld(glm::vec3(float(i), float(j), float(k)));
        const float change = 0.05f * x.x + 0.1f;
        expectedMost = std::max(expectedMost, double(std::abs(change)));
        EXPECT_NEAR(target.get(fine.linearIndex(i, j, k)), linear(x) + change, 1e-5f);
      }
  EXPECT_NEAR(most, expectedMost, 1e-5);

  // Clamped to [lo, hi]: mu stays within Eq. 14's bounds.
  Field3D mu = linearField(fine, [](glm::vec3) { return 0.5f; });
  const Field3D up = linearField(coarse, [](glm::vec3 x) { return x.x; });
  const Field3D zero = linearField(coarse, [](glm::vec3) { return 0.f; });
  prolongChange(up, zero, GridMap(coarse), mu, 0.f, 1.f);
  for (int i = 0; i < fine.dims.x; ++i) {
    const float x = fine.indexToWorld(glm::vec3(float(i), 8.f, 8.f)).x;
    EXPECT_NEAR(mu.get(fine.linearIndex(i, 8, 8)), std::clamp(0.5f + x, 0.f, 1.f), 1e-5f);
  }

  // The maximum of a linear field over the samples (the centre and a third of a coarse voxel
  // along each axis) lies at the corner sample uphill: f(centre) + sum |a_i| h_i / 3.
  Field3D m("max", coarse, Precision::FP32);
  restrictMax(f, GridMap(fine), m);
  const float uphill = (0.3f + 0.2f + 0.1f) * coarse.spacing.x / 3.f;
  for (int k = 1; k < 4; ++k)
    for (int j = 1; j < 4; ++j)
      for (int i = 1; i < 4; ++i)
        EXPECT_NEAR(m.get(coarse.linearIndex(i, j, k)),
                    linear(coarse.indexToWorld(glm::vec3(float(i), float(j), float(k)))) + uphill,
                    1e-5f);
}

namespace {

constexpr int kN = 40;
constexpr float kSphereRadius = 12.f, kShell = 0.75f;

// The scene of test_context_surfaces: a wide thin disc (radius 9, the important structure)
// inside a thin-shell sphere (radius 12), here on two multigrid levels.
void setup(Engine& e) {
  OccluderScene s;
  s.n = kN;
  s.slabY0 = 1e9f;  // no slab
  s.slabY1 = -1e9f;
  s.blobCentre = glm::vec3(0.5f, 0.5f, 0.5f);
  s.blobRadius = 9.f;
  s.blobHalfThickness = 0.4f;
  e.setVolume(makeOccluderVolume(s, e.precision()));
  e.setTransferFunction(occluderTransferFunction());
  e.setImportanceCurve(blobImportance());
  e.setCamera(Camera::orbit({0, 0, 0}, 0.f, 0.f, 90.f));  // on -y, facing the disc
  PointLight light;
  light.position = {0.f, -90.f, 0.f};
  e.setLight(light);
  e.setViewportSize(48, 48);
  const GridSpec& g = e.volume().grid();
  const Field3D phi0 = shellSphereSdf(g, kSphereRadius, kShell);
  ContextSurfaceSpec spec;
  spec.source = "test:shell sphere";
  spec.filled = false;
  spec.shell = kShell;
  e.addContextSurface(spec, phi0);
  ExtinctionSettings st;
  st.levels = 2;
  st.maxIterationsPerLevel = 60;
  st.frustumScale = 1.f;
  e.setExtinctionSettings(st);
}

// The camera on the far side (+y): there the back cap of the shell, which the first view did
// not need opened, hides the disc.
Camera farSide() {
  return Camera::orbit({0, 0, 0}, 180.f, 0.f, 90.f);
}

// The visibility of the disc for the current camera in the finest state: what one finest
// iteration's view scan measures before its step.
double visibilityNow(Engine& e) {
  const auto st = e.continueOptimization(1);
  return st.empty() ? -1.0 : st.front().visibilityView;
}

template <class F>
void singleThreaded(F body) {
  tbb::task_arena arena(1);
  arena.execute(body);
}

}  // namespace

TEST(CameraFollow, CoarseIterationsOpenTheSurfaceForTheNewView) {
  Engine following, waiting;
  for (Engine* e : {&following, &waiting}) {
    setup(*e);
    e->optimize();
    e->setCamera(farSide());
  }
  const auto stats = following.followCamera(20);
  ASSERT_EQ(stats.size(), 20u);
  for (const IterationStats& st : stats) {
    EXPECT_EQ(st.level, 0) << "the coarsest level";
    EXPECT_TRUE(st.following);
  }
  EXPECT_LT(stats.front().visibilityView, 0.1) << "the back cap hides the disc at first";

  const double followed = visibilityNow(following), stayed = visibilityNow(waiting);
  EXPECT_LT(stayed, 0.1) << "without following, the new view still looks at the closed cap";
  EXPECT_GT(followed, 0.5) << "the coarse correction must have opened the cap on the finest grid";

  // The corrected state is one the finest level carries on from: mu within Eq. 14's bounds,
  // phi finite, and further finest iterations keep the view open.
  const Field3D& mu = *following.optimizedExtinction();
  const float muMax = 0.3f;  // the occluder transfer function's largest extinction (Eq. 14)
  for (size_t v = 0; v < mu.size(); ++v) {
    ASSERT_GE(mu.get(v), 0.f);
    ASSERT_LE(mu.get(v), muMax * 1.0001f);
  }
  const Field3D& phi = *following.contextSurfacePhi(0);
  for (size_t v = 0; v < phi.size(); ++v) ASSERT_TRUE(std::isfinite(phi.get(v)));
  std::vector<IterationStats> more = following.continueOptimization(10);
  ASSERT_EQ(more.size(), 10u);
  EXPECT_GT(more.back().visibilityView, 0.5);
  EXPECT_LT(more.back().maxDeviationVoxels, 20.0) << "no runaway surface after the correction";
}

// An iteration abandoned before its extinction step changes nothing on the finest grid, as in
// continueOptimization: the workstation abandons on every newer camera.
TEST(CameraFollow, AnAbandonedIterationChangesNothing) {
  singleThreaded([] {
    Engine e;
    setup(e);
    e.optimize();
    e.setCamera(farSide());
    ASSERT_EQ(e.followCamera(2).size(), 2u);
    const std::vector<float> mu = valuesOf(*e.optimizedExtinction());
    const std::vector<float> phi = valuesOf(*e.contextSurfacePhi(0));
    int polls = 0;
    EXPECT_TRUE(e.followCamera(1, {}, [&] { return ++polls == 3; }).empty());
    EXPECT_EQ(polls, 3);
    EXPECT_EQ(valuesOf(*e.optimizedExtinction()), mu);
    EXPECT_EQ(valuesOf(*e.contextSurfacePhi(0)), phi);
    ASSERT_EQ(e.followCamera(1).size(), 1u);
    EXPECT_NE(valuesOf(*e.optimizedExtinction()), mu) << "the next one does change mu";
  });
}

// The coarse level exists only while following: listed in the ledger then, gone after a reset;
// a frozen result does not follow.
TEST(CameraFollow, TheCoarseLevelIsModelledOnlyWhileFollowing) {
  Engine e;
  setup(e);
  e.optimize();
  const auto following = [&] {
    for (const auto& entry : e.ledger().entries())
      if (entry.name.find("(following)") != std::string::npos) return true;
    return false;
  };
  EXPECT_FALSE(following());
  e.setCamera(farSide());
  ASSERT_EQ(e.followCamera(1).size(), 1u);
  EXPECT_TRUE(following());
  e.resetOptimization();
  EXPECT_FALSE(following());

  e.optimize();
  e.setFrozen(true);
  const std::vector<float> mu = valuesOf(*e.optimizedExtinction());
  EXPECT_TRUE(e.followCamera(3).empty());
  EXPECT_EQ(valuesOf(*e.optimizedExtinction()), mu);
}

// A smaller turn: the first view's opening still shows part of the disc; following keeps it and
// opens the rest (with g restricted as a mean the coarse return term closed it instead: 0.06).
TEST(CameraFollow, ASmallerTurnKeepsAndWidensTheOpening) {
  Engine following, waiting;
  for (Engine* e : {&following, &waiting}) {
    setup(*e);
    e->optimize();
    e->setCamera(Camera::orbit({0, 0, 0}, 60.f, 0.f, 90.f));
  }
  ASSERT_EQ(following.followCamera(20).size(), 20u);
  const double followed = visibilityNow(following), stayed = visibilityNow(waiting);
  EXPECT_GT(stayed, 0.1) << "part of the disc shows through the first view's opening";
  EXPECT_GT(followed, stayed + 0.2);
}

// The default scene (the Shepp-Logan head at 64^3, three levels), the camera turned 120 degrees
// about the head after the optimisation: ten coarse iterations (about 2 ms each against ~50 ms
// for a finest one here) open the skull for the new view, which without them still looks at a
// closed skull.
TEST(CameraFollow, TheDefaultSceneOpensForATurnedCamera) {
  Engine following, waiting;
  for (Engine* e : {&following, &waiting}) {
    e->loadBuiltinScene("shepp-logan", 64);
    e->setViewportSize(128, 128);
    e->optimize();
    const Camera c = e->camera();
    const glm::vec3 d = c.eye - c.target;
    const float r = glm::length(d);
    const float azimuth = std::atan2(d.x, -d.y) * 57.29578f;
    const float elevation = std::asin(d.z / r) * 57.29578f;
    e->setCamera(Camera::orbit(c.target, azimuth + 120.f, elevation, r));
  }
  ASSERT_EQ(following.followCamera(10).size(), 10u);
  const auto followed = following.continueOptimization(1);
  const auto stayed = waiting.continueOptimization(1);
  ASSERT_EQ(followed.size(), 1u);
  ASSERT_EQ(stayed.size(), 1u);
  EXPECT_LT(stayed[0].visibilityViewOccluders, 0.1);
  EXPECT_GT(followed[0].visibilityViewOccluders, 0.3);
}

// A preview while dragging draws the extinction as the coarse correction left it (otherwise it
// would show the last full frame's mu until the release), with the T_L it has; the next full
// frame computes T_L again. A scene of volume occluders only, so that nothing else (a context
// surface, drawn live) could make the previews differ.
TEST(CameraFollow, APreviewAfterFollowingDrawsTheCorrectedExtinction) {
  Engine e;
  loadOccluderScene(e);
  ExtinctionSettings st;
  st.levels = 2;
  st.maxIterationsPerLevel = 30;
  e.setExtinctionSettings(st);
  e.optimize();
  RenderSettings full;
  full.width = full.height = 64;
  (void)e.render(full);
  e.setCamera(Camera::orbit({0, 0, 0}, 90.f, 0.f, 90.f));
  RenderSettings preview = full;
  preview.preview = true;
  const Image before = e.render(preview);
  ASSERT_EQ(e.followCamera(10).size(), 10u);
  RenderStats stats;
  const Image after = e.render(preview, &stats);
  EXPECT_EQ(stats.lightMilliseconds, 0.0) << "the preview keeps the T_L it has";
  ASSERT_EQ(before.pixels.size(), after.pixels.size());
  double changed = 0.0;
  for (size_t i = 0; i < before.pixels.size(); ++i)
    changed += double(glm::length(before.pixels[i] - after.pixels[i]));
  EXPECT_GT(changed, 0.0) << "the preview must draw the corrected mu, not the last full frame's";
  const Image again = e.render(preview, &stats);
  EXPECT_EQ(again.pixels, after.pixels) << "nothing changed since: the same preview";
  (void)e.render(full, &stats);
  EXPECT_GT(stats.lightMilliseconds, 0.0) << "the full frame after following computes T_L again";
}
