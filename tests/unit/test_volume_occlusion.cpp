// Ambient occlusion of the volume's samples (kernels/volume_occlusion.h; Himmler & Günther 2026,
// R4 and Fig. 6) against closed forms: the mean transmittance of six axis rays of length R
// through the linear interpolant of mu along each axis, 0 beyond the grid, opaque inside a
// context surface. And its effect in the renderer and its life in the Engine.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "core/device_buffer.h"
#include "kernels/volume_occlusion.h"
#include "render/renderer.h"
#include "render_fixtures.h"
#include "visopt/engine.h"
#include "visopt/scenes.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

constexpr int kN = 40;
constexpr float kSpacing = 0.5f;
constexpr float kMu = 0.3f;  // per world unit in the dense material

// A kN^3 grid of spacing kSpacing whose scalars are 1 (dense) or 0 (air) as `dense` says, and a
// two-entry table: air has no extinction, dense material kMu.
struct OcclusionScene {
  Volume volume;
  DeviceBuffer<glm::vec4> table{2};

  OcclusionScene(Precision precision, const std::function<bool(int, int, int)>& dense) {
    GridSpec g;
    g.dims = glm::ivec3(kN);
    g.spacing = glm::vec3(kSpacing);
    volume.name = "occlusion";
    volume.sourcePath = "test:occlusion";
    volume.valueMin = 0.0;
    volume.valueMax = 1.0;
    volume.normalized = Field3D("volume", g, precision);
    for (int k = 0; k < kN; ++k)
      for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i)
          volume.normalized.set((size_t(k) * kN + size_t(j)) * kN + size_t(i),
                                dense(i, j, k) ? 1.f : 0.f);
    table[0] = glm::vec4(1.f, 1.f, 1.f, 0.f);
    table[1] = glm::vec4(1.f, 1.f, 1.f, kMu);
  }
  RenderScene scene() const {
    RenderScene s;
    s.volume = &volume;
    s.transfer = &table;
    return s;
  }
};

size_t at(int i, int j, int k) {
  return (size_t(k) * kN + size_t(j)) * kN + size_t(i);
}

float tolerance(Precision p) {
  return p == Precision::FP16 ? 2e-3f : 2e-5f;
}

}  // namespace

class VolumeOcclusion : public ::testing::TestWithParam<Precision> {};

// Dense material everywhere but an empty cube of half-width 2 voxels around (20, 20, 20). Rays of
// 6 voxels (3 world units): from the cavity's centre each crosses 2 empty voxels, one voxel where
// mu ramps linearly from 0 to kMu, then 3 dense ones: optical depth kMu h (6 - 2 - 0.5). Deep in
// the material every ray has kMu h 6; next to the grid's face one ray leaves the grid after i
// voxels (kMu h i). Fractional reaches (6.5 and 2.5 voxels) integrate the interpolant part way.
TEST_P(VolumeOcclusion, AxisRaysThroughACavityAndTheMaterialMatchClosedForms) {
  const Precision precision = GetParam();
  const OcclusionScene built(precision, [](int i, int j, int k) {
    return std::abs(i - 20) > 2 || std::abs(j - 20) > 2 || std::abs(k - 20) > 2;
  });
  Field3D ao("ao", built.volume.grid(), precision);
  const float h = kSpacing;
  computeVolumeOcclusion(built.scene(), RenderMethod::Optimized, 0.3f, 6.f * h, ao);
  EXPECT_NEAR(ao.get(at(20, 20, 20)), std::exp(-kMu * h * 3.5f), tolerance(precision));
  EXPECT_NEAR(ao.get(at(8, 8, 8)), std::exp(-kMu * h * 6.f), tolerance(precision));
  EXPECT_NEAR(ao.get(at(2, 8, 8)),
              (5.f * std::exp(-kMu * h * 6.f) + std::exp(-kMu * h * 2.f)) / 6.f,
              tolerance(precision));
  EXPECT_NEAR(ao.get(at(0, 0, 0)), (3.f * std::exp(-kMu * h * 6.f) + 3.f) / 6.f,
              tolerance(precision));
  // The cavity is lighter than the material around it and darkens towards its walls: a voxel
  // one step off the centre along x sees one ray of depth kMu h 2.5 and one of kMu h 4.5.
  const float offCentre =
      (4.f * std::exp(-kMu * h * 3.5f) + std::exp(-kMu * h * 2.5f) + std::exp(-kMu * h * 4.5f)) /
      6.f;
  EXPECT_NEAR(ao.get(at(21, 20, 20)), offCentre, tolerance(precision));

  computeVolumeOcclusion(built.scene(), RenderMethod::Optimized, 0.3f, 6.5f * h, ao);
  EXPECT_NEAR(ao.get(at(8, 8, 8)), std::exp(-kMu * h * 6.5f), tolerance(precision));
  EXPECT_NEAR(ao.get(at(20, 20, 20)), std::exp(-kMu * h * 4.f), tolerance(precision));
  // A reach of 2.5 voxels ends half-way up the ramp at the cavity's wall: the interpolant's
  // integral there is kMu h / 8 (a left-endpoint rule would give 0).
  computeVolumeOcclusion(built.scene(), RenderMethod::Optimized, 0.3f, 2.5f * h, ao);
  EXPECT_NEAR(ao.get(at(20, 20, 20)), std::exp(-kMu * h * 0.125f), tolerance(precision));
}

