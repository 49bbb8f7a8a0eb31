// The narrow-band path of the level-set step and redistancing (LevelSetSettings::band; issue 11)
// against the dense reference path (band = 0) on analytic cases: mean-curvature flow of a sphere
// (r^2 = R^2 - 4 c t for both), relaxation from far away to phi0, redistancing a distorted
// sphere (|grad phi| in [0.95, 1.05] next to brick faces as elsewhere), a surface that shrinks to
// nothing, a thin shell, a surface touching the grid's faces. The zero set is compared where it
// lies: voxels within a voxel of the dense result's surface, tolerance 0.05 voxel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <tuple>
#include <vector>

#include "core/field_view.h"
#include "level_set_fixtures.h"
#include "optimize/level_set.h"
#include "optimize/narrow_band.h"
#include "visopt/field.h"
#include "visopt/level_set.h"

namespace visopt {
namespace {

using namespace testing_fixtures;

GridSpec box(glm::ivec3 dims) {
  GridSpec g;
  g.dims = dims;
  g.spacing = glm::vec3(1.f);
  return g;
}

Field3D clone(const Field3D& f) {
  Field3D out("phi", f.grid(), f.precision());
  for (size_t v = 0; v < f.size(); ++v) out.set(v, f.get(v));
  return out;
}

// Largest |band - dense| over voxels within a voxel of the dense surface (|dense| <= 1), and
// whether the two agree on the sign of every voxel (no spurious or lost inside anywhere).
struct ZeroSetComparison {
  float worst = 0.f;
  int nearVoxels = 0;
  int signMismatches = 0;
};
ZeroSetComparison compare(const Field3D& band, const Field3D& dense) {
  ZeroSetComparison c;
  for (size_t v = 0; v < dense.size(); ++v) {
    const float d = dense.get(v), b = band.get(v);
    if ((d < 0.f) != (b < 0.f) && std::fabs(d) > 0.25f) ++c.signMismatches;
    if (std::fabs(d) > 1.f) continue;
    ++c.nearVoxels;
    c.worst = std::max(c.worst, std::fabs(b - d));
  }
  return c;
}

// Where the zero level set of phi (trilinear) crosses the ray from `centre` along `dir`: the
// first sign change outwards, by bisection; -1 when there is none within `reach`.
float zeroCrossing(const Field3D& phi, glm::vec3 centre, glm::vec3 dir, float reach) {
  const FieldView view(phi);
  const auto at = [&](float r) { return view.sample(phi.grid().worldToIndex(centre + r * dir)); };
  float lo = 0.f;
  for (float r = 0.25f; r <= reach; r += 0.25f) {
    if ((at(lo) < 0.f) != (at(r) < 0.f)) {
      float a = lo, b = r;
      for (int n = 0; n < 30; ++n) {
        const float m = 0.5f * (a + b);
        ((at(a) < 0.f) != (at(m) < 0.f) ? b : a) = m;
      }
      return 0.5f * (a + b);
    }
    lo = r;
  }
  return -1.f;
}

// The largest distance, over 400 directions, between the zero sets of a and b (and of each from
// a sphere of radius `exact`, when given > 0), in voxels.
struct ZeroSetDistance {
  float between = 0.f, aFromExact = 0.f, bFromExact = 0.f;
};
ZeroSetDistance zeroSetDistance(const Field3D& a, const Field3D& b, glm::vec3 centre, float reach,
                                float exact) {
  ZeroSetDistance z;
  for (glm::vec3 dir : directions(400)) {
    const float ra = zeroCrossing(a, centre, dir, reach), rb = zeroCrossing(b, centre, dir, reach);
    z.between = std::max(z.between, std::fabs(ra - rb));
    if (exact > 0.f) {
      z.aFromExact = std::max(z.aFromExact, std::fabs(ra - exact));
      z.bFromExact = std::max(z.bFromExact, std::fabs(rb - exact));
    }
  }
  return z;
}

struct SurfaceRun {
  Field3D phi;
  Field3D scratch;
  int64_t bandVoxels = 0;
};

// Each test runs for both precisions and both integrators of Eq. 23 (explicit Euler, the
// reference, and the semi-implicit step): the band must not change what either computes.
class LevelSetBand : public ::testing::TestWithParam<std::tuple<Precision, bool>> {
 protected:
  Precision precision() const { return std::get<0>(GetParam()); }
  LevelSetSettings settings() const {
    LevelSetSettings s;
    s.semiImplicit = std::get<1>(GetParam());
    return s;
  }
  float tolerance() const { return precision() == Precision::FP16 ? 0.06f : 0.05f; }
};

// Constant ghat: mean-curvature flow, with redistancing after every step as the optimiser does.
TEST_P(LevelSetBand, MeanCurvatureFlowMatchesTheDensePath) {
  const GridSpec g = box(glm::ivec3(96, 96, 96));
  const glm::vec3 centre(47.3f, 47.6f, 47.9f);
  const float radius = 20.f, c = 1.f;
  const Field3D phi0 = makeField("phi0", g, precision(), sphere(centre, radius));
  const Field3D ghat = makeField("ghat", g, precision(), [=](glm::vec3) { return c; });
  LevelSetSettings banded = settings();
  banded.lambda = 0.f;
  LevelSetSettings dense = banded;
  dense.band = 0.f;
  SurfaceRun b{makeField("phi", g, precision(), sphere(centre, radius)), {}};
  SurfaceRun d{clone(b.phi), {}};
  double t = 0.0;
  int64_t most = 0;
  while (t < 40.0) {
    const LevelSetStepStats sb = levelSetStep(b.phi, phi0, ghat, nullptr, banded, b.scratch);
    const LevelSetStepStats sd = levelSetStep(d.phi, phi0, ghat, nullptr, dense, d.scratch);
    ASSERT_EQ(sb.timeStep, sd.timeStep);
    EXPECT_EQ(sd.bandVoxels, 0);
    most = std::max(most, sb.bandVoxels);
    t += sb.timeStep * sb.substeps;
    redistance(b.phi, banded, b.scratch);
    redistance(d.phi, dense, d.scratch);
  }
  const ZeroSetComparison cmp = compare(b.phi, d.phi);
  const double expected = std::sqrt(double(radius) * radius - 4.0 * c * t);
  const ZeroSetDistance z = zeroSetDistance(b.phi, d.phi, centre, 40.f, float(expected));
  std::printf(
      "MCF to t = %.1f: r band %.3f, dense %.3f, analytic %.3f; zero sets %.4f voxel "
      "apart (band %.4f, dense %.4f from the analytic sphere); phi near the surface "
      "differs by %.4f voxel; band at most %lld of %zu voxels\n",
      t, equivalentRadius(b.phi), equivalentRadius(d.phi), expected, z.between, z.aFromExact,
      z.bFromExact, cmp.worst, static_cast<long long>(most), g.voxelCount());
  EXPECT_GT(cmp.nearVoxels, 1000);
  EXPECT_LT(z.between, tolerance());
  EXPECT_EQ(cmp.signMismatches, 0);
  EXPECT_NEAR(equivalentRadius(b.phi) * equivalentRadius(b.phi), expected * expected,
              0.03 * radius * radius);
  // The band is a band: the sphere's shell of bricks and the region it swept, not the box.
  EXPECT_GT(most, 0);
  EXPECT_LT(double(most), 0.5 * double(g.voxelCount()));
}

// The band kept between calls (NarrowBand) follows a surface that moves 30 voxels: mean-curvature
// flow (lambda = 0, so no band around phi0) shrinks a sphere of radius 36 to 6 (r^2 = R^2 - 4 c t).
// The inner bricks hold the start's distances until the surface comes near; they must be claimed
// across the faces of the active bricks as it does, or the surface stops at the band's old inner
// edge. Checks: the radius follows the analytic one; every voxel within the half-width of the
// final surface lies in an active brick (no holes); no active brick is far from it (no stale
// bricks) and the active set shrank with the surface.
TEST_P(LevelSetBand, TheBandFollowsASurfaceThirtyVoxels) {
  const GridSpec g = box(glm::ivec3(80, 80, 80));
  const glm::vec3 centre(39.4f, 39.7f, 39.6f);
  const float startRadius = 36.f, endRadius = 6.f, c = 1.f;
  const Field3D phi0 = makeField("phi0", g, precision(), sphere(centre, startRadius));
  const Field3D ghat = makeField("ghat", g, precision(), [=](glm::vec3) { return c; });
  LevelSetSettings s = settings();
  s.lambda = 0.f;
  s.substeps = 8;
  Field3D phi = clone(phi0), scratch;
  NarrowBand band;
  double t = 0.0;
  const double tEnd =
      (double(startRadius) * startRadius - double(endRadius) * endRadius) / (4.0 * c);
  int64_t firstBricks = -1, released = 0, activated = 0;
  double worstRadius = 0.0;
  while (t < tEnd) {
    const LevelSetStepStats st = levelSetStep(phi, phi0, ghat, nullptr, s, scratch, &band);
    if (firstBricks < 0) firstBricks = band.activeBricks();
    released += band.lastReleased();
    activated += band.lastActivated();
    t += st.timeStep * st.substeps;
    redistance(phi, s, scratch, &phi0, 3.f, &band);
    released += band.lastReleased();
    activated += band.lastActivated();
    const double expected =
        std::sqrt(std::max(0.0, double(startRadius) * startRadius - 4.0 * c * t));
    if (expected > 2.0 * endRadius)
      worstRadius = std::max(worstRadius, std::fabs(equivalentRadius(phi) - expected));
  }
  const double expected = std::sqrt(std::max(0.0, double(startRadius) * startRadius - 4.0 * c * t));
  const double radius = equivalentRadius(phi);
  // Coverage and staleness, against the analytic sphere of the final radius.
  std::vector<uint8_t> inBand(g.voxelCount(), 0);
  for (const RowSpan& r : band.band().spans)
    for (int x = r.x0; x < r.x1; ++x) inBand[size_t(r.row * g.dims.x + x)] = 1;
  int holes = 0, covered = 0;
  float farthest = 0.f;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const float dist = std::fabs(glm::length(glm::vec3(i, j, k) - centre) - float(expected));
        const size_t v = g.linearIndex(i, j, k);
        if (dist <= s.band) {
          ++covered;
          holes += !inBand[v];
        }
        if (inBand[v]) farthest = std::max(farthest, dist);
      }
  std::printf(
      "band follows MCF 36 -> 6: r %.3f, analytic %.3f (worst %.3f on the way); %lld bricks at "
      "the start, %lld at the end, %lld activated and %lld released; %d holes of %d voxels "
      "within the half-width; farthest band voxel %.1f voxels from the surface\n",
      radius, expected, worstRadius, static_cast<long long>(firstBricks),
      static_cast<long long>(band.activeBricks()), static_cast<long long>(activated),
      static_cast<long long>(released), holes, covered, farthest);
  // The semi-implicit step is first order in time with an error that grows with the curvature:
  // at the end (r ~ 6, steps of 8 substeps) it has shrunk the sphere too far, by 0.37 voxel in
  // fp32 and 0.51 in fp16 (the explicit path: 0.1; the cause of fp16's extra 0.14 is not pinned
  // down: the solves carry increments, whose fp16 rounding is fine near the surface).
  // test_level_set_semi_implicit checks the scheme's accuracy on its own.
  const bool semi = std::get<1>(GetParam());
  EXPECT_NEAR(radius, expected, !semi ? 0.3 : precision() == Precision::FP16 ? 0.55 : 0.45);
  EXPECT_LT(worstRadius, 0.3);
  EXPECT_GT(covered, 1000);
  EXPECT_EQ(holes, 0);
  // A face-claimed brick's nearest voxel lies within half-width + 1 + margin of the surface; its
  // farthest at most a brick diagonal more.
  EXPECT_LT(farthest, s.band + 1.f + NarrowBand::kReleaseMarginVoxels + std::sqrt(3.f) * kBrick);
  EXPECT_GT(activated, 0);
  EXPECT_GT(released, 0);
  EXPECT_LT(band.activeBricks(), firstBricks / 4);
}

// No importance, a large return term: phi starts as a sphere of radius 30 and must become phi0,
// a sphere of radius 12, 18 voxels away. Between the two lies the region the band must cover
// (phi and phi0 of opposite signs), or the old inside would stay as a spurious surface.
TEST_P(LevelSetBand, RelaxationFromFarAwayMatchesTheDensePath) {
  const GridSpec g = box(glm::ivec3(80, 80, 80));
  const glm::vec3 centre(39.5f, 40.2f, 39.8f);
  const Field3D phi0 = makeField("phi0", g, precision(), sphere(centre, 12.f));
  const Field3D ghat = makeField("ghat", g, precision(), [](glm::vec3) { return 0.f; });
  LevelSetSettings banded = settings();
  banded.lambda = 0.5f;
  LevelSetSettings dense = banded;
  dense.band = 0.f;
  SurfaceRun b{makeField("phi", g, precision(), sphere(centre, 30.f)), {}};
  SurfaceRun d{clone(b.phi), {}};
  for (int n = 0; n < 10; ++n) {
    levelSetStep(b.phi, phi0, ghat, nullptr, banded, b.scratch);
    levelSetStep(d.phi, phi0, ghat, nullptr, dense, d.scratch);
    redistance(b.phi, banded, b.scratch, &phi0, 3.f);
    redistance(d.phi, dense, d.scratch, &phi0, 3.f);
  }
  const ZeroSetComparison cmp = compare(b.phi, d.phi);
  std::printf("relaxation 30 -> 12: r band %.3f, dense %.3f; zero set differs by %.4f voxel\n",
              equivalentRadius(b.phi), equivalentRadius(d.phi), cmp.worst);
  EXPECT_NEAR(equivalentRadius(d.phi), 12.0, 0.1);
  EXPECT_NEAR(equivalentRadius(b.phi), 12.0, 0.1);
  EXPECT_LT(cmp.worst, tolerance());
  EXPECT_EQ(cmp.signMismatches, 0);
}

// A distorted sphere SDF redistanced in the band: |grad phi| within [0.95, 1.05] within three
// voxels of the surface, on voxels next to brick faces (index 7 or 8 mod 8) as everywhere.
TEST_P(LevelSetBand, RedistancingLeavesNoSeamsAtBrickFaces) {
  const GridSpec g = box(glm::ivec3(64, 64, 64));
  const glm::vec3 centre(31.3f, 32.1f, 31.7f);
  const float radius = 17.f;
  const Fn exact = sphere(centre, radius);
  Field3D phi = makeField("phi", g, precision(), [&](glm::vec3 x) {
    const float distortion = 1.f + 0.5f * std::sin(0.3f * x.x + 0.2f * x.y) * std::cos(0.25f * x.z);
    return exact(x) * distortion;
  });
  Field3D scratch;
  LevelSetSettings s = settings();
  s.redistanceIterations = 200;
  const RedistanceStats st = redistance(phi, s, scratch);
  EXPECT_GT(st.bandVoxels, 0);
  int faceVoxels = 0, faceOutside = 0, otherVoxels = 0, otherOutside = 0;
  for (int k = 1; k + 1 < g.dims.z; ++k)
    for (int j = 1; j + 1 < g.dims.y; ++j)
      for (int i = 1; i + 1 < g.dims.x; ++i) {
        const glm::vec3 x = g.indexToWorld(glm::vec3(i, j, k));
        if (std::fabs(exact(x)) > 3.f) continue;
        auto at = [&](int a, int b, int c) { return phi.get(g.linearIndex(a, b, c)); };
        const float m = glm::length(glm::vec3(at(i + 1, j, k) - at(i - 1, j, k),
                                              at(i, j + 1, k) - at(i, j - 1, k),
                                              at(i, j, k + 1) - at(i, j, k - 1))) /
                        2.f;
        const bool bad = m < 0.95f || m > 1.05f;
        const auto onFace = [](int n) { return n % 8 == 7 || n % 8 == 0; };
        if (onFace(i) || onFace(j) || onFace(k)) {
          ++faceVoxels;
          faceOutside += bad;
        } else {
          ++otherVoxels;
          otherOutside += bad;
        }
      }
  std::printf(
      "|grad phi| outside [0.95, 1.05]: %d of %d voxels at brick faces, %d of %d "
      "elsewhere\n",
      faceOutside, faceVoxels, otherOutside, otherVoxels);
  ASSERT_GT(faceVoxels, 1000);
  EXPECT_LE(double(faceOutside) / faceVoxels, 0.02);
  EXPECT_LE(double(faceOutside) / faceVoxels, double(otherOutside) / otherVoxels + 0.01);
}

// Extremes: a small sphere that mean-curvature flow shrinks to nothing (the band empties, no
// error, phi stays finite and positive), a thin shell thinner than a voxel and a surface cut by
// the grid's faces (the same answers as the dense path), a grid of one brick and a 1-voxel-thick
// grid.
TEST_P(LevelSetBand, ExtremesMatchTheDensePath) {
  struct Case {
    const char* name;
    glm::ivec3 dims;
    Fn phi;
    float ghat;
    int iterations;
  };
  const Case cases[] = {
      {"vanishing sphere", {40, 40, 40}, sphere(glm::vec3(19.5f), 3.f), 1.f, 30},
      {"thin shell 0.4 voxel",
       {48, 48, 48},
       [](glm::vec3 x) { return std::fabs(glm::length(x - glm::vec3(23.5f)) - 15.f) - 0.4f; },
       0.5f,
       4},
      {"sphere cut by the faces", {40, 40, 40}, sphere(glm::vec3(5.f, 20.f, 20.f), 14.f), 1.f, 8},
      {"one brick", {8, 8, 8}, sphere(glm::vec3(3.5f), 2.5f), 0.2f, 8},
      {"one voxel thick", {40, 40, 1}, sphere(glm::vec3(19.5f, 19.5f, 0.f), 10.f), 0.5f, 8},
  };
  for (const Case& cs : cases) {
    SCOPED_TRACE(cs.name);
    const GridSpec g = box(cs.dims);
    const Field3D phi0 = makeField("phi0", g, precision(), cs.phi);
    const Field3D ghat = makeField("ghat", g, precision(), [&](glm::vec3) { return cs.ghat; });
    LevelSetSettings banded = settings();
    banded.lambda = 0.f;
    LevelSetSettings dense = banded;
    dense.band = 0.f;
    SurfaceRun b{clone(phi0), {}};
    SurfaceRun d{clone(phi0), {}};
    for (int n = 0; n < cs.iterations; ++n) {
      levelSetStep(b.phi, phi0, ghat, nullptr, banded, b.scratch);
      levelSetStep(d.phi, phi0, ghat, nullptr, dense, d.scratch);
      redistance(b.phi, banded, b.scratch, &phi0, 3.f);
      redistance(d.phi, dense, d.scratch, &phi0, 3.f);
    }
    const ZeroSetComparison cmp = compare(b.phi, d.phi);
    int insideBand = 0, insideDense = 0;
    for (size_t v = 0; v < b.phi.size(); ++v) {
      insideBand += b.phi.get(v) < 0.f;
      insideDense += d.phi.get(v) < 0.f;
    }
    std::printf(
        "%s: zero set differs by %.4f voxel over %d voxels, %d sign mismatches; "
        "inside voxels: band %d, dense %d\n",
        cs.name, cmp.worst, cmp.nearVoxels, cmp.signMismatches, insideBand, insideDense);
    EXPECT_LT(cmp.worst, tolerance());
    EXPECT_EQ(cmp.signMismatches, 0);
    for (size_t v = 0; v < b.phi.size(); ++v) ASSERT_TRUE(std::isfinite(b.phi.get(v)));
  }
}

// Bricks where ghat is 0 (with a voxel around) and phi is still phi0 are a fixed point of the
// step and of redistancing against phi0 (narrow_band.h): the kernels skip them. A sphere opens
// where ghat = 0.6 > lambda (x below the middle) and stays put elsewhere; with the fixed bricks
// marked, every voxel of phi, every dt and every redistancing's pass count equal those of the
// same band path without the marks, bit for bit, while the kernels run over fewer voxels.
TEST_P(LevelSetBand, FixedBricksAreSkippedWithoutChangingAnything) {
  const GridSpec g = box(glm::ivec3(64, 64, 64));
  const glm::vec3 centre(31.6f, 32.2f, 31.9f);
  const Field3D phi0 = makeField("phi0", g, precision(), sphere(centre, 18.f));
  const Field3D ghat =
      makeField("ghat", g, precision(), [](glm::vec3 x) { return x.x < 24.f ? 0.6f : 0.f; });
  LevelSetSettings s = settings();
  s.lambda = 0.3f;
  s.substeps = 6;
  SurfaceRun marked{clone(phi0), {}}, plain{clone(phi0), {}};
  NarrowBand markedBand, plainBand;
  markFixedBricks(marked.phi, phi0, ghat, s, markedBand);
  ASSERT_TRUE(markedBand.fixedFor(ghat));
  EXPECT_GT(markedBand.fixedBricks(), 0);
  int64_t work = 0, band = 0;
  for (int n = 0; n < 12; ++n) {
    const LevelSetStepStats a =
        levelSetStep(marked.phi, phi0, ghat, nullptr, s, marked.scratch, &markedBand);
    const LevelSetStepStats b =
        levelSetStep(plain.phi, phi0, ghat, nullptr, s, plain.scratch, &plainBand);
    ASSERT_EQ(a.timeStep, b.timeStep) << "step " << n;
    EXPECT_EQ(a.bandVoxels, b.bandVoxels);
    work = a.workVoxels;
    band = a.bandVoxels;
    const RedistanceStats ra = redistance(marked.phi, s, marked.scratch, &phi0, 3.f, &markedBand);
    const RedistanceStats rb = redistance(plain.phi, s, plain.scratch, &phi0, 3.f, &plainBand);
    ASSERT_EQ(ra.iterations, rb.iterations) << "redistancing " << n;
    ASSERT_EQ(ra.meanSquaredChange, rb.meanSquaredChange);
  }
  size_t differ = 0, moved = 0;
  for (size_t v = 0; v < phi0.size(); ++v) {
    differ += marked.phi.get(v) != plain.phi.get(v);
    moved += plain.phi.get(v) != phi0.get(v);
  }
  std::printf("fixed bricks: %lld of %lld band voxels skipped, %zu voxels moved, %zu differ\n",
              static_cast<long long>(band - work), static_cast<long long>(band), moved, differ);
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(moved, 1000u) << "the sphere opened where ghat > lambda";
  EXPECT_LT(work, band) << "the fixed bricks were skipped";
  EXPECT_GT(work, 0);
}

INSTANTIATE_TEST_SUITE_P(PrecisionsAndIntegrators, LevelSetBand,
                         ::testing::Combine(::testing::Values(Precision::FP32, Precision::FP16),
                                            ::testing::Values(false, true)),
                         [](const auto& param) {
                           return std::string(std::get<0>(param.param) == Precision::FP16
                                                  ? "fp16"
                                                  : "fp32") +
                                  (std::get<1>(param.param) ? "_semi_implicit" : "_explicit");
                         });

}  // namespace
}  // namespace visopt
