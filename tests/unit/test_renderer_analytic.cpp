// The renderer against closed forms (Himmler & Günther 2026, Eqs. 6-9).
#include <cmath>

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "render_fixtures.h"
#include "visopt/engine.h"
#include "visopt/frustum.h"
#include "visopt/scenes.h"

using namespace visopt;
using namespace visopt::testing;

namespace {
constexpr float kPi = 3.14159265358979f;

// Head-on camera along +y through the cube's centre.
Camera headOn(float distance) {
  return Camera::orbit({0, 0, 0}, 0.f, 0.f, distance);
}
}  // namespace

class RendererPrecision : public ::testing::TestWithParam<Precision> {};

// A homogeneous slab of extinction mu and length L seen head-on transmits exp(-mu L): with no
// light and a white background the centre pixel is exactly that.
TEST_P(RendererPrecision, SlabTransmitsExpMinusMuL) {
  for (float mu : {0.01f, 0.1f, 0.5f}) {
    for (bool jitter : {false, true}) {
      Engine engine(GetParam());
      engine.setVolume(homogeneousCube(17, GetParam()));  // L = 16 between voxel centres
      engine.setTransferFunction(constantTransferFunction(mu, glm::vec3(1.f)));
      engine.setCamera(headOn(60.f));
      PointLight dark;
      dark.intensity = 0.f;
      engine.setLight(dark);
      RenderSettings s = pureSingleScattering(33);  // odd: pixel 16 is on the axis
      s.background = glm::vec3(1.f);
      s.jitter = jitter;
      s.stepFactor = 0.7f;
      Image img = engine.render(s);
      const float expected = std::exp(-mu * 16.f);
      // fp16 stores the normalised scalars (exact here) and T_L; the TF table is fp32.
      EXPECT_NEAR(img.at(16, 16).x, expected, 2e-4f + 1e-3f * expected) << "mu " << mu;
      EXPECT_NEAR(img.at(16, 16).y, expected, 2e-4f + 1e-3f * expected);
    }
  }
}

// Single scattering in a thin homogeneous slab, lit by a point light at the eye: along the
// central ray T_V(s) = T_L(s) = exp(-mu s), so
//   L = integral_0^L exp(-2 mu s) mu a f_HG(-1) L_e ds = a L_e f_HG(-1) (1 - exp(-2 mu L)) / 2.
TEST_P(RendererPrecision, SingleScatteringMatchesClosedFormWithinOnePercent) {
  for (float g : {0.f, 0.5f}) {
    for (float mu : {0.02f, 0.08f}) {
      Engine engine(GetParam());
      engine.setVolume(homogeneousCube(33, GetParam()));  // L = 32
      const glm::vec3 albedo(0.9f, 0.6f, 0.3f);
      engine.setTransferFunction(constantTransferFunction(mu, albedo));
      Camera cam = headOn(80.f);
      engine.setCamera(cam);
      PointLight light;
      light.position = cam.eye;
      light.intensity = 10.f;
      engine.setLight(light);
      RenderSettings s = pureSingleScattering(21);
      s.hgAnisotropy = g;
      s.stepFactor = 0.25f;
      s.lightGridSize = 65;
      Image img = engine.render(s);
      const float d = 1.f + g * g + 2.f * g;  // cos(theta) = -1: light returns to the eye
      const float phase = (1.f - g * g) / (4.f * kPi * d * std::sqrt(d));
      const float L = 32.f;
      for (int c = 0; c < 3; ++c) {
        const float expected =
            albedo[c] * light.intensity * phase * (1.f - std::exp(-2.f * mu * L)) / 2.f;
        EXPECT_NEAR(img.at(10, 10)[c], expected, 0.01f * expected)
            << "g " << g << " mu " << mu << " channel " << c;
      }
    }
  }
}

// Without T_L (light at the far side, everything in shadow of an opaque slab) the result is
// darker than with the light at the eye: shadows come from T_L.
TEST(Renderer, LightBehindAnOpaqueSlabLeavesItDark) {
  Engine engine;
  engine.setVolume(homogeneousCube(17));
  engine.setTransferFunction(constantTransferFunction(2.f, glm::vec3(1.f)));
  Camera cam = headOn(60.f);
  engine.setCamera(cam);
  RenderSettings s = pureSingleScattering(17);
  PointLight front;
  front.position = cam.eye;
  engine.setLight(front);
  const float lit = engine.render(s).at(8, 8).x;
  PointLight back;
  back.position = -cam.eye;  // behind the slab, shining at the camera through 16 units of mu=2
  engine.setLight(back);
  const float shadowed = engine.render(s).at(8, 8).x;
  EXPECT_GT(lit, 1e-3f);
  EXPECT_LT(shadowed, 1e-6f);
}

TEST(Renderer, PreviewHasRequestedSizeAndFewerSamples) {
  Engine engine;
  engine.setVolume(homogeneousCube(17));
  engine.setTransferFunction(constantTransferFunction(0.1f, glm::vec3(1.f)));
  engine.setCamera(headOn(40.f));
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  RenderStats full, preview;
  Image a = engine.render(s, &full);
  s.preview = true;
  Image b = engine.render(s, &preview);
  EXPECT_EQ(b.width, 64);
  EXPECT_EQ(b.height, 48);
  EXPECT_EQ(preview.width, 16);
  EXPECT_LT(preview.samples * 20, full.samples);
  EXPECT_GT(psnr(a, b), 20.0);
}

