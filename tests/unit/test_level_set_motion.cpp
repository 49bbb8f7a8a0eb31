// What the level-set step reports about motion (LevelSetStepStats), which decides when the
// optimiser redistances: nearMaxChange is how far the zero set moved, not how much phi changed
// next to it, and insideRise is how fast a kink of the inside comes up towards zero. Analytic
// cases: a plane relaxing (Eq. 23's return term, no importance) to a shifted plane moves its zero
// set by exactly dt lambda shift per substep; relaxing to a field with the same zero plane but
// a different slope changes phi a voxel away and more, and moves no surface; mean-curvature
// flow of a ball raises its centre (the inside's kink), of the outside of a hole nothing.
#include <gtest/gtest.h>

#include <cmath>

#include "level_set_fixtures.h"
#include "optimize/level_set.h"
#include "visopt/field.h"
#include "visopt/level_set.h"

namespace visopt {
namespace {

using namespace testing_fixtures;

// phi = x - x0 over a 32^3 grid of unit voxels, the plane through voxel centres.
constexpr float kPlane = 15.f;

LevelSetStepStats relaxOnce(const Fn& phi0Fn, Precision p, float band, bool semiImplicit = false) {
  const GridSpec g = cube(32);
  const Field3D phi0 = makeField("phi0", g, p, phi0Fn);
  const Field3D ghat = makeField("ghat", g, p, constant(0.f));
  Field3D phi = makeField("phi", g, p, [](glm::vec3 x) { return x.x - kPlane; });
  Field3D scratch;
  LevelSetSettings s;
  s.lambda = 0.5f;
  s.substeps = 1;
  s.band = band;
  s.semiImplicit = semiImplicit;
  return levelSetStep(phi, phi0, ghat, nullptr, s, scratch);
}

class LevelSetMotion : public ::testing::TestWithParam<float> {};  // the band (0: dense)

TEST_P(LevelSetMotion, AShiftedPlaneMovesTheZeroSetByTheRelaxation) {
  const float shift = 0.6f;
  for (const bool semiImplicit : {false, true}) {
    const LevelSetStepStats st = relaxOnce([=](glm::vec3 x) { return x.x - kPlane + shift; },
                                           Precision::FP32, GetParam(), semiImplicit);
    // Explicit: phi += dt lambda (phi0 - phi) = dt lambda shift everywhere, the plane moves by
    // that much; semi-implicit: the return term's exact decay, (1 - exp(-dt lambda)) shift.
    const double dtLambda = st.timeStep * 0.5;
    const double expected = semiImplicit ? (1.0 - std::exp(-dtLambda)) * shift : dtLambda * shift;
    EXPECT_GT(expected, 0.1);
    EXPECT_NEAR(st.nearMaxChange, expected, 1e-4 * expected) << semiImplicit;
    EXPECT_NEAR(st.maxChange, expected, 1e-4 * expected) << semiImplicit;
  }
}

TEST_P(LevelSetMotion, ASteeperFieldAboutTheSameZeroPlaneMovesNoSurface) {
  // phi0 = 3 (x - x0): the same zero set; the return term changes phi by dt lambda 2 (x - x0),
  // a voxel away from the plane and more, and not on it.
  const LevelSetStepStats st =
      relaxOnce([](glm::vec3 x) { return 3.f * (x.x - kPlane); }, Precision::FP32, GetParam());
  EXPECT_GT(st.maxChange, 1.0);  // far away phi changed a lot
  EXPECT_LT(st.nearMaxChange, 1e-6);
  // Outside, phi rises away from zero; inside it falls away from it: no kink comes up.
  EXPECT_EQ(st.insideRise, 0.0);
}

TEST_P(LevelSetMotion, TheInsideRisesAtAKinkNotOutside) {
  // Mean-curvature flow of a ball: its centre, where |grad phi| kinks, rises fastest.
  const GridSpec g = cube(32);
  const glm::vec3 centre(15.5f, 15.3f, 15.4f);
  const Field3D ball = makeField("phi0", g, Precision::FP32, sphere(centre, 9.f));
  const Field3D ghat = makeField("ghat", g, Precision::FP32, constant(1.f));
  LevelSetSettings s;
  s.lambda = 0.f;
  s.substeps = 1;
  s.band = GetParam();
  Field3D phi = makeField("phi", g, Precision::FP32, sphere(centre, 9.f)), scratch;
  const LevelSetStepStats in = levelSetStep(phi, ball, ghat, nullptr, s, scratch);
  EXPECT_GT(in.insideRise, 0.1 * in.timeStep);
  // The complement (a spherical hole in an infinite inside... here: outside negative): the
  // centre is outside now and its kink falls away from zero; the inside (phi < 0 beyond the
  // hole) is smooth and its curvature term is clamped at max(0, .) = rises only slowly.
  const Field3D hole = makeField("phi0", g, Precision::FP32,
                                 [&](glm::vec3 x) { return -(glm::length(x - centre) - 9.f); });
  Field3D phi2 = makeField("phi", g, Precision::FP32,
                           [&](glm::vec3 x) { return -(glm::length(x - centre) - 9.f); });
  const LevelSetStepStats out = levelSetStep(phi2, hole, ghat, nullptr, s, scratch);
  EXPECT_LT(out.insideRise, 0.25 * in.insideRise);
}

INSTANTIATE_TEST_SUITE_P(BandAndDense, LevelSetMotion, ::testing::Values(8.f, 0.f),
                         [](const auto& param) {
                           return std::string(param.param > 0.f ? "band" : "dense");
                         });

}  // namespace
}  // namespace visopt
