// ClearView with more than one context and more than one focus layer (Krüger et al. 2006, §3.1:
// "one or more semi-transparent context layers", "one or more opaque focus layers"): each deeper
// context layer is found from where the one before it was hit, each pixel shows the nearest focus
// hit, and the context layers are blended back to front, each by its own opacity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "clearview_fixtures.h"
#include "kernels/clearview_composite.h"
#include "render/clearview.h"
#include "visopt/engine.h"
#include "visopt/error.h"
#include "visopt/scenes.h"

namespace visopt {
namespace {

void extract(const std::vector<const Field3D*>& contexts, const std::vector<const Field3D*>& foci,
             int w, int h, ClearViewLayers& out) {
  const Volume v = volumeOf(fieldOf([](glm::vec3) { return 0.f; }), -1.0, 1.0);
  const DeviceBuffer<glm::vec4> transfer;
  std::vector<ClearViewSurfaceSource> c, f;
  for (const Field3D* field : contexts) c.push_back({field, 0.f, 1.f});
  for (const Field3D* field : foci) f.push_back({field, 0.f, 1.f});
  extractClearViewLayers(v, transfer, frontCamera(), w, h, c, f, false, out);
}

float ballAt(glm::vec3 x, glm::vec3 centre, float r) {
  return r - glm::length(x - centre);
}

// The exact first hit of pixel (x, row)'s ray with the sphere |p - centre| = r beyond t >= tMin.
bool exactHit(int w, int h, int x, int row, glm::vec3 centre, float r, glm::vec3& hit) {
  const FrustumGrid f =
      FrustumGrid::forCamera(frontCamera(), w, h, cubeGrid().worldBounds(), 1, 1.f);
  const glm::vec3 d = f.rayDirection(float(x), float(h - 1 - row));
  const glm::vec3 o = frontCamera().eye - centre;
  const float b = glm::dot(o, d), c = glm::dot(o, o) - r * r;
  const float disc = b * b - c;
  if (disc < 0.f) return false;
  hit = frontCamera().eye + (-b - std::sqrt(disc)) * d;
  return true;
}

// Three concentric spheres: context 26, deeper context 18, focus 10. The deeper layer's hits lie
// on the middle sphere as exactly as the first layer's lie on the outer one, behind them.
TEST(ClearViewLayers, ADeeperContextLayerLiesOnItsOwnSurfaceBehindTheFirst) {
  const Field3D outer = fieldOf([](glm::vec3 x) { return ball(x, 26.f); });
  const Field3D middle = fieldOf([](glm::vec3 x) { return ball(x, 18.f); });
  const Field3D inner = fieldOf([](glm::vec3 x) { return ball(x, 10.f); });
  ClearViewLayers L;
  const int w = 48, h = 48;
  extract({&outer, &middle}, {&inner}, w, h, L);
  ASSERT_EQ(L.deeperContexts.size(), 1u);
  const ClearViewContextLayer& deep = L.deeperContexts[0];
  int checked = 0;
  int64_t withHit = 0;
  float worst = 0.f;
  for (int row = 0; row < h; ++row)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(row) * w + x;
      withHit += deep.depth[i] < kClearViewNoHit;
      glm::vec3 exact(0.f);
      if (!exactHit(w, h, x, row, glm::vec3(0.f), 18.f, exact)) {
        EXPECT_FALSE(deep.depth[i] < kClearViewNoHit && L.contextDepth[i] < kClearViewNoHit &&
                     std::abs(glm::length(deep.position[i]) - 18.f) > 1.f);
        continue;
      }
      const glm::vec3 n = glm::normalize(exact);
      if (glm::dot(n, -glm::normalize(exact - frontCamera().eye)) < 0.2f) continue;  // grazing
      ASSERT_LT(deep.depth[i], kClearViewNoHit) << x << "," << row;
      EXPECT_GT(deep.depth[i], L.contextDepth[i]);
      worst = std::max(worst, std::abs(glm::length(deep.position[i]) - 18.f));
      EXPECT_LT(glm::length(deep.normal[i] - n), 0.01f);
      ++checked;
    }
  EXPECT_GT(checked, 150);
  EXPECT_LT(worst, 0.05f);
  EXPECT_EQ(deep.pixels, withHit);
  EXPECT_LT(deep.pixels, L.contextPixels);  // the middle sphere covers less of the image
}

// The deeper layer is searched from the first layer's hit, not from the camera: its field has a
// ball in front of the first context surface and one behind it, and the layer finds the one behind.
TEST(ClearViewLayers, ADeeperLayerIsSearchedFromWhereTheOneBeforeItWasHit) {
  const glm::vec3 front(0.f, -27.f, 0.f), behind(0.f, 0.f, 0.f);
  const Field3D first = fieldOf([](glm::vec3 x) { return ball(x, 20.f); });
  const Field3D second =
      fieldOf([&](glm::vec3 x) { return std::max(ballAt(x, front, 3.f), ballAt(x, behind, 8.f)); });
  const Field3D focus = fieldOf([](glm::vec3 x) { return ball(x, 4.f); });
  ClearViewLayers L;
  const int w = 33, h = 33;
  extract({&first, &second}, {&focus}, w, h, L);
  const size_t centre = size_t(h / 2) * w + size_t(w / 2);
  glm::vec3 expected(0.f);
  ASSERT_TRUE(exactHit(w, h, w / 2, h / 2, behind, 8.f, expected));
  ASSERT_LT(L.deeperContexts[0].depth[centre], kClearViewNoHit);
  EXPECT_LT(glm::length(L.deeperContexts[0].position[centre] - expected), 0.05f);
  // The same field as the first layer finds the front ball.
  ClearViewLayers alone;
  extract({&second}, {&focus}, w, h, alone);
  ASSERT_TRUE(exactHit(w, h, w / 2, h / 2, front, 3.f, expected));
  // r = 3: trilinear interpolation of the distance to the ball is off by ~h^2 / (8 r).
  EXPECT_LT(glm::length(alone.contextPosition[centre] - expected), 0.15f);
}

// Two focus balls, a small one in front of a large one: each pixel holds the nearest hit, and the
// focus point is on the nearer ball.
TEST(ClearViewLayers, EachPixelShowsTheNearestFocusSurface) {
  const glm::vec3 small(0.f, -16.f, 3.f);
  const Field3D context = fieldOf([](glm::vec3 x) { return ball(x, 28.f); });
  const Field3D large = fieldOf([](glm::vec3 x) { return ball(x, 10.f); });
  const Field3D near = fieldOf([&](glm::vec3 x) { return ballAt(x, small, 4.f); });
  const int w = 48, h = 48;
  for (bool nearFirst : {false, true}) {
    ClearViewLayers L;
    extract({&context},
            nearFirst ? std::vector<const Field3D*>{&near, &large}
                      : std::vector<const Field3D*>{&large, &near},
            w, h, L);
    int onSmall = 0, onLarge = 0;
    for (int row = 0; row < h; ++row)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(row) * w + x;
        glm::vec3 hs(0.f), hl(0.f);
        const bool s = exactHit(w, h, x, row, small, 4.f, hs);
        const bool l = exactHit(w, h, x, row, glm::vec3(0.f), 10.f, hl);
        if (!s && !l) continue;
        const glm::vec3 want =
            s && (!l || glm::length(hs - frontCamera().eye) < glm::length(hl - frontCamera().eye))
                ? hs
                : hl;
        const glm::vec3 centre = want == hs ? small : glm::vec3(0.f);
        const float r = want == hs ? 4.f : 10.f;
        const glm::vec3 n = glm::normalize(want - centre);
        if (glm::dot(n, -glm::normalize(want - frontCamera().eye)) < 0.3f) continue;  // grazing
        ASSERT_LT(L.focusDepth[i], kClearViewNoHit) << x << "," << row;
        // Trilinear interpolation of |x - c| is off by ~h^2 / (8 r) (0.03 voxel at r = 4).
        EXPECT_NEAR(glm::length(L.focusPosition[i] - centre), r, r < 5.f ? 0.08f : 0.05f)
            << x << "," << row;
        (want == hs ? onSmall : onLarge) += 1;
      }
    EXPECT_GT(onSmall, 20);
    EXPECT_GT(onLarge, 100);
    glm::vec3 C(0.f);
    ASSERT_TRUE(clearViewFocusPoint(L, glm::vec2(-1.f), C));
    EXPECT_NEAR(glm::length(C - small), 4.f, 0.08f) << "nearFirst " << nearFirst;
  }
}