// Air with a context surface filling the half-space i < 10 (phi = (i - 10) h): the surface's
// interior is opaque, so from i = 14 the ray towards it is blocked (5/6 of the ambient light
// arrives) and from i = 16 on it ends before the surface (all of it). Inside a sphere of radius
// 15 voxels every ray is blocked; 2 voxels outside it one ray is.
TEST_P(VolumeOcclusion, ContextSurfacesAreOpaque) {
  const Precision precision = GetParam();
  const OcclusionScene built(precision, [](int, int, int) { return false; });
  Field3D plane("plane", built.volume.grid(), precision),
      sphere("sphere", built.volume.grid(), precision);
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        plane.set(at(i, j, k), float(i - 10) * kSpacing);
        const glm::vec3 p(float(i - 20), float(j - 20), float(k - 20));
        sphere.set(at(i, j, k), (glm::length(p) - 15.f) * kSpacing);
      }
  RenderScene scene = built.scene();
  scene.surfaces = {&plane};
  Field3D ao("ao", built.volume.grid(), precision);
  computeVolumeOcclusion(scene, RenderMethod::Optimized, 0.3f, 6.f * kSpacing, ao);
  EXPECT_NEAR(ao.get(at(14, 20, 20)), 5.f / 6.f, tolerance(precision));
  EXPECT_NEAR(ao.get(at(16, 20, 20)), 1.f, tolerance(precision));
  EXPECT_NEAR(ao.get(at(30, 20, 20)), 1.f, tolerance(precision));
  EXPECT_LT(ao.get(at(5, 20, 20)), 1e-3f);
  scene.surfaces = {&sphere};
  computeVolumeOcclusion(scene, RenderMethod::Optimized, 0.3f, 6.f * kSpacing, ao);
  EXPECT_LT(ao.get(at(20, 20, 20)), 1e-3f);
  // Outside, 2 voxels off it: only the ray back towards the centre meets the surface.
  EXPECT_NEAR(ao.get(at(20, 20, 37)), 5.f / 6.f, tolerance(precision));
}

// Extremes: an opaque material (mu far beyond what any ray transmits) gives 0, not NaN, deep
// inside and on the grid's corners half the rays leave at once; a grid one voxel thick along z
// has rays of length 0 along it.
TEST_P(VolumeOcclusion, OpaqueMaterialAndThinGridsStayFinite) {
  const Precision precision = GetParam();
  OcclusionScene built(precision, [](int, int, int) { return true; });
  built.table[1].w = 1e30f;
  Field3D ao("ao", built.volume.grid(), precision);
  computeVolumeOcclusion(built.scene(), RenderMethod::Optimized, 0.3f, 6.f * kSpacing, ao);
  EXPECT_NEAR(ao.get(at(20, 20, 20)), 0.f, 1e-6f);
  EXPECT_NEAR(ao.get(at(0, 0, 0)), 0.5f, tolerance(precision));
  for (size_t v = 0; v < ao.size(); ++v) ASSERT_TRUE(std::isfinite(ao.get(v)));

  GridSpec thin;
  thin.dims = {8, 8, 1};
  Volume slab;
  slab.valueMin = 0.0;
  slab.valueMax = 1.0;
  slab.normalized = Field3D("slab", thin, precision);
  slab.normalized.fill(1.f);
  built.table[1].w = 0.5f;
  RenderScene scene;
  scene.volume = &slab;
  scene.transfer = &built.table;
  Field3D aoThin("ao", thin, precision);
  computeVolumeOcclusion(scene, RenderMethod::Optimized, 0.3f, 2.f, aoThin);
  // From (4, 4): the x and y rays cross 2 voxels of mu 0.5 (depth 1), the z rays none.
  EXPECT_NEAR(aoThin.get(4 * 8 + 4), (4.f * std::exp(-1.f) + 2.f) / 6.f, tolerance(precision));
}

