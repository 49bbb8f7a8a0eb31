// The fast visibility scan (kernels/visibility_scan_fast.h, what the optimiser runs) against the
// reference per-ray scan (kernels/visibility_scan.h): the same d, the same running maximum of g
// behind each cell (half of ghat, Eq. 19) and the same sums (energies, V, V_occ) to float
// round-off, on small grids with and without context surfaces, a lens, a screen mask, view and
// light frusta, fp32 and fp16: one ray per launch with the per-ray buffer and without it (the
// form CUDA compiles), and the CPU backend's tiles of rays (host/visibility_scan_tiles.h; the
// frusta are 26 and 21 rays wide, so their last tiles are partly padding).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "host/visibility_scan_packet.h"
#include "host/visibility_scan_tiles.h"
#include "kernels/visibility_scan_fast.h"
#include "optimize/scan_skip_grid.h"
#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/frustum.h"

using namespace visopt;

namespace {

enum class Weights { None, Lens, Mask };

struct Case {
  Precision precision;  // of every field, except the importance with mixedImportance
  int surfaces;         // 0, 1 or 2 spheres
  Weights weights;
  bool lightFrustum;
  bool behindMax;
  bool mixedImportance = false;       // g in fp32 whatever the others' precision
  bool sparse = false;                // mu only in a ball, empty space around it
  bool importanceEverywhere = false;  // g in every voxel, up to the volume's faces
  bool eyeInside = false;             // the camera inside the volume
  std::string name() const {
    return std::string(precision == Precision::FP16 ? "fp16" : "fp32") + "_surfaces" +
           std::to_string(surfaces) +
           (weights == Weights::Lens   ? "_lens"
            : weights == Weights::Mask ? "_mask"
                                       : "") +
           (lightFrustum ? "_light" : "_view") + (behindMax ? "_max" : "");
  }
};

struct Scene {
  GridSpec grid;
  Field3D mu, g, mask;
  Field3D phi[2];
  FrustumGrid frustum;
};

// mu: random, zero in a slab (empty space keeps T); g: random in a ball, zero elsewhere.
Scene makeScene(const Case& c) {
  Scene s;
  s.grid.dims = glm::ivec3(23, 19, 17);
  s.grid.spacing = glm::vec3(0.05f, 0.06f, 0.055f);
  s.grid.origin = -0.5f * glm::vec3(s.grid.dims - 1) * s.grid.spacing;
  s.mu = Field3D("mu", s.grid, c.precision);
  s.g = Field3D("g", s.grid, c.mixedImportance ? Precision::FP32 : c.precision);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const glm::ivec3 n = s.grid.dims;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const size_t v = (size_t(k) * n.y + j) * n.x + i;
        const glm::vec3 x = s.grid.origin + glm::vec3(i, j, k) * s.grid.spacing;
        const bool empty = (i > 15 && i < 19) || (c.sparse && glm::length(x) > 0.36f);
        s.mu.set(v, empty ? 0.f : 6.f * u(rng));
        const bool important =
            c.importanceEverywhere || glm::length(x - glm::vec3(0.1f, 0.f, 0.05f)) < 0.3f;
        s.g.set(v, important ? u(rng) : 0.f);
      }
  const glm::vec3 centres[2] = {{-0.2f, 0.05f, 0.f}, {0.15f, -0.1f, 0.1f}};
  for (int sIdx = 0; sIdx < c.surfaces; ++sIdx) {
    s.phi[sIdx] = Field3D("phi", s.grid, c.precision);
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          const glm::vec3 x = s.grid.origin + glm::vec3(i, j, k) * s.grid.spacing;
          s.phi[sIdx].set((size_t(k) * n.y + j) * n.x + i, glm::length(x - centres[sIdx]) - 0.18f);
        }
  }
  const Bounds bounds = s.grid.worldBounds();
  if (c.lightFrustum) {
    PointLight light;
    light.position = glm::vec3(1.2f, -0.9f, 1.5f);
    s.frustum = FrustumGrid::forLight(light, bounds, glm::ivec3(21, 21, 0), s.grid.minSpacing());
  } else {
    Camera cam;
    cam.eye = c.eyeInside ? glm::vec3(0.05f, -0.1f, 0.02f) : glm::vec3(0.4f, -2.1f, 0.7f);
    cam.target = glm::vec3(0.02f, 0.01f, -0.03f);
    s.frustum = FrustumGrid::forCamera(cam, 26, 20, bounds, 0, s.grid.minSpacing());
  }
  if (c.weights == Weights::Mask) {
    GridSpec mg;
    mg.dims = glm::ivec3(9, 7, 1);
    s.mask = Field3D("screen mask", mg, Precision::FP32);
    for (size_t v = 0; v < s.mask.size(); ++v) s.mask.set(v, u(rng));
  }
  return s;
}

