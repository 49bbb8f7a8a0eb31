// builtin:level-set-cases, paper 000's Fig. 3: the three ways an important object lies relative
// to an opaque context surface, and what the level-set optimisation (Eq. 23) must do in each.
//   left:   important in front of the context   -> the isocontour does not change;
//   middle: important nested inside a shell     -> the front wall opens, the back wall stays;
//   right:  important behind a context rod      -> the rod's occluding middle shrinks from front
//           and back until the isocontour splits in two, whose parts move apart until their
//           tips reach the ball's silhouette; it returns to its initial shape when the
//           occlusion is gone (the camera turned to the other side).
// Everything is measured on the surface's SDF (phi against its base phi0), not on images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

#include "core/field_view.h"
#include "visopt/engine.h"

using namespace visopt;

namespace {

constexpr int kResolution = 64;
constexpr float kHalf = 100.f;  // mm: normalised scene coordinates are world / 100 mm

// phi at a point given in the scene's normalised coordinates (trilinear), in voxels.
float phiAt(const Field3D& phi, glm::vec3 normalised) {
  const GridSpec& g = phi.grid();
  return FieldView(phi).sample(g.worldToIndex(normalised * kHalf)) / g.minSpacing();
}

// The largest |phi - phi0| (voxels) over voxels near the base surface (|phi0| < 2 voxels) whose
// normalised coordinates satisfy `inRegion`.
template <class Region>
double maxDeviationNearSurface(const Field3D& phi, const Field3D& phi0, Region inRegion) {
  const GridSpec& g = phi.grid();
  const float h = g.minSpacing();
  double worst = 0.0;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::vec3 p = g.indexToWorld(glm::vec3(i, j, k)) / kHalf;
        if (!inRegion(p)) continue;
        const size_t v = g.linearIndex(i, j, k);
        const float base = phi0.get(v) / h;
        if (std::abs(base) >= 2.f) continue;
        worst = std::max(worst, double(std::abs(phi.get(v) / h - base)));
      }
  return worst;
}

// Connected components (6-neighbourhood) of {phi < 0} among voxels in the region.
template <class Region>
int insideComponents(const Field3D& phi, Region inRegion) {
  const GridSpec& g = phi.grid();
  const glm::ivec3 d = g.dims;
  std::vector<char> state(g.voxelCount(), 0);  // 0 unvisited, 1 inside, 2 done
  for (int k = 0; k < d.z; ++k)
    for (int j = 0; j < d.y; ++j)
      for (int i = 0; i < d.x; ++i)
        if (inRegion(g.indexToWorld(glm::vec3(i, j, k)) / kHalf) &&
            phi.get(g.linearIndex(i, j, k)) < 0.f)
          state[g.linearIndex(i, j, k)] = 1;
  int components = 0;
  for (int k = 0; k < d.z; ++k)
    for (int j = 0; j < d.y; ++j)
      for (int i = 0; i < d.x; ++i) {
        if (state[g.linearIndex(i, j, k)] != 1) continue;
        ++components;
        std::queue<glm::ivec3> open;
        open.push({i, j, k});
        state[g.linearIndex(i, j, k)] = 2;
        while (!open.empty()) {
          const glm::ivec3 c = open.front();
          open.pop();
          for (const glm::ivec3 step :
               {glm::ivec3(1, 0, 0), glm::ivec3(-1, 0, 0), glm::ivec3(0, 1, 0),
                glm::ivec3(0, -1, 0), glm::ivec3(0, 0, 1), glm::ivec3(0, 0, -1)}) {
            const glm::ivec3 n = c + step;
            if (glm::any(glm::lessThan(n, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(n, d)))
              continue;
            const size_t v = g.linearIndex(n.x, n.y, n.z);
            if (state[v] != 1) continue;
            state[v] = 2;
            open.push(n);
          }
        }
      }
  return components;
}

// The three cases' regions (normalised coordinates), as the scene lays them out.
bool leftCase(glm::vec3 p) {
  return p.x < -0.34f;
}
bool rightRod(glm::vec3 p) {  // the context rod of the right case, in front of its ball
  return p.x > 0.36f && p.y < -0.1f;
}

// The rod's gap along its axis (x = 0.54, y = -0.3, normalised): the extent in z of {phi > 0}
// around z = 0, in voxels; 0 while the rod is whole. Its two ends are the split parts' tips.
struct RodGap {
  float lower = 0.f, upper = 0.f;  // normalised z of the tips facing the gap
  float voxels(const GridSpec& g) const { return (upper - lower) * kHalf / g.minSpacing(); }
};
RodGap rodGap(const Field3D& phi) {
  const float dz = 0.25f * phi.grid().minSpacing() / kHalf;
  RodGap gap;
  if (phiAt(phi, {0.54f, -0.3f, 0.f}) <= 0.f) return gap;
  while (gap.upper < 0.5f && phiAt(phi, {0.54f, -0.3f, gap.upper + dz}) > 0.f) gap.upper += dz;
  while (gap.lower > -0.5f && phiAt(phi, {0.54f, -0.3f, gap.lower - dz}) > 0.f) gap.lower -= dz;
  return gap;
}

struct CasesRun {
  Engine engine;
  std::vector<IterationStats> stats;
  explicit CasesRun(Precision precision) : engine(precision) {
    engine.loadBuiltinScene("level-set-cases", kResolution);
    engine.setViewportSize(128, 128);
    stats = engine.optimize();
  }
  const Field3D& phi() const { return *engine.contextSurfacePhi(0); }
  const Field3D& phi0() const { return *engine.contextSurfaceBase(0); }
};

}  // namespace

