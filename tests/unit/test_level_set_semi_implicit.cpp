// The semi-implicit level-set step (LevelSetSettings::semiImplicit, kernels/implicit_diffusion.h;
// issue 11) against analytic answers and against the explicit reference (Eq. 25, Alg. 1):
// - one line's tridiagonal solve against the system it solves (residual) and a linear field,
//   which diffusion with constant ghat leaves as it is;
// - mean-curvature flow of a sphere, r^2 = R^2 - 4 c t, in steps of 16 to 512 explicit substeps'
//   time each;
// - the same dented surface as the explicit path after the same flow time (an importance blob
//   behind a sphere's front: Fig. 3, middle);
// - the implicit return term: phi - phi0 shrinks by exactly 1 / (1 + dt lambda) per step;
// - stability far beyond the explicit limit (bounded by the data: no new extrema), fp16, a grid
//   one voxel thick, the world mask, and the band against the dense path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/device_bit_mask.h"
#include "core/field_access.h"
#include "core/field_view.h"
#include "kernels/implicit_diffusion.h"
#include "level_set_fixtures.h"
#include "optimize/level_set.h"
#include "optimize/narrow_band.h"
#include "visopt/bit_mask.h"
#include "visopt/field.h"
#include "visopt/level_set.h"

namespace visopt {
namespace {

using namespace testing_fixtures;

LevelSetSettings semiImplicit(int substeps) {
  LevelSetSettings s;
  s.semiImplicit = true;
  s.substeps = substeps;
  return s;
}

// Largest |a - b| over voxels within a voxel of b's surface (|b| <= 1): how far apart the two
// zero sets lie there, in voxels (unit spacing).
float nearSurfaceDiff(const Field3D& a, const Field3D& b) {
  float m = 0.f;
  for (size_t v = 0; v < a.size(); ++v)
    if (std::fabs(b.get(v)) <= 1.f) m = std::max(m, std::fabs(a.get(v) - b.get(v)));
  return m;
}

// ---- one group of lines ---------------------------------------------------------------------

// The solve of 8 lines of 13 voxels along y with Dirichlet ends, varying ghat, from an
// increment so far delta_0: u = phi^n + delta satisfies (I - r A) u = phi^n + delta_0 with A the
// flux-form operator of implicit_diffusion.h, written out here independently, to float
// round-off; the voxels at y = 0 and 14 lie outside the segment and keep phi^n.
TEST(SemiImplicitLines, SolvesTheTridiagonalSystem) {
  const glm::ivec3 dims(8, 15, 1);
  const size_t count = size_t(dims.x * dims.y);
  std::vector<float> before(count), delta(count), ghat(count);
  for (int j = 0; j < dims.y; ++j)
    for (int i = 0; i < dims.x; ++i) {
      const size_t v = size_t(j * dims.x + i);
      before[v] = std::sin(0.7f * float(j) + float(i)) * 3.f + 0.2f * float(j);
      delta[v] = (j == 0 || j == dims.y - 1) ? 0.f : 0.3f * std::cos(1.1f * float(j * i));
      ghat[v] = 0.5f + 0.45f * std::cos(1.3f * float(j) - 0.4f * float(i));
    }
  const std::vector<float> start = delta;
  ImplicitLines L;
  L.first = dims.x;  // y = 1
  L.step = dims.x;
  L.laneStep = 1;
  L.n = dims.y - 2;
  L.lanes = 8;
  const float r = 3.7f;  // dt / h^2: ~22x the explicit limit for ghat <= 0.95
  std::vector<float> work(size_t(2 * L.n * kImplicitLanes));
  const Fp32Access d{delta.data()}, g{ghat.data()}, b{before.data()};
  solveImplicitLines<Fp32Access, true>(d, g, b, L, r, work.data(), false);
  float worst = 0.f;
  for (int i = 0; i < dims.x; ++i)
    for (int j = 1; j + 1 < dims.y; ++j) {
      auto at = [&](const std::vector<float>& f, int jj) { return f[size_t(jj * dims.x + i)]; };
      auto u = [&](int jj) { return at(before, jj) + at(delta, jj); };
      const float wm = 0.5f * r * (at(ghat, j) + at(ghat, j - 1));
      const float wp = 0.5f * r * (at(ghat, j) + at(ghat, j + 1));
      const float lhs = u(j) - wp * (u(j + 1) - u(j)) + wm * (u(j) - u(j - 1));
      worst = std::max(worst, std::fabs(lhs - (at(before, j) + at(start, j))));
    }
  EXPECT_LT(worst, 2e-5f);
  for (int i = 0; i < dims.x; ++i) {  // outside the segment: not written
    EXPECT_EQ(delta[size_t(i)], 0.f);
    EXPECT_EQ(delta[size_t((dims.y - 1) * dims.x + i)], 0.f);
  }
}

// A linear field with constant ghat has no second difference: the first solve's increment is 0
// (up to round-off), also with faces at both ends and fewer lanes than the group holds.
TEST(SemiImplicitLines, LeavesALinearFieldInPlace) {
  const int n = 20;
  std::vector<float> before(size_t(n) * 3), ghat(before.size(), 0.8f), delta(before.size(), 7.f);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < 3; ++i) before[size_t(j * 3 + i)] = 1.5f * float(j) - 7.f + float(i);
  ImplicitLines L;
  L.first = 0;
  L.step = 3;
  L.laneStep = 1;
  L.n = n;
  L.lanes = 3;
  L.lowFace = L.highFace = true;
  std::vector<float> work(size_t(2 * n * kImplicitLanes));
  solveImplicitLines<Fp32Access, true>(Fp32Access{delta.data()}, Fp32Access{ghat.data()},
                                       Fp32Access{before.data()}, L, 50.f, work.data(), true);
  for (size_t v = 0; v < delta.size(); ++v) EXPECT_NEAR(delta[v], 0.f, 1e-4f) << v;
}

// ---- mean-curvature flow ------------------------------------------------------------------

// Constant ghat = c, lambda = 0: a sphere shrinks as r^2 = R^2 - 4 c t. Redistancing after
// every step, as in the optimiser; each step covers `substeps` explicit steps' time, moving the
// surface ~0.014 voxel per substep here: 8 to 32 substeps stay within the half voxel the
// optimiser allows a chunk, and are held to the explicit path's 3 % of R^2 (test_level_set);
// 64 (~0.9 voxel per step) to 4 %: the scheme is first order in time and shrinks the sphere a
// little too fast at long steps (measured 1.1 % at 16, 3.3 % at 64).
class SemiImplicitFlow : public ::testing::TestWithParam<int> {};

TEST_P(SemiImplicitFlow, SphereFollowsMeanCurvatureFlow) {
  const GridSpec g = cube(48);
  const glm::vec3 centre(23.5f);
  const float radius = 12.f, c = 1.f;
  Field3D phi0 = makeField("phi0", g, Precision::FP32, sphere(centre, radius));
  Field3D phi = makeField("phi", g, Precision::FP32, sphere(centre, radius));
  Field3D ghat = makeField("ghat", g, Precision::FP32, constant(c));
  Field3D scratch;
  LevelSetSettings s = semiImplicit(GetParam());
  s.lambda = 0.f;
  const double r0 = equivalentRadius(phi);
  double t = 0.0, worst = 0.0;
  int steps = 0;
  while (t < 20.0) {
    const LevelSetStepStats st = levelSetStep(phi, phi0, ghat, nullptr, s, scratch);
    t += st.timeStep * st.substeps;
    redistance(phi, s, scratch);
    const double r = equivalentRadius(phi);
    worst = std::max(worst, std::fabs(r * r - (r0 * r0 - 4.0 * c * t)) / (r0 * r0));
    ++steps;
  }
  std::printf(
      "semi-implicit, %d substeps per step: %d steps to t = %.2f, r = %.3f (expected "
      "%.3f), worst |r^2 - (R^2 - 4ct)| / R^2 = %.4f\n",
      GetParam(), steps, t, equivalentRadius(phi), std::sqrt(r0 * r0 - 4.0 * c * t), worst);
  EXPECT_LT(worst, GetParam() <= 32 ? 0.03 : 0.04);
}

INSTANTIATE_TEST_SUITE_P(StepLengths, SemiImplicitFlow, ::testing::Values(8, 16, 32, 64));

// ---- against the explicit reference --------------------------------------------------------

// Fig. 3, middle: a sphere whose front hides an important blob inside it; ghat is high in a
// cylinder in front of the blob. The explicit path runs 24 chunks of 32 substeps, redistancing
// after each as the optimiser does; the semi-implicit one the same flow time in steps of 8 and of
// 32 substeps. Measured: the explicit dent is 2.26 voxels deep, the semi-implicit one 2.30 at 8
// and 2.58 at 32 (first order in time, and a different O(dx) discretisation: docs/methods.md
// §3). Held to 0.15 voxel at 8 and 0.4 at 32 in depth, the zero sets (0.21 and 0.35 apart at
// most, at the rim) to 0.25 and 0.4 voxel.
TEST(SemiImplicitAgainstExplicit, DentsASphereLikeTheExplicitPath) {
  for (const Precision p : {Precision::FP32, Precision::FP16}) {
    const GridSpec g = cube(40);
    const glm::vec3 centre(19.5f);
    const Fn base = sphere(centre, 14.f);
    Field3D phi0 = makeField("phi0", g, p, base);
    // ghat: 0.9 within 5 voxels of the axis along -z in front of the centre, 0 beyond 8.
    Field3D ghat = makeField("ghat", g, p, [&](glm::vec3 x) {
      const float rho = std::hypot(x.x - centre.x, x.y - centre.y);
      const float across = std::clamp((8.f - rho) / 3.f, 0.f, 1.f);
      return x.z < centre.z ? 0.9f * across : 0.f;
    });
    Field3D scratch;
    auto run = [&](bool implicitStep, int chunk, float& depth) {
      Field3D phi = makeField("phi", g, p, base);
      LevelSetSettings s;
      s.semiImplicit = implicitStep;
      s.substeps = chunk;
      for (int n = 0; n < 24 * 32 / chunk; ++n) {
        levelSetStep(phi, phi0, ghat, nullptr, s, scratch);
        redistance(phi, s, scratch, &phi0, 3.f);
      }
      // How deep the dent is on the axis: how far the front's zero set moved in.
      const FieldView view(phi);
      depth = 0.f;
      for (float z = centre.z - 14.f; z < centre.z; z += 0.02f)
        if (view.sample(glm::vec3(centre.x, centre.y, z)) >= 0.f) depth = z - (centre.z - 14.f);
      return phi;
    };
    float explicitDepth = 0.f;
    const Field3D reference = run(false, 32, explicitDepth);
    EXPECT_GT(explicitDepth, 2.f);
    for (const int chunk : {8, 32}) {
      float depth = 0.f;
      const Field3D phi = run(true, chunk, depth);
      const float apart = nearSurfaceDiff(phi, reference);
      std::printf(
          "%s, steps of %d substeps: dent %.2f voxels deep (explicit %.2f); zero sets "
          "%.3f voxel apart\n",
          p == Precision::FP16 ? "fp16" : "fp32", chunk, depth, explicitDepth, apart);
      EXPECT_NEAR(depth, explicitDepth, chunk <= 8 ? 0.15f : 0.4f);
      EXPECT_LT(apart, chunk <= 8 ? 0.25f : 0.4f);
    }
  }
}

// ---- the return term ----------------------------------------------------------------------

// ghat = 0: no drive, so each step is the return term's exact solution,
// phi - phi0 <- (phi - phi0) exp(-lambda dt), at a dt where explicit Euler would overshoot
// (dt lambda = 8; explicit substeps of dt lambda = cfl = 0.5 give 0.5^16 instead of exp(-8)).
TEST(SemiImplicitReturn, RelaxesExponentiallyWithoutOvershoot) {
  for (const Precision p : {Precision::FP32, Precision::FP16}) {
    const GridSpec g = cube(16);
    Field3D phi0 = makeField("phi0", g, p, sphere(glm::vec3(7.5f), 5.f));
    const Fn start = [](glm::vec3 x) {
      return glm::length(x - glm::vec3(7.5f)) - 5.f + 3.f * std::sin(0.9f * x.x + 0.4f * x.z);
    };
    Field3D phi = makeField("phi", g, p, start);
    Field3D ghat = makeField("ghat", g, p, constant(0.f));
    Field3D scratch;
    LevelSetSettings s = semiImplicit(1);
    s.lambda = 0.5f;
    const double dt = levelSetTimeStep(ghat, s);  // cfl / lambda
    s.substeps = int(std::lround(8.0 / (dt * s.lambda)));
    const LevelSetStepStats st = levelSetStep(phi, phi0, ghat, nullptr, s, scratch);
    const double decay = std::exp(-st.timeStep * st.substeps * s.lambda);
    EXPECT_NEAR(decay, std::exp(-8.0), 1e-6);
    float worst = 0.f;
    for (int k = 0; k < g.dims.z; ++k)
      for (int j = 0; j < g.dims.y; ++j)
        for (int i = 0; i < g.dims.x; ++i) {
          const size_t v = g.linearIndex(i, j, k);
          const double expected =
              phi0.get(v) + (start(g.indexToWorld(glm::vec3(i, j, k))) - phi0.get(v)) * decay;
          worst = std::max(worst, float(std::fabs(phi.get(v) - expected)));
        }
    EXPECT_LT(worst, p == Precision::FP16 ? 8e-3f : 1e-5f);
  }
}

// ---- extremes -----------------------------------------------------------------------------

// 10^4 explicit steps' time in one step with a rough ghat: bounded by the data (the solves are
// M-matrices and the clamp and return term average), finite, and a surface still there.
TEST(SemiImplicitExtremes, HugeStepsStayBoundedByTheData) {
  for (const Precision p : {Precision::FP32, Precision::FP16}) {
    const GridSpec g = cube(24);
    const Fn base = sphere(glm::vec3(11.5f), 8.f);
    Field3D phi0 = makeField("phi0", g, p, base);
    Field3D phi = makeField("phi", g, p, base);
    Field3D ghat = makeField("ghat", g, p, [](glm::vec3 x) {
      return 0.5f + 0.5f * std::sin(2.1f * x.x) * std::cos(1.7f * x.y + 0.3f * x.z);
    });
    float lo = 1e30f, hi = -1e30f;
    for (size_t v = 0; v < phi.size(); ++v) {
      lo = std::min({lo, phi.get(v), phi0.get(v)});
      hi = std::max({hi, phi.get(v), phi0.get(v)});
    }
    Field3D scratch;
    LevelSetSettings s = semiImplicit(10000);
    levelSetStep(phi, phi0, ghat, nullptr, s, scratch);
    for (size_t v = 0; v < phi.size(); ++v) {
      ASSERT_TRUE(std::isfinite(phi.get(v)));
      ASSERT_GE(phi.get(v), lo - 1e-3f);
      ASSERT_LE(phi.get(v), hi + 1e-3f);
    }
  }
}

// A grid one voxel thick (the z solve has nothing to do) and one a single brick: no crash, and
// the 2D circle shrinks by curve-shortening flow as the explicit path has it.
TEST(SemiImplicitExtremes, ThinAndSingleBrickGrids) {
  for (const glm::ivec3 dims : {glm::ivec3(32, 32, 1), glm::ivec3(8, 8, 8), glm::ivec3(5, 3, 2)}) {
    GridSpec g;
    g.dims = dims;
    const glm::vec3 c = (glm::vec3(dims) - 1.f) * 0.5f;
    const Fn base = [&](glm::vec3 x) {
      return std::hypot(x.x - c.x, x.y - c.y) - 0.3f * float(std::min(dims.x, dims.y));
    };
    std::vector<Field3D> results;
    for (const bool implicitStep : {false, true}) {
      Field3D phi0 = makeField("phi0", g, Precision::FP32, base);
      Field3D phi = makeField("phi", g, Precision::FP32, base);
      Field3D ghat = makeField("ghat", g, Precision::FP32, constant(0.5f));
      Field3D scratch;
      LevelSetSettings s;
      s.semiImplicit = implicitStep;
      s.lambda = 0.f;
      s.substeps = 2;
      for (int n = 0; n < 2; ++n) levelSetStep(phi, phi0, ghat, nullptr, s, scratch);
      for (size_t v = 0; v < phi.size(); ++v) ASSERT_TRUE(std::isfinite(phi.get(v)));
      results.push_back(std::move(phi));
    }
    // The smallest grid's circle (radius 0.9) is below what either scheme resolves.
    if (dims.x >= 8) {
      EXPECT_LT(nearSurfaceDiff(results[1], results[0]), 0.2f)
          << dims.x << "x" << dims.y << "x" << dims.z;
    }
  }
}

// The world mask turns the drive off: masked voxels only relax back to phi0 (here: stay at it).
TEST(SemiImplicitExtremes, MaskedVoxelsKeepTheirBase) {
  const GridSpec g = cube(24);
  const Fn base = sphere(glm::vec3(11.5f), 8.f);
  Field3D phi0 = makeField("phi0", g, Precision::FP32, base);
  Field3D phi = makeField("phi", g, Precision::FP32, base);
  Field3D ghat = makeField("ghat", g, Precision::FP32, constant(0.9f));
  BitMask bits = BitMask::cleared(g.dims);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < 12; ++i) bits.set(g.linearIndex(i, j, k), true);
  const DeviceBitMask mask(bits, "mask", nullptr);
  Field3D scratch;
  LevelSetSettings s = semiImplicit(64);
  levelSetStep(phi, phi0, ghat, &mask, s, scratch);
  float maskedMoved = 0.f, freeMoved = 0.f;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const size_t v = g.linearIndex(i, j, k);
        const float moved = std::fabs(phi.get(v) - phi0.get(v));
        (i < 12 ? maskedMoved : freeMoved) = std::max(i < 12 ? maskedMoved : freeMoved, moved);
      }
  EXPECT_EQ(maskedMoved, 0.f);
  EXPECT_GT(freeMoved, 0.2f);
}

