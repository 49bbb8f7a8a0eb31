// ClearView (Krüger, Schneider, Westermann 2006): layer extraction against analytic spheres and
// planes, the curvature and distance measures against values computed from the exact geometry,
// the shaders against the paper's formulas evaluated by hand, and the Engine's reuse of layers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "clearview_fixtures.h"
#include "kernels/clearview_composite.h"
#include "kernels/clearview_shading.h"
#include "render/clearview.h"
#include "render/renderer.h"
#include "visopt/engine.h"
#include "visopt/error.h"
#include "visopt/frustum.h"
#include "visopt/scenes.h"
#include "visopt/transfer_function.h"

namespace visopt {
namespace {

struct Extracted {
  ClearViewLayers layers;
  Volume volume;
};

// Layers of `context` and `focus` (inside-high fields) seen by frontCamera at w x h.
void extract(const Field3D& context, const Field3D& focus, int w, int h, ClearViewLayers& out,
             const Camera& cam = frontCamera()) {
  Volume v = volumeOf(fieldOf([](glm::vec3) { return 0.f; }), -1.0, 1.0);
  DeviceBuffer<glm::vec4> transfer;
  const ClearViewSurfaceSource contexts[] = {{&context, 0.f, 1.f}}, foci[] = {{&focus, 0.f, 1.f}};
  extractClearViewLayers(v, transfer, cam, w, h, contexts, foci, false, out);
}

TEST(ClearViewExtraction, TheHitOnASphereLiesWithinATwentiethOfAVoxelOfTheExactOne) {
  const float r = 20.f;
  for (Precision prec : {Precision::FP32, Precision::FP16}) {
    const Field3D sphere = fieldOf([&](glm::vec3 x) { return ball(x, r); }, prec);
    ClearViewLayers L;
    const int w = 48, h = 40;
    extract(sphere, sphere, w, h, L);
    const Bounds bounds = cubeGrid().worldBounds();
    int hits = 0;
    float worst = 0.f, worstNormal = 0.f;
    for (int row = 0; row < h; ++row)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(row) * w + x;
        glm::vec3 exact(0.f);
        const bool expected = exactSphereHit(frontCamera(), bounds, w, h, x, row, r, exact);
        const bool got = L.contextDepth[i] < kClearViewNoHit;
        // Rays that graze the sphere within a voxel may go either way.
        if (expected != got) {
          const FrustumGrid f = FrustumGrid::forCamera(frontCamera(), w, h, bounds, 1, 1.f);
          const glm::vec3 d = f.rayDirection(float(x), float(h - 1 - row));
          const float miss = glm::length(glm::cross(-frontCamera().eye, d));  // ray to centre
          EXPECT_NEAR(miss, r, 1.f) << x << "," << row;
          continue;
        }
        if (!got) continue;
        ++hits;
        const glm::vec3 n = glm::normalize(exact);
        // Hits that graze the sphere are ill-conditioned along the ray; measure the distance
        // to the surface (what the tolerance of the issue means) and the normal.
        if (glm::dot(n, -glm::normalize(exact - frontCamera().eye)) < 0.2f) continue;
        worst = std::max(worst, std::abs(glm::length(L.contextPosition[i]) - r));
        worstNormal = std::max(worstNormal, glm::length(L.contextNormal[i] - n));
      }
    EXPECT_GT(hits, 400);
    EXPECT_LT(worst, 0.05f) << toString(prec);
    EXPECT_LT(worstNormal, 0.01f) << toString(prec);
  }
}

TEST(ClearViewExtraction, AFieldWithoutTheSurfaceGivesNoHitsAndNoNaN) {
  const Field3D empty = fieldOf([](glm::vec3) { return -1.f; });
  ClearViewLayers L;
  extract(empty, empty, 16, 16, L);
  EXPECT_EQ(L.contextPixels, 0);
  EXPECT_EQ(L.focusPixels, 0);
  for (size_t i = 0; i < 256; ++i) {
    EXPECT_GE(L.contextDepth[i], kClearViewNoHit);
    EXPECT_EQ(L.contextNormal[i], glm::vec3(0.f));
  }
}

TEST(ClearViewCurvature, APlaneIsFlatAndItsSilhouetteIsMaximal) {
  // The slab y <= 0 (inside high), seen from the front: every ray that meets the box hits it.
  const Field3D plane = fieldOf([](glm::vec3 x) { return -x.y; });
  ClearViewLayers L;
  const int w = 40, h = 40;
  Camera cam = frontCamera();
  cam.fovYDegrees = 50.f;  // wider than the box: some rays miss it
  extract(plane, plane, w, h, L, cam);
  int flat = 0, rim = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if (!(L.contextDepth[i] < kClearViewNoHit)) continue;
      int missing = 0;
      const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4; ++k) {
        const int qx = x + dx[k], qy = y + dy[k];
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        missing += !(L.contextDepth[size_t(qy) * w + qx] < kClearViewNoHit);
      }
      const float c = clearViewCurvature(L.contextNormal.data(), L.contextDepth.data(), w, h, x, y);
      if (missing == 0) {
        EXPECT_NEAR(c, 0.f, 1e-4f) << x << "," << y;
        ++flat;
      } else {
        EXPECT_NEAR(c, 2.f * float(missing), 1e-4f) << x << "," << y;  // each empty one counts 2
        ++rim;
      }
    }
  EXPECT_GT(flat, 200);
  EXPECT_GT(rim, 10);
}

