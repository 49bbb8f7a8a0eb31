// The comparison baselines of Fig. 10 as Himmler & Günther 2026, §IV-A defines them, each against
// its defining property:
//  - cut-away: the context surface is absent exactly where ghat exceeds the threshold, in the
//    image and in the light's transmittance T_L;
//  - transparency modulation: the surface's opacity is 1 - ghat, in the image and in T_L;
//  - both draw the volume's extinction optimised as in [9]: the optimisation with the surfaces
//    held at phi0, which is bit for bit the optimisation of the same scene without surfaces.
// The kernel tests build a half-space surface facing the camera over an empty volume and a ghat
// that ramps linearly across x, so where each ray meets the surface and the ghat it finds there
// follow from the geometry alone.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "core/device_buffer.h"
#include "core/frustum_map.h"
#include "render/renderer.h"
#include "render_fixtures.h"
#include "visopt/engine.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

constexpr int kN = 33;            // unit voxels, the box spans [-16, 16]^3
constexpr float kPlaneY = 4.f;    // the surface: phi = kPlaneY - y, inside behind it (y > kPlaneY)
constexpr float kCut = 0.3f;      // the cut-away threshold
constexpr float kAmbient = 0.5f;  // the only light on the surface: it shows 3 a C
const glm::vec3 kColour(0.2f, 0.5f, 0.8f), kBackground(0.f, 0.f, 1.f);

// ghat of the ramp at world x: 0 at the box's left face, 1 at its right face.
float rampAt(float x) {
  return (x + 16.f) / 32.f;
}

struct HalfSpaceScene {
  Volume volume = homogeneousCube(kN);
  DeviceBuffer<glm::vec4> table{2};
  Field3D phi, ghat;

  HalfSpaceScene()
      : phi("half-space", volume.grid(), Precision::FP32),
        ghat("ramp", volume.grid(), Precision::FP32) {
    volume.normalized.fill(0.f);
    table[0] = table[1] = glm::vec4(1.f, 1.f, 1.f, 0.f);  // the volume is empty
    const GridSpec& g = volume.grid();
    for (int k = 0; k < kN; ++k)
      for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i) {
          const glm::vec3 x = g.indexToWorld(glm::vec3(float(i), float(j), float(k)));
          phi.set(g.linearIndex(i, j, k), kPlaneY - x.y);
          ghat.set(g.linearIndex(i, j, k), rampAt(x.x));
        }
  }
  RenderScene scene() const {
    RenderScene s;
    s.volume = &volume;
    s.transfer = &table;
    s.camera.eye = glm::vec3(0.f, -100.f, 0.f);
    s.camera.target = glm::vec3(0.f);
    s.camera.up = glm::vec3(0.f, 0.f, 1.f);
    s.light.position = glm::vec3(0.f, -100.f, 0.f);
    s.light.intensity = 0.f;
    s.surfaces = {&phi};
    s.surfaceBases = {&phi};
    s.surfaceColors = {kColour};
    s.importanceBehind = &ghat;
    return s;
  }
};

RenderSettings ambientOnly(int size, RenderMethod method) {
  RenderSettings s = pureSingleScattering(size);
  s.surfaceSpecular = 0.f;
  s.ambientOcclusion = false;
  s.ambient = kAmbient;
  s.background = kBackground;
  s.method = method;
  s.cutAwayThreshold = kCut;
  return s;
}

// For each pixel whose ray meets the plane well inside the box: the ghat there.
template <class Check>
void forEachPixelOnThePlane(const RenderScene& scene, int size, Check check) {
  const FrustumMap camera(
      FrustumGrid::forCamera(scene.camera, size, size, scene.volume->grid().worldBounds(), 1, 1.f));
  int pixels = 0;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      const glm::vec3 dir = camera.rayDirection(float(px), float(py));
      const float t = (kPlaneY - camera.eye.y) / dir.y;
      const glm::vec3 hit = camera.eye + t * dir;
      if (std::abs(hit.x) > 15.f || std::abs(hit.z) > 15.f) continue;
      check(px, py, rampAt(hit.x));
      ++pixels;
    }
  ASSERT_GT(pixels, size * size / 4) << "the plane fills too little of the image";
}

}  // namespace

