// The joint optimisation with context surfaces at the extremes, fp32 and fp16 (issue: thickness
// 0 and larger than the object, lambda 0 and very large, ghat = 1, a flat or constant phi,
// anisotropic spacing, tiny grids): nothing becomes NaN, phi stays bounded, the time step adapts.
#include <cmath>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "occluder_scene.h"
#include "visopt/engine.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

Volume ballVolume(glm::ivec3 dims, glm::vec3 spacing, Precision p) {
  GridSpec g;
  g.dims = dims;
  g.spacing = spacing;
  g.origin = -0.5f * glm::vec3(dims - 1) * spacing;
  Volume v;
  v.name = "ball";
  v.sourcePath = "test:ball";
  v.valueMin = 0.0;
  v.valueMax = 1.0;
  v.normalized = Field3D("volume", g, p);
  const float r0 = 0.35f * glm::length(glm::vec3(dims - 1) * spacing) / std::sqrt(3.f);
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int i = 0; i < dims.x; ++i) {
        const float r = glm::length(g.indexToWorld(glm::vec3(float(i), float(j), float(k))));
        v.normalized.set(g.linearIndex(i, j, k), r < 0.4f * r0 ? 0.5f : (r < r0 ? 0.25f : 0.f));
      }
  return v;
}

struct Case {
  std::string name;
  glm::ivec3 dims{20};
  glm::vec3 spacing{1.f};
  bool filled = false;
  float shell = 1.f;
  float lambda = 0.3f;
  bool importanceEverywhere = false;
  std::string source = "iso:0.12:inside-high";
};

class ContextExtremes : public ::testing::TestWithParam<Precision> {};

}  // namespace

TEST_P(ContextExtremes, StayFiniteAndBounded) {
  const std::vector<Case> cases = {
      {"shell thickness 0", {20, 20, 20}, {1, 1, 1}, false, 0.f},
      {"shell thicker than the object", {20, 20, 20}, {1, 1, 1}, false, 50.f},
      {"lambda 0", {20, 20, 20}, {1, 1, 1}, true, 0.f, 0.f},
      {"lambda huge", {20, 20, 20}, {1, 1, 1}, true, 0.f, 1e6f},
      {"ghat = 1 everywhere", {20, 20, 20}, {1, 1, 1}, true, 0.f, 0.3f, true},
      {"anisotropic spacing", {24, 20, 6}, {0.5f, 1.f, 6.f}, false, 1.f},
      {"tiny grid", {3, 3, 3}, {1, 1, 1}, true, 0.f},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Engine e(GetParam());
    e.setVolume(ballVolume(c.dims, c.spacing, GetParam()));
    e.setTransferFunction(occluderTransferFunction());
    if (c.importanceEverywhere)
      e.setImportanceCurve({{0.0, 1.0}, {1.0, 1.0}});
    else
      e.setImportanceCurve(blobImportance());
    e.orbitCamera(15.f, 10.f, 3.f);
    e.setLight(PointLight::keyLightFor(e.camera(), e.volume().grid().worldBounds()));
    e.setViewportSize(32, 32);
    LevelSetSettings ls;
    ls.lambda = c.lambda;
    e.setLevelSetSettings(ls);
    ContextSurfaceSpec spec;
    spec.source = c.source;
    spec.filled = c.filled;
    spec.shell = c.shell;
    e.addContextSurface(spec);
    ExtinctionSettings s;
    s.levels = 2;
    s.maxIterationsPerLevel = 8;
    s.minIterationsPerLevel = 8;
    s.r = 5.f;
    e.setExtinctionSettings(s);
    const auto stats = e.optimize();
    ASSERT_FALSE(stats.empty());
    for (const auto& st : stats) {
      ASSERT_TRUE(std::isfinite(st.energy()));
      ASSERT_TRUE(std::isfinite(st.levelSetTimeStep) && st.levelSetTimeStep > 0.0);
      ASSERT_TRUE(std::isfinite(st.maxDeviationVoxels));
      if (c.lambda >= 1e6f) {
        EXPECT_LE(st.levelSetTimeStep, 1e-6) << "dt must follow 1/lambda";
      }
    }
    const Field3D& phi = *e.contextSurfacePhi(0);
    const Field3D& phi0 = *e.contextSurfaceBase(0);
    // Bounded as a distance in this box can be: where a surface moved (ghat = 1 everywhere eats
    // a ball from the view and the light side, leaving a part off-centre) the distance from the
    // far corner exceeds any of phi0's, but never the box's diagonal.
    float bound = std::max(e.volume().grid().diagonal(), 0.f);
    for (size_t i = 0; i < phi0.size(); ++i) bound = std::max(bound, std::abs(phi0.get(i)));
    bound += 2.f * glm::length(e.volume().grid().spacing);
    for (size_t i = 0; i < phi.size(); ++i) {
      ASSERT_TRUE(std::isfinite(phi.get(i))) << "voxel " << i;
      ASSERT_LE(std::abs(phi.get(i)), bound) << "voxel " << i;
    }
    RenderSettings rs;
    rs.width = rs.height = 24;
    rs.deviationView = true;
    for (const auto& p : e.render(rs).pixels)
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}

INSTANTIATE_TEST_SUITE_P(Precisions, ContextExtremes,
                         ::testing::Values(Precision::FP32, Precision::FP16),
                         [](const auto& param) { return std::string(toString(param.param)); });