TEST(ClearViewCurvature, OnASphereItIsTheSumOfTheExactNormalsDifferences) {
  const float r = 24.f;
  const Field3D sphere = fieldOf([&](glm::vec3 x) { return ball(x, r); });
  ClearViewLayers L;
  const int w = 48, h = 48;
  extract(sphere, sphere, w, h, L);
  const Bounds bounds = cubeGrid().worldBounds();
  auto exactNormal = [&](int x, int y, glm::vec3& n) {
    glm::vec3 p;
    if (!exactSphereHit(frontCamera(), bounds, w, h, x, y, r, p)) return false;
    n = glm::normalize(p);
    return true;
  };
  int checked = 0;
  for (int y = 1; y < h - 1; ++y)
    for (int x = 1; x < w - 1; ++x) {
      glm::vec3 n(0.f), q(0.f);
      if (!exactNormal(x, y, n)) continue;
      float expected = 0.f;
      bool all = true;
      const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4 && all; ++k) {
        all = exactNormal(x + dx[k], y + dy[k], q);
        if (all) expected += glm::length(n - q);
      }
      // Away from the silhouette (where a neighbour's hit is ill-conditioned).
      if (!all || glm::dot(n, -glm::normalize(frontCamera().target - frontCamera().eye)) < 0.5f)
        continue;
      const float c = clearViewCurvature(L.contextNormal.data(), L.contextDepth.data(), w, h, x, y);
      EXPECT_NEAR(c, expected, 0.02f) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 300);
}

// Two concentric spheres: the context of radius 24 outside, the focus of radius 12 inside.
struct Concentric {
  Field3D outer = fieldOf([](glm::vec3 x) { return ball(x, 24.f); });
  Field3D inner = fieldOf([](glm::vec3 x) { return ball(x, 12.f); });
};

ClearViewCompositeParams paramsFor(const ClearViewLayers& L) {
  ClearViewCompositeParams p;
  p.width = L.width;
  p.height = L.height;
  p.layers = L.view();
  p.eye = frontCamera().eye;
  return p;
}