INSTANTIATE_TEST_SUITE_P(Precisions, RendererPrecision,
                         ::testing::Values(Precision::FP32, Precision::FP16));

// The volume's empty-space block ranges computed once (what the Engine keeps per volume) give the
// image that building them for the frame gives, bit for bit, in both precisions; ranges of
// another volume's size are not used.
TEST(Renderer, BlockRangesKeptAcrossFramesGiveTheSameImage) {
  for (Precision precision : {Precision::FP32, Precision::FP16}) {
    BuiltinScene built = makeBuiltinScene("shepp-logan", 40, precision);
    const Volume& volume = built.volume;
    const TransferTable baked = built.transferFunction.bake(volume.valueMin, volume.valueMax,
                                                            volume.grid().minSpacing(), 1024);
    DeviceBuffer<glm::vec4> table(baked.albedoExtinction.size());
    for (size_t i = 0; i < table.size(); ++i) table[i] = baked.albedoExtinction[i];
    RenderScene scene;
    scene.volume = &volume;
    scene.transfer = &table;
    scene.camera = Camera::orbitBounds(volume.grid().worldBounds(), 30.f, 20.f, 3.f);
    scene.light = PointLight::keyLightFor(scene.camera, volume.grid().worldBounds());
    RenderSettings settings;
    settings.width = settings.height = 48;
    const Image perFrame = renderImage(scene, settings, nullptr, {});
    const DeviceBuffer<glm::vec2> ranges = computeBlockRange(volume.normalized);
    scene.volumeBlockRange = &ranges;
    const Image kept = renderImage(scene, settings, nullptr, {});
    ASSERT_EQ(kept.pixels.size(), perFrame.pixels.size());
    size_t lit = 0;
    for (size_t i = 0; i < kept.pixels.size(); ++i) {
      ASSERT_EQ(kept.pixels[i], perFrame.pixels[i]) << "pixel " << i << ", " << toString(precision);
      lit += glm::length(perFrame.pixels[i] - settings.background) > 0.05f;
    }
    EXPECT_GT(lit, kept.pixels.size() / 10) << "the scene is not in the image";
    // The kept ranges are what the frame uses: ranges saying every block holds only air (value
    // 0, transparent in this transfer function) skip the whole volume.
    DeviceBuffer<glm::vec2> air(ranges.size());
    for (size_t i = 0; i < air.size(); ++i) air[i] = glm::vec2(0.f, 0.f);
    scene.volumeBlockRange = &air;
    EXPECT_NE(renderImage(scene, settings, nullptr, {}).pixels, perFrame.pixels);
    // Ranges that do not fit the volume (another volume's) are not used.
    DeviceBuffer<glm::vec2> other(ranges.size() + 1);
    for (size_t i = 0; i < other.size(); ++i) other[i] = glm::vec2(0.f, 0.f);
    scene.volumeBlockRange = &other;
    EXPECT_EQ(renderImage(scene, settings, nullptr, {}).pixels, perFrame.pixels);

    // With an optimised mu: its change to mu_bar adds extinction in a slab through the air and
    // takes it away elsewhere. Its ranges kept give the frame's image too.
    Field3D change("change", volume.grid(), precision);
    const glm::ivec3 d = volume.grid().dims;
    for (size_t v = 0; v < change.size(); ++v) {
      const int i = int(v % size_t(d.x)), k = int(v / (size_t(d.x) * size_t(d.y)));
      change.set(v, i < d.x / 6 ? 2.f : (k % 2 ? -0.5f : 0.f));
    }
    scene.extinctionChange = &change;
    scene.volumeBlockRange = nullptr;
    const Image changedPerFrame = renderImage(scene, settings, nullptr, {});
    EXPECT_NE(changedPerFrame.pixels, perFrame.pixels);
    const DeviceBuffer<glm::vec2> changeRanges = computeBlockRange(change);
    scene.volumeBlockRange = &ranges;
    scene.changeBlockRange = &changeRanges;
    EXPECT_EQ(renderImage(scene, settings, nullptr, {}).pixels, changedPerFrame.pixels);
    // Used: change ranges saying "nothing added" skip the slab in the air.
    scene.changeBlockRange = &air;
    EXPECT_NE(renderImage(scene, settings, nullptr, {}).pixels, changedPerFrame.pixels);
  }
}

// The Engine keeps the block ranges per volume: a new volume of the same size gets its own (a
// stale one would skip or keep the wrong blocks), as a fresh engine would draw it; the ranges
// are in the ledger.
TEST(Renderer, TheEngineRebuildsBlockRangesForANewVolume) {
  RenderSettings settings;
  settings.width = settings.height = 40;
  Engine engine;
  engine.loadBuiltinScene("shepp-logan", 32);
  (void)engine.render(settings);
  bool listed = false;
  for (const auto& f : engine.ledger().entries()) listed = listed || f.name == "render-skip-ranges";
  EXPECT_TRUE(listed);
  engine.loadBuiltinScene("marschner-lobb", 32);
  Engine fresh;
  fresh.loadBuiltinScene("marschner-lobb", 32);
  EXPECT_EQ(engine.render(settings).pixels, fresh.render(settings).pixels);
}
