// The workstation's render overlays (RenderSettings::importanceOverlay, worldMaskOverlay): an
// overlay changes exactly the pixels whose rays pass through important (g > 0) or masked
// voxels, compared with a render without it, and an overlay that is off (0, or no mask) leaves
// the image bit-identical. Which rays pass near a ball at the view target follows from the
// pinhole geometry alone: a pixel's ray misses the target by D sin(angle to the axis).
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "render_fixtures.h"
#include "visopt/bit_mask.h"
#include "visopt/engine.h"
#include "visopt/session.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

constexpr int kN = 33;        // voxels per side (unit spacing, centred at the origin)
constexpr int kSize = 48;     // image pixels per side
constexpr float kD = 60.f;    // camera distance to the origin
constexpr float kBall = 5.f;  // radius of the important / masked ball about the origin

// Distance from the origin (the view target) to pixel (x, y)'s ray; symmetric in the image,
// so the row direction does not matter.
float rayMiss(int x, int y, float fovYDegrees) {
  const float tanY = std::tan(0.5f * fovYDegrees * 3.14159265f / 180.f);
  const float u = ((float(x) + 0.5f) / kSize * 2.f - 1.f) * tanY;  // square image: tanX = tanY
  const float v = ((float(y) + 0.5f) / kSize * 2.f - 1.f) * tanY;
  const float tanAngle = std::sqrt(u * u + v * v);
  return kD * std::sin(std::atan(tanAngle));
}

bool identical(const Image& a, const Image& b) {
  return a.pixels.size() == b.pixels.size() &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(glm::vec3)) == 0;
}

float difference(glm::vec3 a, glm::vec3 b) {
  const glm::vec3 d = glm::abs(a - b);
  return d.x + d.y + d.z;
}

// A foggy cube (constant extinction and albedo whatever the scalar) whose scalars are 1 in the
// voxels within kBall of the origin and 0.5 elsewhere; seen obliquely from distance kD.
void foggyScene(Engine& e) {
  Volume v = homogeneousCube(kN);
  const GridSpec& g = v.grid();
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i)
        if (glm::length(g.indexToWorld(glm::vec3(float(i), float(j), float(k)))) <= kBall)
          v.normalized.set(g.linearIndex(i, j, k), 1.f);
  e.setVolume(std::move(v));
  e.setTransferFunction(constantTransferFunction(0.05f, glm::vec3(0.3f, 0.6f, 0.9f)));
  e.setCamera(Camera::orbit(glm::vec3(0.f), 30.f, 20.f, kD));
  e.setLight(PointLight::keyLightFor(e.camera(), e.volume().grid().worldBounds()));
}

RenderSettings settings() {
  RenderSettings s;
  s.width = s.height = kSize;
  return s;
}

// Voxels whose centres lie within `radius` of `centre`.
BitMask ballMask(const GridSpec& g, glm::vec3 centre, float radius) {
  BitMask m = BitMask::cleared(g.dims);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i)
        if (glm::length(g.indexToWorld(glm::vec3(float(i), float(j), float(k))) - centre) <= radius)
          m.set(g.linearIndex(i, j, k), true);
  return m;
}

}  // namespace

TEST(RenderOverlays, ImportanceOverlayTintsOnlyRaysThroughImportance) {
  Engine e;
  foggyScene(e);
  // g = 0 up to the value 0.75 and 1 from 0.9: only where the interpolated scalar sees a ball
  // voxel, i.e. within kBall + sqrt(3) of the origin.
  e.setImportanceCurve({{0.0, 0.0}, {0.75, 0.0}, {0.9, 1.0}, {1.0, 1.0}});
  RenderSettings rs = settings();
  const Image base = e.render(rs);
  rs.importanceOverlay = 0.f;
  EXPECT_TRUE(identical(e.render(rs), base)) << "overlay 0 must not change a bit";
  rs.importanceOverlay = -2.f;
  EXPECT_TRUE(identical(e.render(rs), base)) << "a negative overlay is off";

  rs.importanceOverlay = 1.f;
  const Image full = e.render(rs);
  rs.importanceOverlay = 0.5f;
  const Image half = e.render(rs);
  const float fov = e.camera().fovYDegrees;
  int checkedSame = 0, checkedChanged = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float miss = rayMiss(x, y, fov);
      if (miss > kBall + 2.5f) {
        ASSERT_EQ(full.at(x, y), base.at(x, y)) << "pixel " << x << "," << y << " miss " << miss;
        ++checkedSame;
      } else if (miss < kBall - 2.f) {
        const float d = difference(full.at(x, y), base.at(x, y));
        EXPECT_GT(d, 0.02f * difference(base.at(x, y), glm::vec3(0.f)))
            << "pixel " << x << "," << y << " miss " << miss;
        // Half the overlay moves the colour part of the way.
        EXPECT_LT(difference(half.at(x, y), base.at(x, y)), d) << x << "," << y;
        EXPECT_GT(difference(half.at(x, y), base.at(x, y)), 0.f) << x << "," << y;
        // Towards the (orange) highlight: less blue relative to red than the fog's albedo.
        EXPECT_GT(full.at(x, y).x / full.at(x, y).z, base.at(x, y).x / base.at(x, y).z);
        ++checkedChanged;
      }
    }
  EXPECT_GT(checkedSame, kSize * kSize / 2);
  EXPECT_GT(checkedChanged, 20);
}