struct Result {
  std::vector<float> d, behindMax;
  ScanSums sums;
};

// The tiled CPU scan (host/visibility_scan_tiles.h), for run<>.
struct TiledScan {
  VisibilityScan scan;
};

// With skip: the fast scans' empty-space skip grid (kernels/scan_skip.h) built for the scene.
template <class Kernel>
Result run(const Scene& s, const Case& c, bool skip = false) {
  GridSpec fg;
  fg.dims = frustumStorageDims(s.frustum.dims);
  Field3D out("d", fg, c.precision), behind("behind max", fg, c.precision);
  Kernel kernel{};
  VisibilityScan& scan = [&]() -> VisibilityScan& {
    if constexpr (std::is_same_v<Kernel, VisibilityScan>)
      return kernel;
    else
      return kernel.scan;
  }();
  scan.frustum = FrustumMap(s.frustum);
  scan.volume = GridMap(s.grid);
  scan.mu = FieldView(s.mu);
  scan.importance = FieldView(s.g);
  scan.out = FrustumFieldView(out, s.frustum.dims);
  scan.surfaces.count = c.surfaces;
  for (int i = 0; i < c.surfaces; ++i) scan.surfaces.phi[i] = FieldView(s.phi[i]);
  if (c.weights == Weights::Lens) {
    scan.weights.lensCentre = glm::vec2(0.45f, 0.55f);
    scan.weights.lensRadius = 0.3f;
    scan.weights.lensStrength = 0.2f;
  } else if (c.weights == Weights::Mask) {
    scan.weights.mask = FieldView(s.mask);
  }
  if (c.behindMax) scan.behindMax = FrustumFieldView(behind, s.frustum.dims);
  ScanSkipStorage skipGrid;
  if (skip) {
    buildScanSkipGrid(s.mu, s.g, scan.surfaces, skipGrid);
    scan.skip = skipGrid.grid;
  }
  Result r;
  if constexpr (std::is_same_v<Kernel, TiledScan>)
    r.sums = scanTilesOnHost("test scan", scan);
  else
    r.sums = exec::reduce("test scan", int64_t(s.frustum.dims.x) * s.frustum.dims.y, ScanSums{},
                          kernel, [](const ScanSums& a, const ScanSums& b) { return a + b; });
  const glm::ivec3 n = s.frustum.dims;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        r.d.push_back(scan.out.at(i, j, k));
        if (c.behindMax) r.behindMax.push_back(scan.behindMax.at(i, j, k));
      }
  return r;
}

void expectSame(const Result& ref, const Result& fast, const Case& c, const char* form) {
  SCOPED_TRACE(c.name() + " " + form);
  // fp16 stores d with 11 significant bits; fp32 differs only by the order of float operations.
  const float rel = c.precision == Precision::FP16 ? 2e-3f : 2e-5f;
  ASSERT_EQ(ref.d.size(), fast.d.size());
  float scale = 0.f;
  for (float v : ref.d) scale = std::max(scale, std::abs(v));
  ASSERT_GT(scale, 0.f);
  size_t nonzero = 0;
  for (size_t i = 0; i < ref.d.size(); ++i) {
    ASSERT_NEAR(ref.d[i], fast.d[i], rel * scale) << "cell " << i;
    nonzero += ref.d[i] != 0.f;
  }
  // The rays do cross the volume. The fewest nonzero d are in the light cases with two surfaces,
  // 4.8 % of the cells (rays that miss the box, or cells behind its surfaces, hold 0).
  EXPECT_GT(nonzero, ref.d.size() / 25);
  ASSERT_EQ(ref.behindMax.size(), fast.behindMax.size());
  for (size_t i = 0; i < ref.behindMax.size(); ++i)
    ASSERT_NEAR(ref.behindMax[i], fast.behindMax[i], rel) << "cell " << i;
  auto near = [&](double a, double b, const char* what) {
    EXPECT_NEAR(a, b, 1e-5 * std::max(std::abs(a), 1e-12)) << what;
  };
  EXPECT_GT(ref.sums.gMu, 0.0);
  near(ref.sums.gMuT, fast.sums.gMuT, "sum g mu T dV");
  near(ref.sums.gMu, fast.sums.gMu, "sum g mu dV");
  near(ref.sums.importantSeen, fast.sums.importantSeen, "V_occ numerator");
  near(ref.sums.importantSeenAlone, fast.sums.importantSeenAlone, "V_occ denominator");
}

}  // namespace