TEST(ClearViewMeasures, TheDistanceMeasuresEqualTheRadialGapAndTheRayGap) {
  Concentric s;
  ClearViewLayers L;
  const int w = 48, h = 48;
  extract(s.outer, s.inner, w, h, L);
  const Bounds bounds = cubeGrid().worldBounds();
  ClearViewCompositeParams p = paramsFor(L);
  p.hasFocusPoint = true;
  p.weight = 1.f;
  p.invDistance = 1.f / 100.f;  // opacity = distance / 100 where the focus point is at P
  int both = 0, outerOnly = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if (!(L.contextDepth[i] < kClearViewNoHit)) continue;
      glm::vec3 po(0.f);
      ASSERT_TRUE(exactSphereHit(frontCamera(), bounds, w, h, x, y, 24.f, po) ||
                  glm::length(L.contextPosition[i]) > 23.f);
      p.focusPoint = L.contextPosition[i];  // the distance term is 0 here
      // §3.2.2: along the inward normal of a sphere lies the centre, so the inner sphere is
      // met after exactly the radial gap of 12.
      p.measure = ClearViewMeasureKind::Distance;
      EXPECT_NEAR(L.normalDistance[i], 12.f, 0.05f) << x << "," << y;
      EXPECT_NEAR(clearViewContextOpacity(p, 0, x, y), L.normalDistance[i] / 100.f, 1e-6f);
      // §3.2.3: along the view ray, the gap between the two exact hits where the ray meets
      // both; opaque (1) where it misses the focus.
      p.measure = ClearViewMeasureKind::ViewDistance;
      glm::vec3 pi(0.f);
      if (exactSphereHit(frontCamera(), bounds, w, h, x, y, 12.f, pi) &&
          L.focusDepth[i] < kClearViewNoHit) {
        // Each hit within 0.05 voxel of its sphere; along a ray that meets a sphere at a
        // grazing angle that is a longer way, so those rays are left out.
        const glm::vec3 ray = glm::normalize(pi - frontCamera().eye);
        if (-glm::dot(ray, glm::normalize(pi)) < 0.5f || -glm::dot(ray, glm::normalize(po)) < 0.5f)
          continue;
        const float gap = glm::length(pi - frontCamera().eye) - glm::length(po - frontCamera().eye);
        EXPECT_NEAR(clearViewContextOpacity(p, 0, x, y), gap / 100.f, 0.2f / 100.f);
        ++both;
      } else if (!(L.focusDepth[i] < kClearViewNoHit)) {
        EXPECT_EQ(clearViewContextOpacity(p, 0, x, y), 1.f);
        ++outerOnly;
      }
    }
  EXPECT_GT(both, 150);
  EXPECT_GT(outerOnly, 100);
}

TEST(ClearViewCompositing, TheBorderIsExactlyThePixelsAtZeroNinetyFiveToOneSize) {
  Concentric s;
  ClearViewLayers L;
  const int w = 64, h = 64;
  extract(s.outer, s.inner, w, h, L);
  ClearViewSettings cv;
  cv.width = w;
  cv.height = h;
  cv.size = 15.f;
  cv.contextShader = cv.focusShader = ClearViewShader::Diffuse;
  cv.ambient = 1.f;  // unshaded: the border's darkening is the only difference
  glm::vec3 C(0.f);
  ASSERT_TRUE(clearViewFocusPoint(L, cv.focusPixel, C));
  EXPECT_NEAR(glm::length(C), 12.f, 0.05f);  // the centre pixel projected onto the focus
  const Camera cam = frontCamera();
  const PointLight light;
  cv.border = false;
  Image plain, ringed;
  compositeClearView(L, cv, cam, light, 1.f, nullptr, plain);
  cv.border = true;
  compositeClearView(L, cv, cam, light, 1.f, nullptr, ringed);
  int ring = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const bool front =
          L.contextDepth[i] < kClearViewNoHit && !(L.focusDepth[i] < L.contextDepth[i]);
      const float d = front ? glm::length(C - L.contextPosition[i]) / cv.size : -1.f;
      const bool inRing = d >= 0.95f && d <= 1.f;
      const bool darker = glm::length(ringed.at(x, y)) < glm::length(plain.at(x, y)) - 1e-6f;
      EXPECT_EQ(darker, inRing) << x << "," << y << " d " << d;
      ring += inRing;
    }
  EXPECT_GT(ring, 20);
}

