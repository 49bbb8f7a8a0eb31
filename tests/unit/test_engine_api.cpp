// Engine facade additions the workstation uses: removing a context surface, recolouring one,
// reading back the render-optimised flag and the viewport size, a render that gives way to a
// newer camera, and previews that reuse the light transmittance while the optimisation runs.
#include <sys/resource.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "render_fixtures.h"
#include "visopt/engine.h"
#include "visopt/error.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

// A sphere SDF of `radius` about `centre` on the volume grid.
Field3D sphereSdf(const GridSpec& g, glm::vec3 centre, float radius) {
  Field3D phi("sphere", g, Precision::FP32);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i)
        phi.set(
            g.linearIndex(i, j, k),
            glm::length(g.indexToWorld(glm::vec3(float(i), float(j), float(k))) - centre) - radius);
  return phi;
}

// An empty volume of 33^3 unit voxels seen along -z from far away, lit from the eye; no AO or
// specular, so a surface facing the eye shows colour * 3 / pi.
void emptyScene(Engine& e) {
  e.setVolume(homogeneousCube(33));
  e.setTransferFunction(constantTransferFunction(0.f, glm::vec3(1.f)));
  Camera cam = Camera::orbit({0, 0, 0}, 0.f, 0.f, 100.f);
  e.setCamera(cam);
  PointLight light;
  light.position = cam.eye;
  light.intensity = 3.f;
  e.setLight(light);
}

RenderSettings surfaceOnly() {
  RenderSettings s = pureSingleScattering(33);
  s.surfaceSpecular = 0.f;
  s.ambientOcclusion = false;
  return s;
}

ContextSurfaceSpec specNamed(const std::string& name, glm::vec3 colour) {
  ContextSurfaceSpec spec;
  spec.source = name;
  spec.color = colour;
  return spec;
}

}  // namespace

TEST(EngineApi, RemoveContextSurfaceShiftsTheOthersDown) {
  Engine e;
  emptyScene(e);
  const GridSpec& g = e.volume().grid();
  // Three small spheres side by side along x (left, middle, right).
  e.addContextSurface(specNamed("left", glm::vec3(1, 0, 0)), sphereSdf(g, {-10, 0, 0}, 4.f));
  e.addContextSurface(specNamed("middle", glm::vec3(0, 1, 0)), sphereSdf(g, {0, 0, 0}, 4.f));
  e.addContextSurface(specNamed("right", glm::vec3(0, 0, 1)), sphereSdf(g, {10, 0, 0}, 4.f));
  const Image before = e.render(surfaceOnly());

  e.removeContextSurface(1);
  ASSERT_EQ(e.contextSurfaces().size(), 2u);
  EXPECT_EQ(e.contextSurfaces()[0].source, "left");
  EXPECT_EQ(e.contextSurfaces()[1].source, "right");
  ASSERT_NE(e.contextSurfaceBase(1), nullptr);
  EXPECT_EQ(e.contextSurfaceBase(2), nullptr);
  // The base now at index 1 is the right sphere's: phi0 = -4 at its centre (index 26,16,16).
  EXPECT_NEAR(e.contextSurfaceBase(1)->get(g.linearIndex(26, 16, 16)), -4.f, 1e-5f);

  const Image after = e.render(surfaceOnly());
  // Seen from (0, -100, 0) with a 30 degree field of view, 33 pixels span 53.6 world units at
  // the spheres: their centres land near columns 16 -+ 6.2, radii 2.5 pixels. The middle one
  // is gone (background, 0); columns at least 4 from the centre are untouched.
  EXPECT_GT(before.at(16, 16).y, 0.1f);
  EXPECT_NEAR(after.at(16, 16).y, 0.f, 1e-6f);
  float outer = 0.f;
  for (int y = 0; y < 33; ++y)
    for (int x = 0; x < 33; ++x) {
      if (std::abs(x - 16) < 4) {
        EXPECT_NEAR(after.at(x, y).y, 0.f, 1e-6f) << x << "," << y;
        continue;
      }
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(after.at(x, y)[c], before.at(x, y)[c], 1e-5f) << x << "," << y;
      outer += after.at(x, y).x + after.at(x, y).z;
    }
  EXPECT_GT(outer, 1.f) << "the outer spheres should still be drawn";

  for (int bad : {-1, 2, 7}) EXPECT_THROW(e.removeContextSurface(bad), Error) << bad;
  e.removeContextSurface(0);
  e.removeContextSurface(0);
  EXPECT_TRUE(e.contextSurfaces().empty());
  const Image none = e.render(surfaceOnly());
  for (const glm::vec3& px : none.pixels) EXPECT_EQ(px, glm::vec3(0.f));
}