// Unshaded layers (diffuse, ambient 1) and no measure term: each context layer's opacity is
// saturate(|C - P_k| / s), and the pixel is a0 c + (1 - a0) (a1 c + (1 - a1) f), in display values.
TEST(ClearViewLayers, ContextLayersAreBlendedBackToFrontByTheirOwnOpacity) {
  const Field3D outer = fieldOf([](glm::vec3 x) { return ball(x, 26.f); });
  const Field3D middle = fieldOf([](glm::vec3 x) { return ball(x, 18.f); });
  const Field3D inner = fieldOf([](glm::vec3 x) { return ball(x, 10.f); });
  ClearViewLayers L;
  const int w = 40, h = 40;
  extract({&outer, &middle}, {&inner}, w, h, L);
  ClearViewSettings cv;
  cv.width = w;
  cv.height = h;
  cv.size = 30.f;
  cv.weight = 0.f;
  cv.border = false;
  cv.contextShader = cv.focusShader = ClearViewShader::Diffuse;
  cv.ambient = 1.f;
  cv.contextColor = glm::vec3(0.8f, 0.3f, 0.2f);
  cv.focusColor = glm::vec3(0.1f, 0.6f, 0.9f);
  Image image;
  compositeClearView(L, cv, frontCamera(), PointLight{}, 1.f, nullptr, image);
  glm::vec3 C(0.f);
  ASSERT_TRUE(clearViewFocusPoint(L, cv.focusPixel, C));
  auto display = [](glm::vec3 c) {
    for (int k = 0; k < 3; ++k)
      c[k] = c[k] <= 0.0031308f ? 12.92f * c[k] : 1.055f * std::pow(c[k], 1.f / 2.4f) - 0.055f;
    return c;
  };
  auto linear = [](glm::vec3 c) {
    for (int k = 0; k < 3; ++k)
      c[k] = c[k] <= 0.04045f ? c[k] / 12.92f : std::pow((c[k] + 0.055f) / 1.055f, 2.4f);
    return c;
  };
  const glm::vec3 cc = display(cv.contextColor), fc = display(cv.focusColor);
  int both = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float t0 = L.contextDepth[i], t1 = L.deeperContexts[0].depth[i], tf = L.focusDepth[i];
      if (!(t0 < kClearViewNoHit && t1 < kClearViewNoHit && tf < kClearViewNoHit)) continue;
      const float a0 = std::clamp(glm::length(C - L.contextPosition[i]) / cv.size, 0.f, 1.f);
      const float a1 =
          std::clamp(glm::length(C - L.deeperContexts[0].position[i]) / cv.size, 0.f, 1.f);
      const glm::vec3 want = linear(a0 * cc + (1.f - a0) * (a1 * cc + (1.f - a1) * fc));
      EXPECT_LT(glm::length(image.at(x, y) - want), 3e-3f) << x << "," << y;
      ++both;
    }
  EXPECT_GT(both, 100);
  // Without the deeper layer the same pixels show more of the focus.
  ClearViewLayers one;
  extract({&outer}, {&inner}, w, h, one);
  Image single;
  compositeClearView(one, cv, frontCamera(), PointLight{}, 1.f, nullptr, single);
  const size_t centre = size_t(h / 2) * w + size_t(w / 2);
  EXPECT_GT(single.pixels[centre].b - single.pixels[centre].r,
            image.pixels[centre].b - image.pixels[centre].r);
}