TEST(ClearViewShaders, BoneAndSkinEqualThePapersFormulasForHandPickedVectors) {
  const glm::vec3 z(0.f, 0.f, 1.f), x(1.f, 0.f, 0.f);
  const ClearViewLut bone = clearViewBoneLut(), skin = clearViewSkinLut();
  // Facing, headlight: A = 1, B = 0.4, C = 0 -> LUT(0.6).
  EXPECT_EQ(clearViewBone(z, z, z), bone.at(0.6f));
  // Silhouette (N . V = 0), headlight: A = 0.5, B = 0.4, C = 0.4 * 0.5 = 0.2 -> LUT(0.3 + 0.1).
  EXPECT_EQ(clearViewBone(x, z, z), bone.at(0.4f));
  // Facing, headlight: A = 0.95, B = 0.2, R = V so B' = 1, C = 0.6, D = 0, no red shift.
  ClearViewSkinTerms t = clearViewSkinTerms(z, z, z);
  EXPECT_FLOAT_EQ(t.A, 0.95f);
  EXPECT_FLOAT_EQ(t.B, 0.2f);
  EXPECT_FLOAT_EQ(t.Bprime, 1.f);
  EXPECT_FLOAT_EQ(t.C, 0.6f);
  EXPECT_FLOAT_EQ(t.D, 0.f);
  EXPECT_EQ(t.redShift, 0.f);
  const glm::vec3 expected =
      0.8f * skin.at(0.95f) + 0.25f * 0.f * skin.at(0.6f) + 0.15f * skin.at(0.f) + glm::vec3(0.1f);
  const glm::vec3 got = clearViewSkin(z, z, z);
  EXPECT_NEAR(got.r, expected.r, 1e-6f);
  EXPECT_NEAR(got.g, expected.g, 1e-6f);
  EXPECT_NEAR(got.b, expected.b, 1e-6f);
  // Light from the side, viewer in front, N at 45 degrees between them: N.L = N.V = 0.7071,
  // L.V = 0, R = 2 (N.V) N - V = L, so B' = 1; A = 0.5 * 0.7071 + 0.45.
  const glm::vec3 n = glm::normalize(glm::vec3(1.f, 0.f, 1.f));
  t = clearViewSkinTerms(n, x, z);
  EXPECT_NEAR(t.A, 0.5f * 0.70710678f + 0.45f, 1e-6f);
  EXPECT_NEAR(t.B, 0.6f, 1e-6f);
  EXPECT_NEAR(t.Bprime, 1.f, 1e-5f);
  EXPECT_NEAR(t.C, 0.8f, 1e-5f);
  const float s3 = std::pow(1.f - 0.70710678f, 3.f);
  EXPECT_NEAR(t.D, 0.9f * s3, 1e-6f);
}

TEST(ClearViewShaders, TheRedShiftAppliesOnlyWhereASkinIsAtMostHalf) {
  const glm::vec3 z(0.f, 0.f, 1.f);
  // A = 0.5 L.N + 0.45: L.N = 0.2 gives A = 0.55 (no shift), L.N = 0.1 gives A = 0.5 (the
  // boundary, a shift of 0), L.N = -0.3 gives A = 0.3 (a shift of 0.4).
  auto lightAt = [](float ln) { return glm::vec3(std::sqrt(1.f - ln * ln), 0.f, ln); };
  EXPECT_EQ(clearViewSkinTerms(z, lightAt(0.2f), z).redShift, 0.f);
  EXPECT_NEAR(clearViewSkinTerms(z, lightAt(0.1f), z).redShift, 0.f, 1e-6f);
  EXPECT_NEAR(clearViewSkinTerms(z, lightAt(-0.3f), z).redShift, 0.4f, 1e-6f);
  // The shift makes the diffuse part redder: green and blue fall against red.
  const glm::vec3 shadowed = clearViewSkin(z, lightAt(-0.3f), z);
  const ClearViewSkinTerms t = clearViewSkinTerms(z, lightAt(-0.3f), z);
  const ClearViewLut lut = clearViewSkinLut();
  // N.V = 1: the side term (1 - N.V) LUT(C) is 0.
  const glm::vec3 unshifted = 0.8f * lut.at(t.A) + 0.15f * lut.at(t.D) + glm::vec3(0.1f * t.Bprime);
  EXPECT_NEAR(shadowed.r, unshifted.r, 1e-6f);
  EXPECT_LT(shadowed.g, unshifted.g - 0.01f);
  EXPECT_LT(shadowed.b, unshifted.b - 0.01f);
}