TEST(EngineApi, SetContextSurfaceColorRecolours) {
  Engine e;
  emptyScene(e);
  e.addContextSurface(specNamed("sphere", glm::vec3(0.8f)),
                      sphereSdf(e.volume().grid(), glm::vec3(0.f), 10.f));
  const glm::vec3 colour(0.9f, 0.3f, 0.05f);
  e.setContextSurfaceColor(0, colour);
  EXPECT_EQ(e.contextSurfaces()[0].color, colour);
  const Image img = e.render(surfaceOnly());
  // Facing the eye with the light at the eye: colour * L_e / pi (Eq. 8, Lambertian).
  const float pi = 3.14159265f;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(img.at(16, 16)[c], colour[c] * 3.f / pi, 0.03f * colour[c] * 3.f / pi + 1e-3f) << c;
  EXPECT_THROW(e.setContextSurfaceColor(1, colour), Error);
  EXPECT_THROW(e.setContextSurfaceColor(-1, colour), Error);
  EXPECT_THROW(e.setContextSurfaceColor(0, glm::vec3(-0.1f, 0.f, 0.f)), Error);
  EXPECT_THROW(e.setContextSurfaceColor(0, glm::vec3(std::nanf(""), 0.f, 0.f)), Error);
  EXPECT_EQ(e.contextSurfaces()[0].color, colour) << "a rejected colour must not stick";
}

TEST(EngineApi, RenderOptimizedAndViewportSizeReadBack) {
  Engine e;
  EXPECT_TRUE(e.renderOptimized());
  e.setRenderOptimized(false);
  EXPECT_FALSE(e.renderOptimized());
  e.setRenderOptimized(true);
  EXPECT_TRUE(e.renderOptimized());

  EXPECT_EQ(e.viewportSize(), glm::ivec2(512, 512));
  e.setViewportSize(320, 200);
  EXPECT_EQ(e.viewportSize(), glm::ivec2(320, 200));
  try {
    e.setViewportSize(0, 10);
    ADD_FAILURE() << "accepted a zero width";
  } catch (const Error& err) {
    EXPECT_EQ(err.kind(), ErrorKind::Usage);
  }
  EXPECT_EQ(e.viewportSize(), glm::ivec2(320, 200));
}

// A render asked to stop returns an empty image, at its start or between bands; one never asked
// renders exactly what a render without the check renders.
TEST(EngineApi, ARenderGivesWayWhenAskedAndIsUnchangedOtherwise) {
  Engine e;
  emptyScene(e);
  e.addContextSurface(specNamed("ball", glm::vec3(0.8f, 0.4f, 0.2f)),
                      sphereSdf(e.volume().grid(), glm::vec3(0.f), 8.f));
  const RenderSettings s = surfaceOnly();
  const Image plain = e.render(s);
  EXPECT_EQ(e.render(s, nullptr, [] { return true; }).width, 0);
  int polls = 0;
  EXPECT_EQ(e.render(s, nullptr, [&] { return ++polls == 3; }).width, 0);
  EXPECT_EQ(polls, 3) << "stopped between bands";
  polls = 0;
  const Image asked = e.render(s, nullptr, [&] { return ++polls < 0; });
  EXPECT_GT(polls, 2);
  ASSERT_EQ(asked.width, plain.width);
  ASSERT_EQ(asked.height, plain.height);
  for (size_t i = 0; i < plain.pixels.size(); ++i) ASSERT_EQ(asked.pixels[i], plain.pixels[i]);
}