TEST(ClearViewLayers, TheEngineRendersAndCachesSeveralLayers) {
  Engine engine;
  engine.loadBuiltinScene("shepp-logan", 48);
  ClearViewSettings cv;
  cv.width = 96;
  cv.height = 96;
  const Volume& v = engine.volume();
  const double span = v.valueMax - v.valueMin;
  cv.context = {ClearViewLayerKind::Isosurface, v.valueMin + 0.05 * span, 0};
  cv.deeperContexts = {{ClearViewLayerKind::Isosurface, v.valueMin + 0.5 * span, 0}};
  cv.moreFoci = {{ClearViewLayerKind::Isosurface, v.valueMin + 0.9 * span, 0}};
  ClearViewStats st;
  const Image a = engine.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  ASSERT_EQ(st.deeperContextPixels.size(), 1u);
  EXPECT_GT(st.deeperContextPixels[0], 0);
  EXPECT_GT(st.focusPixels, 0);
  for (const glm::vec3& px : a.pixels) ASSERT_TRUE(std::isfinite(px.r + px.g + px.b));
  cv.size = 20.f;  // compositing only
  engine.renderClearView(cv, &st);
  EXPECT_FALSE(st.extracted);
  cv.deeperContexts.clear();  // a different set of layers: extracted again
  const Image b = engine.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  EXPECT_TRUE(st.deeperContextPixels.empty());
  cv.moreFoci.push_back({ClearViewLayerKind::ContextSurface, 0.0, 7});
  try {
    engine.renderClearView(cv, &st);
    ADD_FAILURE() << "a focus layer naming a missing context surface";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("focus 3"), std::string::npos) << e.what();
  }
}

TEST(ClearViewLayers, TooManyOrBadLayersAreRefusedByName) {
  ClearViewSettings cv;
  cv.deeperContexts.assign(size_t(kClearViewMaxLayers), ClearViewLayer{});
  EXPECT_THROW(checkClearViewSettings(cv), Error);
  cv.deeperContexts = {{ClearViewLayerKind::Importance, 2.0, 0}};
  try {
    checkClearViewSettings(cv);
    ADD_FAILURE() << "an importance level of 2";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("context 2"), std::string::npos) << e.what();
  }
  cv.deeperContexts.clear();
  cv.moreFoci = {{ClearViewLayerKind::Isosurface, std::nan(""), 0}};
  EXPECT_THROW(checkClearViewSettings(cv), Error);
}

}  // namespace
}  // namespace visopt