// ---- through the Engine ----------------------------------------------------------------------

TEST(ClearViewEngine, CompositingOnlyChangesDoNotExtractAgain) {
  Engine e;
  e.loadBuiltinScene("shepp-logan", 32, true);
  ClearViewSettings cv;
  cv.width = 64;
  cv.height = 48;
  cv.context = {ClearViewLayerKind::ContextSurface, 0.0, 0};
  ClearViewStats st;
  const Image first = e.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  EXPECT_EQ(st.extractions, 1);
  EXPECT_EQ(first.width, 64);
  EXPECT_EQ(first.height, 48);
  // The hotspot, its size, the measure, the shaders, the weight, the border and the light.
  const std::vector<std::function<void(ClearViewSettings&)>> compositing = {
      [](ClearViewSettings& s) {
        s.focusPixel = {10.f, 20.f};
      },
      [](ClearViewSettings& s) { s.size = 30.f; },
      [](ClearViewSettings& s) { s.measure = ClearViewMeasure::Distance; },
      [](ClearViewSettings& s) { s.measure = ClearViewMeasure::ViewDistance; },
      [](ClearViewSettings& s) { s.contextShader = ClearViewShader::CoolWarm; },
      [](ClearViewSettings& s) { s.focusShader = ClearViewShader::Diffuse; },
      [](ClearViewSettings& s) { s.weight = 0.5f; },
      [](ClearViewSettings& s) { s.border = false; },
      [](ClearViewSettings& s) { s.headlight = false; },
  };
  for (const auto& change : compositing) {
    change(cv);
    e.renderClearView(cv, &st);
    EXPECT_FALSE(st.extracted);
    EXPECT_EQ(st.extractions, 1);
  }
  PointLight light = e.light();
  light.position += glm::vec3(5.f);
  e.setLight(light);
  e.renderClearView(cv, &st);
  EXPECT_FALSE(st.extracted) << "the light is compositing only";
  // The camera, the image size, a layer, the transfer function: extracted again.
  e.orbitCamera(30.f, 10.f, 3.f);
  e.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  cv.width = 32;
  e.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  cv.focus.isovalue = 0.3;
  e.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  e.setTransferFunction(e.transferFunction());
  e.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
  e.renderClearView(cv, &st);
  EXPECT_FALSE(st.extracted);
  EXPECT_EQ(st.extractions, 5);
  // The optimisation moves the context surface: the layers follow it.
  e.setViewportSize(32, 48);
  e.continueOptimization(1);
  e.renderClearView(cv, &st);
  EXPECT_TRUE(st.extracted);
}

// An Engine on a radial volume: value 1 - r / 40 (clamped), so the isosurface at 0.4 is the
// sphere of radius 24 and the one at 0.7 that of radius 12.
void loadRadialScene(Engine& e) {
  e.setVolume(volumeOf(
      fieldOf([](glm::vec3 x) { return std::clamp(1.f - glm::length(x) / 40.f, 0.f, 1.f); }), 0.0,
      1.0));
  Camera cam = frontCamera();
  e.setCamera(cam);
}

