// The per-voxel optimiser updates (AdEMAMix, Adam; docs/methods.md §2) against a scalar reference
// written here from the published update rules, and the fp16 second-moment underflow hazard.
#include <cmath>

#include <gtest/gtest.h>

#include "kernels/optimizer_update.h"
#include "visopt/field.h"

using namespace visopt;

namespace {

struct Reference {
  double m1 = 0, m2 = 0, nu = 0;
  // The PyTorch reference's rules, with nu (not its root) as state.
  double step(double g, int t, double b1, double b2, double b3, double alpha, double lr, double eps,
              bool ademamix) {
    m1 = b1 * m1 + (1 - b1) * g;
    nu = b2 * nu + (1 - b2) * g * g;
    double num = m1 / (1 - std::pow(b1, t));
    if (ademamix) {
      m2 = b3 * m2 + (1 - b3) * g;
      num += alpha * m2;
    }
    return -lr * num / (std::sqrt(nu) / std::sqrt(1 - std::pow(b2, t)) + eps);
  }
};

struct State {
  GridSpec grid;
  Field3D m1, m2, rms;
  explicit State(Precision p) {
    grid.dims = {1, 1, 1};
    m1 = Field3D("m1", grid, p);
    m2 = Field3D("m2", grid, p);
    rms = Field3D("rms", grid, p);
    m1.fill(0.f);
    m2.fill(0.f);
    rms.fill(0.f);
  }
  OptimizerState view() { return {FieldView(m1), FieldView(m2), FieldView(rms)}; }
};

OptimizerCoefficients coefficients(int t, bool ademamix) {
  OptimizerCoefficients c;
  c.ademamix = ademamix;
  c.lr = 0.01f;
  c.alpha = 5.f;
  c.beta3 = 0.9999f;
  c.biasCorrection1 = 1.f - std::pow(c.beta1, float(t));
  c.biasCorrection2 = std::sqrt(1.f - std::pow(c.beta2, float(t)));
  return c;
}

}  // namespace

TEST(OptimizerUpdate, MatchesTheReferenceRulesInFp32) {
  for (bool ademamix : {true, false}) {
    State s(Precision::FP32);
    Reference ref;
    OptimizerState st = s.view();
    for (int t = 1; t <= 50; ++t) {
      const double g = std::sin(0.3 * t) * 0.7 + 0.2;
      const float ours = st.step(0, float(g), coefficients(t, ademamix));
      const double theirs = ref.step(g, t, 0.9, 0.999, 0.9999, 5.0, 0.01, 1e-8, ademamix);
      // 1e-8 = 1e-6 lr: where m1 and alpha m2 nearly cancel, fp32 rounding dominates.
      ASSERT_NEAR(ours, theirs, 1e-4 * std::abs(theirs) + 1e-8) << "t " << t;
    }
  }
}

// Gradients of 1e-5: nu = g^2 ~ 1e-10 is below fp16's smallest subnormal (~6e-8). Storing nu in
// fp16 would flush it to 0 and the step would explode to lr * m / eps. Storing sqrt(nu) keeps
// the fp16 step within 15 % of fp32's even here, in fp16's subnormal range (the optimiser also
// rescales gradients per level so that typical ones are ~1: see extinction_optimizer.cpp).
TEST(OptimizerUpdate, Fp16StateSurvivesTinyGradients) {
  State s16(Precision::FP16), s32(Precision::FP32);
  OptimizerState a = s16.view(), b = s32.view();
  for (int t = 1; t <= 30; ++t) {
    const float g = 1e-5f * (1.f + 0.1f * float(t % 3));
    const float d16 = a.step(0, g, coefficients(t, true));
    const float d32 = b.step(0, g, coefficients(t, true));
    ASSERT_TRUE(std::isfinite(d16));
    EXPECT_NEAR(d16, d32, 0.15f * std::abs(d32)) << "t " << t;
    EXPECT_LT(std::abs(d16), 0.1f) << "an underflowed second moment would give ~lr*m/eps ~ 10";
  }
  // The hazard is real: nu itself is not representable in fp16.
  EXPECT_EQ(halfToFloat(floatToHalf(1e-10f)), 0.f);
}