TEST(Fig10Baselines, CutAwayRemovesTheSurfaceExactlyWhereGhatExceedsTheThreshold) {
  const HalfSpaceScene scene;
  const int size = 96;
  const Image img = renderImage(scene.scene(), ambientOnly(size, RenderMethod::CutAway), nullptr);
  const glm::vec3 surface = 3.f * kAmbient * kColour;
  int cut = 0, kept = 0;
  forEachPixelOnThePlane(scene.scene(), size, [&](int px, int py, float g) {
    if (std::abs(g - kCut) < 0.01f) return;  // the sphere tracer's hit is exact to ~1e-3 units
    const glm::vec3 want = g > kCut ? kBackground : surface;
    (g > kCut ? cut : kept)++;
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(img.at(px, py)[c], want[c], 2e-3f)
          << "pixel " << px << "," << py << " with ghat " << g << ", channel " << c;
  });
  EXPECT_GT(cut, 100);
  EXPECT_GT(kept, 100);
}

TEST(Fig10Baselines, TransparencyGivesTheSurfaceTheOpacityOneMinusGhat) {
  const HalfSpaceScene scene;
  const int size = 96;
  const Image img =
      renderImage(scene.scene(), ambientOnly(size, RenderMethod::TransparencyModulation), nullptr);
  const glm::vec3 surface = 3.f * kAmbient * kColour;
  forEachPixelOnThePlane(scene.scene(), size, [&](int px, int py, float g) {
    const glm::vec3 want = (1.f - g) * surface + g * kBackground;
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(img.at(px, py)[c], want[c], 2e-3f)
          << "pixel " << px << "," << py << " with ghat " << g << ", channel " << c;
  });
}

// T_L through the empty volume: 1 before the surface; behind it 0 (ours, and cut-away where the
// ghat at the light ray's entry is at most the threshold), 1 (cut-away above it) or that ghat
// (transparency modulation: the light passes the surface's 1 - ghat opacity).
TEST(Fig10Baselines, TheLightSeesTheSurfacesAsTheBaselinesDrawThem) {
  const HalfSpaceScene scene;
  const RenderScene rs = scene.scene();
  const FrustumGrid grid = FrustumGrid::forLight(rs.light, scene.volume.grid().worldBounds(),
                                                 glm::ivec3(24, 24, 0), 1.f);
  const FrustumMap light(grid);
  GridSpec lg;
  lg.dims = grid.dims;
  for (RenderMethod method :
       {RenderMethod::Optimized, RenderMethod::CutAway, RenderMethod::TransparencyModulation}) {
    Field3D t("light-transmittance", lg, Precision::FP32);
    computeLightTransmittance(rs, grid, t, {}, method, kCut);
    int behind = 0, before = 0;
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const glm::vec3 dir = light.rayDirection(float(i), float(j));
        auto at = [&](int k) { return light.eye + light.depthOf(float(k)) * dir; };
        auto inBox = [](glm::vec3 x) {
          return std::abs(x.x) < 15.5f && std::abs(x.y) < 15.5f && std::abs(x.z) < 15.5f;
        };
        // The first cell centre behind the plane, and ghat there.
        int entry = -1;
        for (int k = 0; k < grid.dims.z && entry < 0; ++k)
          if (at(k).y > kPlaneY && inBox(at(k))) entry = k;
        if (entry < 0) continue;
        const float g = rampAt(at(entry).x);
        if (method == RenderMethod::CutAway && std::abs(g - kCut) < 0.01f) continue;
        const float passed = method == RenderMethod::Optimized ? 0.f
                             : method == RenderMethod::CutAway ? (g > kCut ? 1.f : 0.f)
                                                               : g;
        for (int k = 0; k < grid.dims.z; ++k) {
          if (!inBox(at(k))) continue;
          const float want = k < entry ? 1.f : passed;
          ASSERT_NEAR(t.get(lg.linearIndex(i, j, k)), want, 1e-5f)
              << toString(method) << ": ray " << i << "," << j << ", cell " << k << " (entry "
              << entry << ", ghat " << g << ")";
          (k < entry ? before : behind)++;
        }
      }
    EXPECT_GT(behind, 1000) << toString(method);
    EXPECT_GT(before, 1000) << toString(method);
  }
}

namespace {

ExtinctionSettings shortRun() {
  ExtinctionSettings s;
  s.levels = 2;
  s.maxIterationsPerLevel = 8;
  s.minIterationsPerLevel = 8;
  return s;
}

void loadCases(Engine& e) {
  e.loadBuiltinScene("level-set-cases", 32);
  e.setViewportSize(48, 48);
  e.setExtinctionSettings(shortRun());
}

bool sameBits(const Field3D& a, const Field3D& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    const float x = a.get(i), y = b.get(i);
    if (std::memcmp(&x, &y, sizeof x) != 0) return false;
  }
  return true;
}

}  // namespace