TEST(FastVisibilityScan, MatchesTheReferenceScan) {
  int cases = 0;
  for (Precision p : {Precision::FP32, Precision::FP16})
    for (int surfaces : {0, 1, 2})
      for (Weights w : {Weights::None, Weights::Lens, Weights::Mask})
        for (bool light : {false, true}) {
          const Case c{p, surfaces, w, light, surfaces > 0 || w == Weights::Lens};
          const Scene s = makeScene(c);
          const Result ref = run<VisibilityScan>(s, c);
          expectSame(ref, run<FastVisibilityScan<kScanBufferCells>>(s, c), c, "buffered");
          expectSame(ref, run<FastVisibilityScan<0>>(s, c), c, "unbuffered");
          expectSame(ref, run<TiledScan>(s, c), c, "tiled");
          ++cases;
        }
  EXPECT_EQ(cases, 36);
}

// Each ray is bounded to the volume before its cells are walked (cellsInVolume): with importance
// up to the volume's faces the cells where a ray enters and leaves count, from outside the volume
// (rays entering through faces, edges and corners, and rays missing it), from the light, and from
// a camera inside the volume.
TEST(FastVisibilityScan, RaysBoundedToTheVolumeKeepTheCellsAtItsFaces) {
  for (Precision p : {Precision::FP32, Precision::FP16})
    for (int view : {0, 1, 2}) {
      Case c{p, 0, Weights::None, view == 1, true};
      c.importanceEverywhere = true;
      c.eyeInside = view == 2;
      const Scene s = makeScene(c);
      SCOPED_TRACE(c.eyeInside ? "eye inside" : "eye outside");
      const Result ref = run<VisibilityScan>(s, c);
      expectSame(ref, run<FastVisibilityScan<kScanBufferCells>>(s, c), c, "buffered");
      expectSame(ref, run<FastVisibilityScan<0>>(s, c), c, "unbuffered");
      expectSame(ref, run<TiledScan>(s, c), c, "tiled");
      expectSame(ref, run<TiledScan>(s, c, true), c, "tiled, skipping");
    }
}

// Fields of mixed precision: the tiled scan's per-ray front-to-back pass (the packet pass needs
// one precision throughout, and the dispatch sends fields of one precision to it).
TEST(FastVisibilityScan, MixedPrecisionMatchesTheReferenceScan) {
  for (int surfaces : {0, 2}) {
    Case c{Precision::FP16, surfaces, Weights::Lens, false, true};
    c.mixedImportance = true;
    const Scene s = makeScene(c);
    expectSame(run<VisibilityScan>(s, c), run<TiledScan>(s, c), c, "tiled, mixed precision");

    VisibilityScan scan;
    scan.mu = FieldView(s.mu);
    scan.importance = FieldView(s.g);
    scan.surfaces.count = surfaces;
    for (int i = 0; i < surfaces; ++i) scan.surfaces.phi[i] = FieldView(s.phi[i]);
    EXPECT_FALSE(packetScanApplies<float>(scan));
    EXPECT_FALSE(packetScanApplies<Half>(scan));
    const Scene same = makeScene(Case{Precision::FP16, surfaces, Weights::Lens, false, true});
    scan.importance = FieldView(same.g);
    scan.mu = FieldView(same.mu);
    for (int i = 0; i < surfaces; ++i) scan.surfaces.phi[i] = FieldView(same.phi[i]);
    EXPECT_TRUE(packetScanApplies<Half>(scan));
    EXPECT_FALSE(packetScanApplies<float>(scan));
  }
}