// ---- the narrow band ----------------------------------------------------------------------

// Band against dense for the semi-implicit step: the band's lines end at its edge, where the
// stale values enter as Dirichlet data; within a voxel of the surface the two agree to 0.05
// voxel after the sphere shrank by several voxels.
TEST(SemiImplicitBand, MatchesTheDensePath) {
  for (const Precision p : {Precision::FP32, Precision::FP16}) {
    const GridSpec g = cube(56);
    const Fn base = sphere(glm::vec3(27.5f), 20.f);
    std::vector<Field3D> results;
    for (const float band : {0.f, 8.f}) {
      Field3D phi0 = makeField("phi0", g, p, base);
      Field3D phi = makeField("phi", g, p, base);
      Field3D ghat = makeField("ghat", g, p, constant(0.8f));
      Field3D scratch;
      LevelSetSettings s = semiImplicit(32);
      s.lambda = 0.f;
      s.band = band;
      NarrowBand narrow;
      for (int n = 0; n < 20; ++n) {
        levelSetStep(phi, phi0, ghat, nullptr, s, scratch, &narrow);
        redistance(phi, s, scratch, nullptr, 3.f, &narrow);
      }
      results.push_back(std::move(phi));
    }
    const double rDense = equivalentRadius(results[0]);
    EXPECT_LT(rDense, 17.5);  // it moved
    EXPECT_LT(nearSurfaceDiff(results[1], results[0]), p == Precision::FP16 ? 0.06f : 0.05f);
    EXPECT_NEAR(equivalentRadius(results[1]), rDense, 0.02);
  }
}

}  // namespace
}  // namespace visopt