TEST(ClearViewEngine, AFocusThatIsNeverHitLeavesTheContextOpaqueAndFinite) {
  Engine e;
  loadRadialScene(e);
  e.setImportanceCurve({{0.0, 0.0}, {1.0, 0.5}});  // g never reaches 1
  ClearViewSettings cv;
  cv.width = cv.height = 48;
  cv.context = {ClearViewLayerKind::Isosurface, 0.4, 0};
  cv.focus = {ClearViewLayerKind::Importance, 1.0, 0};
  ClearViewStats st;
  const Image withHotspot = e.renderClearView(cv, &st);
  EXPECT_EQ(st.focusPixels, 0);
  EXPECT_FALSE(st.hasFocusPoint);
  EXPECT_GT(st.contextPixels, 500);
  // Opaque: the same image as with a weight that saturates every context pixel.
  cv.weight = 1e6f;
  cv.border = false;
  const Image opaque = e.renderClearView(cv, &st);
  for (size_t i = 0; i < withHotspot.pixels.size(); ++i) {
    ASSERT_TRUE(
        std::isfinite(withHotspot.pixels[i].r + withHotspot.pixels[i].g + withHotspot.pixels[i].b));
    EXPECT_EQ(withHotspot.pixels[i], opaque.pixels[i]);
  }
}

TEST(ClearViewEngine, TheHotspotOpensTheContextOverTheFocus) {
  Engine e;
  loadRadialScene(e);
  ClearViewSettings cv;
  cv.width = cv.height = 64;
  cv.context = {ClearViewLayerKind::Isosurface, 0.4, 0};  // radius 24
  cv.focus = {ClearViewLayerKind::Isosurface, 0.7, 0};    // radius 12
  cv.contextShader = cv.focusShader = ClearViewShader::Diffuse;
  cv.ambient = 1.f;  // unshaded colours
  cv.contextColor = glm::vec3(1.f, 0.f, 0.f);
  cv.focusColor = glm::vec3(1.f);
  cv.border = false;
  cv.weight = 0.f;  // the distance term alone
  cv.size = 24.f;
  ClearViewStats st;
  const Image img = e.renderClearView(cv, &st);
  ASSERT_TRUE(st.hasFocusPoint);
  EXPECT_NEAR(glm::length(st.focusPoint), 12.f, 0.05f);
  // At the focus pixel the context (12 from C) is half transparent: red 1, green 0.5 in
  // display values, decoded to linear light.
  const glm::vec3 centre = img.at(32, 32);
  const float d = glm::length(st.focusPoint - glm::vec3(0.f, -24.f, 0.f));  // roughly 12
  EXPECT_GT(d, 11.f);
  EXPECT_NEAR(centre.r, 1.f, 1e-3f);
  EXPECT_GT(centre.g, 0.1f);
  // A hotspot too small to reach the context leaves it opaque red.
  cv.size = 1e-3f;
  const Image closed = e.renderClearView(cv, &st);
  EXPECT_FALSE(st.extracted);
  EXPECT_NEAR(closed.at(32, 32).r, 1.f, 1e-3f);
  EXPECT_LT(closed.at(32, 32).g, 1e-3f);
}

TEST(ClearViewEngine, Fp16AndFp32LayersGiveTheSameImage) {
  Image images[2];
  int n = 0;
  for (Precision prec : {Precision::FP32, Precision::FP16}) {
    Engine e(prec);
    e.loadBuiltinScene("shepp-logan", 64, true);
    ClearViewSettings cv;
    cv.width = cv.height = 96;
    cv.context = {ClearViewLayerKind::ContextSurface, 0.0, 0};
    images[n++] = e.renderClearView(cv);
  }
  // Measured 73 dB (the layers are fp32 either way; fp16 is the storage of the fields they are
  // extracted from: the volume and the SDF).
  EXPECT_GT(psnr(images[0], images[1]), 60.0);
}