TEST(RenderOverlays, ImportanceOverlayWithoutImportanceChangesNothing) {
  Engine e;
  foggyScene(e);
  RenderSettings rs = settings();
  const Image base = e.render(rs);
  rs.importanceOverlay = 1.f;
  EXPECT_TRUE(identical(e.render(rs), base));
}

TEST(RenderOverlays, WorldMaskOverlayTintsOnlyRaysThroughMaskedVoxels) {
  Engine e;
  foggyScene(e);
  RenderSettings rs = settings();
  const Image base = e.render(rs);
  rs.worldMaskOverlay = true;
  EXPECT_TRUE(identical(e.render(rs), base)) << "no mask: nothing to tint";

  e.setWorldMask(ballMask(e.volume().grid(), glm::vec3(0.f), kBall));
  rs.worldMaskOverlay = false;
  EXPECT_TRUE(identical(e.render(rs), base)) << "a mask alone must not change the image";
  rs.worldMaskOverlay = true;
  const Image over = e.render(rs);
  const float fov = e.camera().fovYDegrees;
  int same = 0, changed = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float miss = rayMiss(x, y, fov);
      // A sample is tinted when its nearest voxel is masked: within kBall + sqrt(3)/2.
      if (miss > kBall + 1.5f) {
        ASSERT_EQ(over.at(x, y), base.at(x, y)) << "pixel " << x << "," << y << " miss " << miss;
        ++same;
      } else if (miss < kBall - 2.f) {
        EXPECT_GT(difference(over.at(x, y), base.at(x, y)),
                  0.02f * difference(base.at(x, y), glm::vec3(0.f)))
            << "pixel " << x << "," << y;
        // Magenta: red up relative to green.
        EXPECT_GT(over.at(x, y).x / over.at(x, y).y, base.at(x, y).x / base.at(x, y).y);
        ++changed;
      }
    }
  EXPECT_GT(same, kSize * kSize / 2);
  EXPECT_GT(changed, 20);
}

// A grey context sphere of radius 8 in clear air; the mask is a ball of radius 3 on the sphere's
// point facing the camera. Only the surface around the image centre turns magenta.
TEST(RenderOverlays, WorldMaskOverlayTintsSurfacesInTheMask) {
  Engine e;
  e.setVolume(homogeneousCube(kN));
  e.setTransferFunction(constantTransferFunction(0.f, glm::vec3(1.f)));
  const Camera cam = Camera::orbit(glm::vec3(0.f), 30.f, 20.f, kD);
  e.setCamera(cam);
  PointLight light;
  light.position = cam.eye;
  light.intensity = 3.f;
  e.setLight(light);
  const GridSpec& g = e.volume().grid();
  Field3D sdf("sphere", g, Precision::FP32);
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i)
        sdf.set(g.linearIndex(i, j, k),
                glm::length(g.indexToWorld(glm::vec3(float(i), float(j), float(k)))) - 8.f);
  ContextSurfaceSpec spec;
  spec.source = "test:sphere";
  spec.color = glm::vec3(0.7f);
  e.addContextSurface(spec, sdf);
  const glm::vec3 front = 8.f * glm::normalize(cam.eye);
  e.setWorldMask(ballMask(g, front, 3.f));

  RenderSettings rs = pureSingleScattering(kSize);
  rs.surfaceSpecular = 0.f;
  rs.ambientOcclusion = false;
  const Image base = e.render(rs);
  rs.worldMaskOverlay = true;
  const Image over = e.render(rs);
  int same = 0, changed = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float miss = rayMiss(x, y, cam.fovYDegrees);
      if (miss > 5.5f) {
        ASSERT_EQ(over.at(x, y), base.at(x, y)) << "pixel " << x << "," << y << " miss " << miss;
        ++same;
      } else if (miss < 1.5f) {
        // 40 % towards magenta from grey 0.7: red up by a factor 0.82 / 0.7, green down to 0.6.
        EXPECT_NEAR(over.at(x, y).x / base.at(x, y).x, 0.82f / 0.7f, 0.01f) << x << "," << y;
        EXPECT_NEAR(over.at(x, y).y / base.at(x, y).y, 0.6f, 0.01f) << x << "," << y;
        ++changed;
      }
    }
  EXPECT_GT(same, kSize * kSize / 2);
  EXPECT_GT(changed, 4);
}

TEST(RenderOverlays, SessionStoresOverlaysOnlyWhenOn) {
  Session s;
  s.builtinScene = "shepp-logan";
  std::string json = sessionToJson(s);
  EXPECT_EQ(json.find("Overlay"), std::string::npos) << json;
  s.render.importanceOverlay = 0.25f;
  s.render.worldMaskOverlay = true;
  json = sessionToJson(s);
  const Session back = sessionFromJson(json, "overlays.json");
  EXPECT_EQ(back.render.importanceOverlay, 0.25f);
  EXPECT_TRUE(back.render.worldMaskOverlay);
}