// The renderer multiplies each volume sample's ambient light by the field: with only ambient
// light and a field of 1/2 everywhere a pixel's radiance is exactly half of the unoccluded one;
// with ambient occlusion off in the settings the field is not used.
TEST_P(VolumeOcclusion, TheRendererScalesTheAmbientLightOfVolumeSamples) {
  const Precision precision = GetParam();
  const OcclusionScene built(precision, [](int i, int, int) { return i > 10; });
  RenderScene scene = built.scene();
  scene.camera = Camera::orbitBounds(built.volume.grid().worldBounds(), 20.f, 10.f, 3.f);
  scene.light.intensity = 0.f;
  RenderSettings settings = pureSingleScattering(24);
  settings.ambient = 0.5f;
  settings.jitter = false;
  const Image open = renderImage(scene, settings, nullptr, {});
  Field3D half("half", built.volume.grid(), precision);
  half.fill(0.5f);
  scene.volumeOcclusion = &half;
  const Image occluded = renderImage(scene, settings, nullptr, {});
  double lit = 0.0;
  for (size_t i = 0; i < open.pixels.size(); ++i) {
    EXPECT_NEAR(occluded.pixels[i].x, 0.5f * open.pixels[i].x, 1e-5f + 1e-4f * open.pixels[i].x);
    lit += open.pixels[i].x;
  }
  EXPECT_GT(lit / double(open.pixels.size()), 0.02) << "the material is not in the image";
  settings.ambientOcclusion = false;
  EXPECT_EQ(renderImage(scene, settings, nullptr, {}).pixels, open.pixels);
}

INSTANTIATE_TEST_SUITE_P(Precisions, VolumeOcclusion,
                         ::testing::Values(Precision::FP32, Precision::FP16));

namespace {
bool ledgerHas(const Engine& engine, const std::string& name) {
  for (const auto& entry : engine.ledger().entries())
    if (entry.name == name) return true;
  return false;
}
double meanLuminance(const Image& image) {
  double sum = 0.0;
  for (const auto& p : image.pixels) sum += double(p.x + p.y + p.z) / 3.0;
  return sum / double(image.pixels.size());
}
}  // namespace

// In the Engine the field exists only while ambient occlusion is on with an ambient term, is kept
// across frames that change nothing it reads, and darkens the default scene.
TEST(VolumeOcclusionEngine, AllocatedOnlyWhenAskedForAndKeptAcrossFrames) {
  Engine engine(Precision::FP32);
  engine.loadBuiltinScene("shepp-logan", 48, false);
  RenderSettings settings;
  settings.width = settings.height = 48;
  RenderStats first, second;
  const Image on = engine.render(settings, &first);
  EXPECT_TRUE(ledgerHas(engine, "volume-occlusion (render)"));
  EXPECT_GT(first.occlusionMilliseconds, 0.0);
  const Image again = engine.render(settings, &second);
  EXPECT_EQ(second.occlusionMilliseconds, 0.0) << "recomputed with nothing changed";
  EXPECT_EQ(again.pixels, on.pixels);
  settings.ambientOcclusionRadius = 3.f;  // what the field reads: computed again
  RenderStats third;
  engine.render(settings, &third);
  EXPECT_GT(third.occlusionMilliseconds, 0.0);

  settings.ambientOcclusion = false;
  const Image off = engine.render(settings);
  EXPECT_FALSE(ledgerHas(engine, "volume-occlusion (render)"));
  EXPECT_LT(meanLuminance(on), meanLuminance(off));
  settings.ambientOcclusion = true;
  settings.ambient = 0.f;
  engine.render(settings);
  EXPECT_FALSE(ledgerHas(engine, "volume-occlusion (render)"));
}

// The CPU backend's prefix sweep over groups of side-by-side rows (along y and z) gives the
// per-row reference's prefix integrals bit for bit, on a grid whose rows do not fill the last
// group, in both axes.
TEST(VolumeOcclusionPrefix, RowGroupsMatchThePerRowReference) {
  const glm::ivec3 dims(37, 11, 9);
  const size_t n = size_t(dims.x) * dims.y * dims.z;
  DeviceBuffer<float> mu(n), reference(n), grouped(n);
  for (size_t v = 0; v < n; ++v) mu[v] = float((v * 7919) % 101) * 0.37f;  // some above the cap
  for (int axis = 1; axis <= 2; ++axis) {
    OcclusionPrefixRows rows;
    rows.dims = dims;
    rows.axis = axis;
    rows.spacing = 0.7f;
    rows.mu = mu.data();
    rows.prefix = reference.data();
    for (int64_t r = 0; r < int64_t(n) / dims[axis]; ++r) rows(r);
    rows.prefix = grouped.data();
    const OcclusionPrefixRowGroups groups{rows};
    for (int64_t g = 0; g < groups.groups(); ++g) groups(g);
    for (size_t v = 0; v < n; ++v)
      ASSERT_EQ(grouped[v], reference[v]) << "axis " << axis << ", voxel " << v;
  }
}