TEST(ClearViewEngine, BadSettingsAndMissingLayersAreUsageErrors) {
  Engine e;
  ClearViewSettings cv;
  EXPECT_THROW(e.renderClearView(cv), Error);  // no volume
  e.loadBuiltinScene("shepp-logan", 32, true);
  auto usage = [&](const ClearViewSettings& s) {
    try {
      e.renderClearView(s);
      ADD_FAILURE() << "no error";
    } catch (const Error& err) {
      EXPECT_EQ(err.kind(), ErrorKind::Usage) << err.what();
    }
  };
  ClearViewSettings s = cv;
  s.context = {ClearViewLayerKind::ContextSurface, 0.0, 3};
  usage(s);
  s = cv;
  s.context = {ClearViewLayerKind::Isosurface, e.volume().valueMax + 1.0, 0};
  usage(s);
  s = cv;
  s.size = std::nanf("");
  usage(s);
  s = cv;
  s.width = 0;
  usage(s);
  s = cv;
  s.focus = {ClearViewLayerKind::Importance, 0.0, 0};
  usage(s);
  s = cv;
  s.ambient = 2.f;
  usage(s);
}

}  // namespace
}  // namespace visopt

namespace visopt {
namespace {

// The distance from point p to the half-line from `eye` through `q`.
float distanceToRay(glm::vec3 p, glm::vec3 eye, glm::vec3 q) {
  const glm::vec3 d = q - eye;
  const float t = std::max(glm::dot(p - eye, d) / glm::dot(d, d), 0.f);
  return glm::length(p - (eye + t * d));
}

TEST(ClearViewHotspotImportance, TheBallIsOneInsideHalfTheRadiusAndFallsSmoothlyToZero) {
  Engine e;
  loadRadialScene(e);
  const glm::vec3 c(4.f, -3.f, 2.f);
  const float r = 10.f;
  e.setImportanceHotspot(c, r);
  EXPECT_EQ(e.importanceSource().kind, ImportanceKind::Hotspot);
  const Field3D& g = *e.importance();
  const GridSpec& grid = g.grid();
  for (size_t v = 0; v < g.size(); ++v) {
    const int i = int(v % size_t(kN)), j = int(v / size_t(kN) % size_t(kN)),
              k = int(v / size_t(kN * kN));
    const float d = glm::length(grid.indexToWorld(glm::vec3(i, j, k)) - c);
    const float x = std::clamp((r - d) / (0.5f * r), 0.f, 1.f);
    ASSERT_NEAR(g.get(v), x * x * (3.f - 2.f * x), 1e-6f) << v;
  }
  EXPECT_EQ(g.get(grid.linearIndex(kN / 2 + 4, kN / 2 - 3, kN / 2 + 2)), 1.f);  // within r / 2
  EXPECT_THROW(e.setImportanceHotspot(c, 0.f), Error);
  EXPECT_THROW(e.setImportanceHotspot(glm::vec3(std::nanf("")), 1.f), Error);
}

// Paper 000's optimisation driven by the hotspot: what lies in the ball becomes visible, and mu
// stays mu_bar on every voxel whose view ray and light ray do not go on to pass the ball (where g =
// 0 and nothing important lies behind, the gradient rho (mu - mu_bar) - q (g T_V - G_V) is 0).
TEST(ClearViewHotspotImportance, TheOptimisationOpensTheBallAndLeavesTheRestAlone) {
  Engine e;
  e.loadBuiltinScene("shepp-logan", 48, false);
  e.setViewportSize(48, 48);
  ExtinctionSettings s = e.extinctionSettings();
  s.levels = 1;
  s.maxIterationsPerLevel = 25;
  e.setExtinctionSettings(s);
  const Bounds b = e.volume().grid().worldBounds();
  const glm::vec3 c = b.center() + 0.15f * (b.hi - b.lo) * glm::vec3(0.3f, 0.f, 0.2f);
  const float r = 0.12f * glm::length(b.hi - b.lo);
  e.setImportanceHotspot(c, r);
  const std::vector<IterationStats> stats = e.optimize();
  ASSERT_GT(stats.size(), 2u);
  // V of the ball's matter: 0.002 at mu_bar (the skull and brain hide it), 0.19 after 25
  // iterations (what remains hidden is the ball's own back behind its front).
  EXPECT_GT(stats.back().visibilityView, 20.0 * stats.front().visibilityView);

  // mu - mu_bar per voxel, as the renderer computes it.
  const TransferTable table = e.transferFunction().bake(e.volume().valueMin, e.volume().valueMax,
                                                        e.volume().grid().minSpacing(), 1024);
  DeviceBuffer<glm::vec4> transfer(table.albedoExtinction.size());
  for (size_t i = 0; i < transfer.size(); ++i) transfer[i] = table.albedoExtinction[i];
  Field3D change("change", e.volume().grid(), Precision::FP32);
  computeExtinctionChange(e.volume(), transfer, *e.optimizedExtinction(), change);
  const GridSpec& grid = e.volume().grid();
  const glm::vec3 eye = e.camera().eye, light = e.light().position;
  double maxAway = 0.0, maxNear = 0.0;
  int away = 0;
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const glm::vec3 p = grid.indexToWorld(glm::vec3(i, j, k));
        const double dmu = std::abs(change.get(grid.linearIndex(i, j, k)));
        // Five voxels of margin beyond the ball's shadow: the gather of the gradient from the
        // frustum's cells to the voxels and the smooth ball's tail (measured: changes up to 0.02
        // of the largest extinction reach 4-5 voxels beyond r, none farther).
        // The default weights optimise from the light too (r = q): its rays to the ball count.
        const float margin = r + 5.f * grid.minSpacing();
        if (distanceToRay(c, eye, p) > margin && distanceToRay(c, light, p) > margin) {
          maxAway = std::max(maxAway, dmu);
          ++away;
        } else {
          maxNear = std::max(maxNear, dmu);
        }
      }
  EXPECT_GT(away, 1000);
  EXPECT_GT(maxNear, 0.0);
  EXPECT_LE(maxAway, 1e-3 * table.maxExtinction) << "largest change near the ball " << maxNear;
}

}  // namespace
}  // namespace visopt