// After an optimisation iteration a full frame recomputes the light transmittance T_L; a
// preview reuses the last full frame's once there is one of the optimised scene
// (RenderStats::lightMilliseconds is 0 when T_L was not recomputed).
TEST(EngineApi, PreviewsReuseTheLightTransmittanceWhileTheOptimisationRuns) {
  Engine e;
  e.loadBuiltinScene("shepp-logan", 32);
  e.setViewportSize(64, 64);
  ExtinctionSettings opt;
  opt.levels = 1;
  opt.maxIterationsPerLevel = opt.minIterationsPerLevel = 1;
  e.setExtinctionSettings(opt);
  RenderSettings full;
  full.width = full.height = 64;
  RenderSettings preview = full;
  preview.preview = true;
  RenderStats stats;
  e.optimize();
  e.render(full, &stats);
  EXPECT_GT(stats.lightMilliseconds, 0.0);
  e.continueOptimization(1);
  e.render(preview, &stats);
  EXPECT_EQ(stats.lightMilliseconds, 0.0) << "the preview reused T_L";
  e.render(full, &stats);
  EXPECT_GT(stats.lightMilliseconds, 0.0) << "the full frame recomputed it";
  e.render(full, &stats);
  EXPECT_EQ(stats.lightMilliseconds, 0.0) << "nothing changed since";
}

namespace {

// True when `f` throws Error(Usage) whose message contains `says`.
bool refused(const std::function<void()>& f, const std::string& says) {
  try {
    f();
  } catch (const Error& e) {
    return e.kind() == ErrorKind::Usage && std::string(e.what()).find(says) != std::string::npos;
  }
  return false;
}

}  // namespace

