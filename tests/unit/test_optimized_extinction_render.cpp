// How the renderer draws an optimised extinction (kernels/volume_extinction.h): the transfer
// function's mu_bar classified after interpolation plus the interpolated change mu - mu_bar.
// Where the optimisation changed nothing the picture is the one before it, bit for bit in fp32
// (drawing mu itself, classified per voxel, differs at every sharp edge of the transfer
// function: the Shepp-Logan phantom is made of them); where it changed mu the picture changes;
// the change field exists only while an optimised mu is drawn.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "visopt/engine.h"

using namespace visopt;

namespace {

constexpr int kSize = 64;

RenderSettings settings() {
  RenderSettings s;
  s.width = s.height = kSize;
  return s;
}

float meanDifference(const Image& a, const Image& b) {
  double d = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3 e = glm::abs(a.pixels[i] - b.pixels[i]);
    d += double(e.x + e.y + e.z) / 3.0;
  }
  return float(d / double(a.pixels.size()));
}

float maxDifference(const Image& a, const Image& b) {
  float d = 0.f;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3 e = glm::abs(a.pixels[i] - b.pixels[i]);
    d = std::max({d, e.x, e.y, e.z});
  }
  return d;
}

bool ledgerHas(const Engine& e, const std::string& name) {
  for (const LedgerEntry& entry : e.ledger().entries())
    if (entry.name == name) return true;
  return false;
}

// The volume form of the default scene (no context surfaces), optimised with the visibility
// terms off: mu stays mu_bar.
void optimiseWithoutVisibilityTerms(Engine& e) {
  e.loadBuiltinScene("shepp-logan", 48, /*contextSurfaces=*/false);
  e.setViewportSize(kSize, kSize);
  ExtinctionSettings s;
  s.q = 0.f;
  s.r = 0.f;
  s.levels = 1;
  s.maxIterationsPerLevel = 5;
  e.setExtinctionSettings(s);
  e.optimize();
  ASSERT_TRUE(e.hasOptimizedExtinction());
}

}  // namespace

TEST(OptimizedExtinctionRender, UnchangedExtinctionDrawsAsBefore) {
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    Engine e(p);
    optimiseWithoutVisibilityTerms(e);
    e.setRenderOptimized(true);
    const Image optimised = e.render(settings());
    EXPECT_TRUE(ledgerHas(e, "extinction-change (render)"));
    e.setRenderOptimized(false);
    const Image before = e.render(settings());
    EXPECT_FALSE(ledgerHas(e, "extinction-change (render)")) << "allocated only while drawn";
    const float d = maxDifference(optimised, before), mean = meanDifference(optimised, before);
    std::printf("%s: largest pixel difference %.3g, mean %.3g\n", toString(p), d, mean);
    if (p == Precision::FP32) {
      EXPECT_EQ(d, 0.f);
    } else {
      // fp16 stores mu rounded to 11 bits, so the rho term of the gradient is not quite 0
      // and the change is not either: small, and nowhere a structure.
      EXPECT_LT(mean, 2e-3f);
      EXPECT_LT(d, 0.1f);
    }
  }
}

TEST(OptimizedExtinctionRender, ChangedExtinctionChangesThePicture) {
  Engine e;
  e.loadBuiltinScene("wall-and-membrane", 48, /*contextSurfaces=*/false);
  e.setViewportSize(kSize, kSize);
  ExtinctionSettings s;
  s.maxIterationsPerLevel = 20;
  e.setExtinctionSettings(s);
  e.optimize();
  ASSERT_TRUE(e.hasOptimizedExtinction());
  e.setRenderOptimized(true);
  const Image optimised = e.render(settings());
  e.setRenderOptimized(false);
  const Image before = e.render(settings());
  // The wall in front of the disc thins: the disc shows through (a visible change, not noise).
  EXPECT_GT(maxDifference(optimised, before), 0.05f);
  for (const glm::vec3& c : optimised.pixels) {
    ASSERT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
    ASSERT_GE(std::min({c.x, c.y, c.z}), 0.f);
  }
}
