// Numerical stability of the extinction optimisation at the extremes, fp32 and fp16: every field
// stays finite and inside its bounds, the energy never becomes NaN.
#include <cmath>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "occluder_scene.h"
#include "visopt/engine.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

struct Extreme {
  std::string name;
  std::function<void(Engine&, ExtinctionSettings&)> setup;
};

Volume smallVolume(glm::ivec3 dims, glm::vec3 spacing, Precision p) {
  GridSpec g;
  g.dims = dims;
  g.spacing = spacing;
  g.origin = -0.5f * glm::vec3(dims - 1) * spacing;
  Volume v;
  v.name = "small";
  v.sourcePath = "test:small";
  v.valueMin = 0.0;
  v.valueMax = 1.0;
  v.normalized = Field3D("volume", g, p);
  for (size_t i = 0; i < v.normalized.size(); ++i)
    v.normalized.set(i, float((i * 7919u) % 101u) / 100.f);
  return v;
}

void useVolume(Engine& e, Volume v) {
  e.setVolume(std::move(v));
  e.setTransferFunction(occluderTransferFunction());
  e.setImportanceCurve({{0.0, 0.0}, {0.5, 1.0}, {1.0, 0.2}});
  e.orbitCamera(20.f, 10.f, 3.f);
  e.setLight(PointLight::keyLightFor(e.camera(), e.volume().grid().worldBounds()));
}

std::vector<Extreme> extremes() {
  return {
      {"mu_max tiny", [](Engine&, ExtinctionSettings& s) { s.muMax = 1e-6f; }},
      {"mu_max huge", [](Engine&, ExtinctionSettings& s) { s.muMax = 1e6f; }},
      {"rho zero", [](Engine&, ExtinctionSettings& s) { s.rho = 0.f; }},
      {"q and r huge",
       [](Engine&, ExtinctionSettings& s) {
         s.q = 1e6f;
         s.r = 1e6f;
       }},
      {"g everywhere one",
       [](Engine& e, ExtinctionSettings& s) {
         e.setImportanceCurve({{0.0, 1.0}, {1.0, 1.0}});
         s.r = 10.f;
       }},
      {"2^3 grid",
       [](Engine& e, ExtinctionSettings& s) {
         useVolume(e, smallVolume({2, 2, 2}, {1, 1, 1}, e.precision()));
         s.r = 5.f;
       }},
      {"anisotropic grid",
       [](Engine& e, ExtinctionSettings& s) {
         useVolume(e, smallVolume({24, 20, 3}, {0.5f, 1.f, 25.f}, e.precision()));
         s.r = 5.f;
       }},
      {"camera inside the volume",
       [](Engine& e, ExtinctionSettings& s) {
         Camera c;
         c.eye = {1.f, -2.f, 0.5f};
         c.target = {1.f, 10.f, 0.5f};
         e.setCamera(c);
         s.r = 5.f;
       }},
      {"light behind the camera",
       [](Engine& e, ExtinctionSettings& s) {
         PointLight l;
         l.position = e.camera().eye - 40.f * e.camera().forward();
         e.setLight(l);
         s.r = 5.f;
       }},
      {"light inside the volume",
       [](Engine& e, ExtinctionSettings& s) {
         PointLight l;
         l.position = {0.f, 0.f, 0.f};
         e.setLight(l);
         s.r = 5.f;
       }},
  };
}

class Extremes : public ::testing::TestWithParam<Precision> {};

}  // namespace

TEST_P(Extremes, FieldsStayFiniteAndBounded) {
  for (const auto& ex : extremes()) {
    SCOPED_TRACE(ex.name);
    Engine e(GetParam());
    OccluderScene scene;
    scene.n = 20;
    loadOccluderScene(e, scene);
    e.setViewportSize(32, 32);
    ExtinctionSettings s;
    s.levels = 2;
    s.maxIterationsPerLevel = 6;
    s.minIterationsPerLevel = 6;
    ex.setup(e, s);
    e.setExtinctionSettings(s);
    const auto stats = e.optimize();
    ASSERT_FALSE(stats.empty());
    for (const auto& st : stats) {
      ASSERT_TRUE(std::isfinite(st.energy())) << "iteration " << st.iteration;
      ASSERT_TRUE(std::isfinite(st.visibilityView) && std::isfinite(st.visibilityLight));
      ASSERT_TRUE(std::isfinite(st.stepNorm));
      EXPECT_GE(st.visibilityView, 0.0);
      EXPECT_LE(st.visibilityView, 1.0 + 1e-6);
    }
    const Field3D& mu = *e.optimizedExtinction();
    float bound = s.muMax > 0.f ? s.muMax : 0.3f;
    if (GetParam() == Precision::FP16) bound = std::min(bound, 1e4f);
    for (size_t i = 0; i < mu.size(); ++i) {
      const float m = mu.get(i);
      ASSERT_TRUE(std::isfinite(m)) << "voxel " << i;
      ASSERT_GE(m, 0.f);
      // fp16 rounds a value at the bound to the nearest representable one (6e-8 apart for
      // subnormals), which may lie just above it.
      const float slack = GetParam() == Precision::FP16 ? 1e-3f * bound + 6e-8f : 0.f;
      ASSERT_LE(m, bound + slack);
    }
    // Continuing from the extreme state stays finite too, and the render is finite.
    for (const auto& st : e.continueOptimization(3)) ASSERT_TRUE(std::isfinite(st.energy()));
    RenderSettings rs;
    rs.width = rs.height = 24;
    const Image img = e.render(rs);
    for (const auto& p : img.pixels)
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}

INSTANTIATE_TEST_SUITE_P(Precisions, Extremes, ::testing::Values(Precision::FP32, Precision::FP16),
                         [](const auto& param) { return std::string(toString(param.param)); });