// §IV-A: the baselines "utilize the extinction optimization of [9] for the volume", [9] being
// the optimisation without context surfaces. Held at phi0 and taking no part in the visibility,
// the surfaces change nothing of it: its mu is the mu of the scene without them, bit for bit.
TEST(Fig10Baselines, TheBaselinesVolumeIsTheOptimisationWithoutSurfaces) {
  Engine withSurfaces;
  loadCases(withSurfaces);
  ASSERT_FALSE(withSurfaces.contextSurfaces().empty());
  EXPECT_FALSE(withSurfaces.optimizeBaseline().empty());
  ASSERT_NE(withSurfaces.baselineExtinction(), nullptr);
  ASSERT_NE(withSurfaces.baselineImportanceBehind(), nullptr) << "ghat for cutting and fading";
  EXPECT_FALSE(withSurfaces.hasOptimizedExtinction()) << "ours stays as it was";
  // Held surfaces take no step: the baseline holds no phi, coarse phi0 or level-set scratch.
  bool ghatHeld = false;
  for (const LedgerEntry& entry : withSurfaces.ledger().entries()) {
    if (entry.name.find("(baseline)") == std::string::npos) continue;
    EXPECT_NE(entry.name.rfind("surface", 0), 0u) << entry.name << " allocated for the baseline";
    ghatHeld = ghatHeld || entry.name.rfind("importance-behind", 0) == 0;
  }
  EXPECT_TRUE(ghatHeld) << "the baseline's ghat is in the ledger";

  Engine without;
  loadCases(without);  // the same transfer function, the one meant for the surfaces
  without.clearContextSurfaces();
  without.optimize();
  ASSERT_NE(without.optimizedExtinction(), nullptr);
  EXPECT_TRUE(sameBits(*withSurfaces.baselineExtinction(), *without.optimizedExtinction()));

  // And it is an optimisation: the visibility-driven energy moved mu away from mu_bar.
  Engine unoptimised;
  loadCases(unoptimised);
  unoptimised.setRenderOptimized(false);
  RenderSettings rs;
  rs.width = rs.height = 48;
  rs.method = RenderMethod::CutAway;
  const Image drawnOver = withSurfaces.render(rs);
  EXPECT_LT(psnr(drawnOver, unoptimised.render(rs)), 40.0)
      << "cut-away draws mu_bar, not the baseline's optimised mu";
}

// Without surfaces there is nothing to cut or fade: both baselines are [9]'s optimised volume,
// the image ours draws of the same scene.
TEST(Fig10Baselines, WithoutSurfacesTheBaselinesDrawTheOptimisedVolume) {
  Engine e;
  loadCases(e);
  e.clearContextSurfaces();
  e.optimize();
  RenderSettings rs;
  rs.width = rs.height = 48;
  const Image ours = e.render(rs);
  for (RenderMethod m : {RenderMethod::CutAway, RenderMethod::TransparencyModulation}) {
    rs.method = m;
    const Image baseline = e.render(rs);
    ASSERT_EQ(baseline.pixels.size(), ours.pixels.size());
    EXPECT_EQ(std::memcmp(baseline.pixels.data(), ours.pixels.data(),
                          ours.pixels.size() * sizeof(glm::vec3)),
              0)
        << toString(m);
  }
}

// The baseline is kept while what it was computed for stays, and computed again otherwise; a
// run given up part way leaves none.
TEST(Fig10Baselines, TheBaselineFollowsTheViewAndAnAbandonedRunLeavesNone) {
  Engine e;
  loadCases(e);
  EXPECT_FALSE(e.optimizeBaseline().empty());
  const Field3D* first = e.baselineExtinction();
  ASSERT_NE(first, nullptr);
  EXPECT_TRUE(e.optimizeBaseline().empty()) << "nothing changed: kept";
  e.orbitCamera(40.f, 10.f, 3.f);
  EXPECT_EQ(e.baselineExtinction(), nullptr) << "a baseline of the former view is not current";
  int iterations = 0;
  e.optimizeBaseline([&](const IterationStats&) { return ++iterations > 0; },
                     [&] { return iterations >= 3; });
  EXPECT_EQ(iterations, 3);
  EXPECT_EQ(e.baselineExtinction(), nullptr) << "abandoned part way";
  EXPECT_FALSE(e.optimizeBaseline().empty());
  EXPECT_NE(e.baselineExtinction(), nullptr);
}