// A surface in front of everything blocks every ray from its first cell: d and T vanish behind
// it in both kernels, and the fast kernel still reports the whole volume in sum g mu dV.
TEST(FastVisibilityScan, ASurfaceAroundTheVolumeHidesAll) {
  Case c{Precision::FP32, 1, Weights::None, false, true};
  Scene s = makeScene(c);
  for (size_t v = 0; v < s.phi[0].size(); ++v) s.phi[0].set(v, -1.f);
  const Result ref = run<VisibilityScan>(s, c);
  const Result fast = run<TiledScan>(s, c);
  EXPECT_EQ(fast.sums.gMuT, 0.0);
  EXPECT_EQ(fast.sums.importantSeen, 0.0);
  EXPECT_GT(fast.sums.gMu, 0.0);
  EXPECT_NEAR(fast.sums.gMu, ref.sums.gMu, 1e-5 * ref.sums.gMu);
  for (size_t i = 0; i < fast.d.size(); ++i) ASSERT_EQ(fast.d[i], 0.f);
}

// Empty-space skipping (kernels/scan_skip.h) changes nothing: the same d, maxima and sums bit for
// bit, in every form, on scenes with empty space around the matter, with and without surfaces;
// and it does skip (bricks flagged empty, and bricks where only a surface or only importance
// needs loads).
TEST(FastVisibilityScan, SkippingEmptySpaceChangesNothing) {
  // One thread: the reductions' summation order is then fixed, so the sums compare bit for bit.
  tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
  auto expectIdentical = [](const Result& a, const Result& b, const Case& c, const char* form) {
    SCOPED_TRACE(c.name() + " " + form);
    ASSERT_EQ(a.d.size(), b.d.size());
    for (size_t i = 0; i < a.d.size(); ++i) ASSERT_EQ(a.d[i], b.d[i]) << "cell " << i;
    ASSERT_EQ(a.behindMax, b.behindMax);
    EXPECT_EQ(a.sums.gMuT, b.sums.gMuT);
    EXPECT_EQ(a.sums.gMu, b.sums.gMu);
    EXPECT_EQ(a.sums.importantSeen, b.sums.importantSeen);
    EXPECT_EQ(a.sums.importantSeenAlone, b.sums.importantSeenAlone);
  };
  for (Precision p : {Precision::FP32, Precision::FP16})
    for (int surfaces : {0, 1, 2})
      for (bool light : {false, true}) {
        Case c{p, surfaces, Weights::Lens, light, true};
        c.sparse = true;
        const Scene s = makeScene(c);
        expectIdentical(run<TiledScan>(s, c), run<TiledScan>(s, c, true), c, "tiled");
        expectIdentical(run<FastVisibilityScan<kScanBufferCells>>(s, c),
                        run<FastVisibilityScan<kScanBufferCells>>(s, c, true), c, "buffered");
        expectIdentical(run<FastVisibilityScan<0>>(s, c), run<FastVisibilityScan<0>>(s, c, true), c,
                        "unbuffered");
        // (From the light, two spheres shade most of the small ball: d is almost all zero there,
        // below expectSame's check that the rays cross the volume.)
        if (!(light && surfaces == 2))
          expectSame(run<VisibilityScan>(s, c), run<TiledScan>(s, c, true), c, "tiled, skipping");

        ScanSkipStorage grid;
        SurfaceSet set;
        set.count = surfaces;
        for (int i = 0; i < surfaces; ++i) set.phi[i] = FieldView(s.phi[i]);
        buildScanSkipGrid(s.mu, s.g, set, grid);
        int empty = 0, surfaceOnly = 0, matterWithoutImportance = 0;
        for (size_t b = 0; b < grid.flags.size(); ++b) {
          const uint8_t f = grid.flags[b];
          empty += f == 0;
          surfaceOnly += f == kScanHasSurface;
          matterWithoutImportance += (f & kScanHasExtinction) && !(f & kScanHasImportance);
        }
        EXPECT_GT(empty, 0);
        EXPECT_GT(matterWithoutImportance, 0);
        if (surfaces > 0) {
          EXPECT_EQ(surfaceOnly, 0);  // the spheres lie inside the matter
        }
      }
}