const char* name(Precision p) {
  return p == Precision::FP16 ? "fp16" : "fp32";
}

TEST(LevelSetCasesScene, ContextBehindTheImportantObjectKeepsItsShape) {
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    CasesRun run(p);
    // It hides nothing important, so ghat = 0 on it and Eq. 23's speed is zero.
    EXPECT_LT(maxDeviationNearSurface(run.phi(), run.phi0(), leftCase), 0.1) << name(p);
  }
}

TEST(LevelSetCasesScene, NestedObjectOpensTheFrontWallAndKeepsTheBackWall) {
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    SCOPED_TRACE(name(p));
    CasesRun run(p);
    ASSERT_FALSE(run.stats.empty());
    const glm::vec3 front(0.f, -0.26f, 0.f), back(0.f, 0.26f, 0.f);  // the walls' middles
    EXPECT_LT(phiAt(run.phi0(), front), 0.f) << "the front wall is solid at first";
    EXPECT_GT(phiAt(run.phi(), front), 1.f) << "the level set evolved through the front wall";
    EXPECT_LT(phiAt(run.phi(), back), 0.f);
    EXPECT_NEAR(phiAt(run.phi(), back), phiAt(run.phi0(), back), 0.1) << "nothing hides behind";
    EXPECT_LT(run.stats.front().visibilityViewOccluders, 0.5);
    EXPECT_GT(run.stats.back().visibilityViewOccluders, 0.7);
  }
}

// On the rod's axis, the largest |z| at which the ray from `eye` (normalised) through the axis
// passes the important ball (centre (0.62, 0.25, 0), radius 0.18): the ball's silhouette on it.
float ballSilhouetteOnRodAxis(glm::vec3 eye) {
  const glm::vec3 ball(0.62f, 0.25f, 0.f);
  auto hidesBall = [&](float z) {
    const glm::vec3 d = glm::normalize(glm::vec3(0.54f, -0.3f, z) - eye);
    const glm::vec3 c = ball - eye;
    return glm::length(c - glm::dot(c, d) * d) < 0.18f;
  };
  float lo = 0.f, hi = 0.5f;
  for (int n = 0; n < 40; ++n) (hidesBall(0.5f * (lo + hi)) ? lo : hi) = 0.5f * (lo + hi);
  return lo;
}

TEST(LevelSetCasesScene, ObjectBehindARodSplitsItAndThePartsMoveApartToItsSilhouette) {
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    SCOPED_TRACE(name(p));
    CasesRun run(p);
    EXPECT_EQ(insideComponents(run.phi0(), rightRod), 1);
    EXPECT_EQ(insideComponents(run.phi(), rightRod), 2) << "the isocontour splits";
    // The middle, in front of the ball, is gone from front to back; the stumps above and
    // below the ball's silhouette keep their shape.
    for (float y : {-0.36f, -0.3f, -0.24f})
      EXPECT_GT(phiAt(run.phi(), {0.54f, y, 0.f}), 0.f) << "y " << y;
    for (float z : {-0.35f, 0.35f})
      EXPECT_NEAR(phiAt(run.phi(), {0.54f, -0.3f, z}), phiAt(run.phi0(), {0.54f, -0.3f, z}), 0.1)
          << "z " << z;
    // The two parts moved apart until their tips reach the ball's silhouette as the camera sees
    // it (ghat > 0 exactly where a view ray from the rod meets the ball), and no farther (there
    // the return term of Eq. 23 holds them): each tip within one voxel of it.
    const float silhouette = ballSilhouetteOnRodAxis(run.engine.camera().eye / kHalf);
    const float voxel = run.phi().grid().minSpacing() / kHalf;
    const RodGap gap = rodGap(run.phi());
    EXPECT_NEAR(gap.upper, silhouette, voxel);
    EXPECT_NEAR(gap.lower, -silhouette, voxel);
    EXPECT_GT(gap.voxels(run.phi().grid()), 8.f) << "apart by the silhouette's 10 voxels";
  }
}

TEST(LevelSetCasesScene, SurfacesReturnWhenTheOcclusionIsGone) {
  CasesRun run(Precision::FP32);
  ASSERT_EQ(insideComponents(run.phi(), rightRod), 2);
  ASSERT_GT(phiAt(run.phi(), {0.f, -0.26f, 0.f}), 1.f);
  // From the other side the rod and the shell's former front wall are behind the important
  // objects: the return term of Eq. 23 brings them back to phi0 (and the far wall opens).
  // The key light turns with the camera: left in front, the rod would still shadow the ball
  // from it, and ghat's light half (Eq. 19) would keep a dent in it.
  run.engine.orbitCamera(180.f, 0.f, 2.4f);
  run.engine.setLight(
      PointLight::keyLightFor(run.engine.camera(), run.engine.volume().grid().worldBounds()));
  run.engine.continueOptimization(40);
  EXPECT_EQ(insideComponents(run.phi(), rightRod), 1);
  EXPECT_LT(maxDeviationNearSurface(run.phi(), run.phi0(), rightRod), 0.1);
  EXPECT_NEAR(phiAt(run.phi(), {0.f, -0.26f, 0.f}), phiAt(run.phi0(), {0.f, -0.26f, 0.f}), 0.1);
  EXPECT_GT(phiAt(run.phi(), {0.f, 0.26f, 0.f}), 1.f);
}