// A camera, light, step or level-set setting the kernels cannot use is refused where it is set
// (issue 13: a NaN camera, a 1e30 or 1e-30 distance segfaulted the renderer, a step of 1e-6 ran
// for hours), and the engine keeps what it had.
TEST(EngineApi, CamerasLightsStepsAndLevelSetSettingsOutOfRangeAreRefused) {
  Engine e;
  emptyScene(e);
  const Camera good = e.camera();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto withEye = [&](glm::vec3 eye) {
    Camera c = good;
    c.eye = eye;
    return c;
  };
  EXPECT_TRUE(refused([&] { e.setCamera(withEye({nan, 0.f, 0.f})); }, "finite"));
  EXPECT_TRUE(refused([&] { e.setCamera(withEye(good.target)); }, "bounding radii"));
  EXPECT_TRUE(refused([&] { e.setCamera(withEye({0.f, 0.f, 1e30f})); }, "bounding radii"));
  Camera narrow = good;
  narrow.fovYDegrees = 0.f;
  EXPECT_TRUE(refused([&] { e.setCamera(narrow); }, "field of view"));
  Camera upAlong = good;
  upAlong.up = good.target - good.eye;
  EXPECT_TRUE(refused([&] { e.setCamera(upAlong); }, "up vector"));
  EXPECT_TRUE(refused([&] { e.orbitCamera(nan, 0.f, 2.f); }, "finite"));
  EXPECT_TRUE(refused([&] { e.orbitCamera(0.f, 0.f, 1e30f); }, "distance"));
  EXPECT_TRUE(refused([&] { e.orbitCamera(0.f, 0.f, 0.f); }, "distance"));
  EXPECT_EQ(e.camera().eye, good.eye) << "a refused camera changes nothing";
  e.orbitCamera(0.f, 0.f, 0.5f);   // inside the volume: a fine view
  e.orbitCamera(10.f, 90.f, 2.f);  // from the pole
  e.setCamera(good);

  PointLight light = e.light();
  light.position.x = nan;
  EXPECT_TRUE(refused([&] { e.setLight(light); }, "position must be finite"));
  light = e.light();
  light.intensity = -1.f;
  EXPECT_TRUE(refused([&] { e.setLight(light); }, "intensity"));
  light = e.light();
  light.position = glm::vec3(1e30f);
  EXPECT_TRUE(refused([&] { e.setLight(light); }, "bounding radii"));

  RenderSettings rs;
  rs.width = rs.height = 8;
  for (float step : {1e-6f, 0.f, -1.f, 17.f, nan, std::numeric_limits<float>::infinity()}) {
    rs.stepFactor = step;
    EXPECT_TRUE(refused([&] { e.render(rs); }, "ray-march step")) << step;
  }
  rs.stepFactor = kMinStepFactor;
  EXPECT_EQ(e.render(rs).width, 8);
  // Render settings a session may carry: a light grid of 65536 rays per side asked for 640 GiB
  // (a failure to allocate, exit 3, instead of a usage error).
  RenderSettings bad = rs;
  bad.lightGridSize = 65536;
  EXPECT_TRUE(refused([&] { e.render(bad); }, "light grid"));
  bad = rs;
  bad.previewFactor = 0;
  EXPECT_TRUE(refused([&] { e.render(bad); }, "preview factor"));
  bad = rs;
  bad.exposure = nan;
  EXPECT_TRUE(refused([&] { e.render(bad); }, "exposure"));
  bad = rs;
  bad.earlyStop = 1.f;
  EXPECT_TRUE(refused([&] { e.render(bad); }, "early stop"));

  const LevelSetSettings before = e.levelSetSettings();
  LevelSetSettings ls = before;
  ls.lambda = nan;
  EXPECT_TRUE(refused([&] { e.setLevelSetSettings(ls); }, "lambda"));
  ls = before;
  ls.band = std::numeric_limits<float>::infinity();
  EXPECT_TRUE(refused([&] { e.setLevelSetSettings(ls); }, "narrow band"));
  ls = before;
  ls.redistanceIterations = -1;
  EXPECT_TRUE(refused([&] { e.setLevelSetSettings(ls); }, "redistancing iterations"));
  EXPECT_EQ(e.levelSetSettings().lambda, before.lambda);
}

// A built-in scene that needs more memory than the process may still allocate is refused before
// anything is allocated, also when the limit is the process's own (ulimit -v), not the
// machine's: at 1024^3 the scene exhausted a 4 GB cap instead of being refused.
TEST(EngineApi, ASceneLargerThanTheMemoryLeftIsRefusedUpFront) {
  std::ifstream status("/proc/self/status");
  std::string line;
  size_t vmSize = 0;
  while (std::getline(status, line))
    if (line.rfind("VmSize:", 0) == 0) vmSize = size_t(std::stoull(line.substr(7))) * 1024u;
  ASSERT_GT(vmSize, 0u);
  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &saved), 0);
  rlimit capped = saved;
  capped.rlim_cur = rlim_t(vmSize + (size_t(512) << 20));  // 512 MiB more than now
  if (saved.rlim_max != RLIM_INFINITY && capped.rlim_cur > saved.rlim_max)
    GTEST_SKIP() << "the hard address-space limit is already lower";
  ASSERT_EQ(setrlimit(RLIMIT_AS, &capped), 0);
  Engine e;
  // 512^3 voxels x 4 fields x 4 bytes = 2 GiB.
  const bool refusedUpFront =
      refused([&] { e.loadBuiltinScene("shepp-logan", 512); }, "GiB are available");
  ASSERT_EQ(setrlimit(RLIMIT_AS, &saved), 0);
  EXPECT_TRUE(refusedUpFront);
  e.loadBuiltinScene("shepp-logan", 24);  // within the limit, once restored
}