namespace visopt {
namespace {

// The volume layer keeps its colour edges (the high-pass of §3.1) and fades elsewhere about C.
TEST(ClearViewCompositing, TheVolumeLayerFadesAboutTheFocusPointButKeepsItsEdges) {
  Concentric s;
  ClearViewLayers L;
  const int w = 32, h = 32;
  extract(s.outer, s.inner, w, h, L);
  L.volume = DeviceBuffer<glm::vec4>(size_t(w) * h);
  // A uniform grey veil with a vertical stripe of red in columns 20..21.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      L.volume[size_t(y) * w + x] = x == 20 || x == 21 ? glm::vec4(0.5f, 0.f, 0.f, 0.5f)
                                                       : glm::vec4(0.25f, 0.25f, 0.25f, 0.5f);
  EXPECT_FLOAT_EQ(clearViewColorEdges(L.volume.data(), w, h, 5, 5), 0.f);
  const float edge = glm::length(glm::vec3(0.5f, 0.f, 0.f) - glm::vec3(0.25f));
  EXPECT_NEAR(clearViewColorEdges(L.volume.data(), w, h, 19, 5), edge, 1e-6f);
  EXPECT_NEAR(clearViewColorEdges(L.volume.data(), w, h, 20, 5), edge, 1e-6f);  // 21 is alike
  ClearViewSettings cv;
  cv.width = w;
  cv.height = h;
  cv.size = 1000.f;  // the whole image near the focus point: only the edges keep the veil
  cv.border = false;
  cv.contextShader = cv.focusShader = ClearViewShader::Diffuse;
  cv.ambient = 1.f;
  cv.contextColor = cv.focusColor = cv.background = glm::vec3(0.f);  // black behind the veil
  cv.weight = 10.f;
  Image img;
  compositeClearView(L, cv, frontCamera(), PointLight{}, 1.f, nullptr, img);
  EXPECT_LT(img.at(5, 16).r, 0.01f);   // faded: the black behind shows
  EXPECT_GT(img.at(20, 16).r, 0.1f);   // an edge of the veil: kept (red)
  EXPECT_GT(img.at(19, 16).g, 0.01f);  // the grey next to it, an edge too
}

}  // namespace
}  // namespace visopt
