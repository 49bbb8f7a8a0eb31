// The CPU backend's extinction step (host/extinction_step_rows.h: rows of voxels in SIMD lanes,
// what the optimiser runs on the CPU) against the per-voxel reference ExtinctionStep (what CUDA
// runs): from the same state, the same mu and optimiser moments to float round-off and the same
// sums, for fp32 and fp16 storage, AdEMAMix and Adam, with and without the light term, mu_bar
// from a stored field (coarse levels) and from the transfer function (the finest level), and
// frusta that leave part of the grid outside or behind the eye. The grid's rows (29 voxels) are
// not a whole number of SIMD chunks.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "host/extinction_step_rows.h"
#include "kernels/extinction_step.h"
#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/frustum.h"

using namespace visopt;

namespace {

struct Case {
  Precision precision;
  bool ademamix;
  bool light;
  bool transferBase;  // mu_bar from scalars and a table, else a stored field
  bool eyeInside;     // the view's eye inside the grid: voxels behind it and beside the frustum
  std::string name() const {
    return std::string(precision == Precision::FP16 ? "fp16" : "fp32") +
           (ademamix ? "_ademamix" : "_adam") + (light ? "_light" : "") +
           (transferBase ? "_transfer" : "_field") + (eyeInside ? "_eyeInside" : "");
  }
};

struct Problem {
  GridSpec grid;
  Field3D mu, m1, m2, rms, base, scalars, dView, dLight;
  FrustumGrid view, light;
  std::vector<glm::vec4> table;
};

Field3D randomField(const char* name, const GridSpec& g, Precision p, std::mt19937& rng, float lo,
                    float hi) {
  Field3D f(name, g, p);
  std::uniform_real_distribution<float> u(lo, hi);
  for (size_t v = 0; v < f.size(); ++v) f.set(v, u(rng));
  return f;
}

Problem makeProblem(const Case& c) {
  Problem p;
  p.grid.dims = glm::ivec3(29, 13, 11);
  p.grid.spacing = glm::vec3(0.05f, 0.07f, 0.06f);
  p.grid.origin = -0.5f * glm::vec3(p.grid.dims - 1) * p.grid.spacing;
  std::mt19937 rng(5);
  p.mu = randomField("mu", p.grid, c.precision, rng, 0.f, 4.f);
  p.m1 = randomField("m1", p.grid, c.precision, rng, -0.5f, 0.5f);
  p.m2 = randomField("m2", p.grid, c.precision, rng, -0.5f, 0.5f);
  p.rms = randomField("rms", p.grid, c.precision, rng, 0.f, 1.f);
  p.base = randomField("mu_bar", p.grid, c.precision, rng, 0.f, 4.f);
  p.scalars = randomField("scalars", p.grid, c.precision, rng, -0.1f, 1.1f);  // some clamp
  std::uniform_real_distribution<float> u(0.f, 4.f);
  for (int i = 0; i < 64; ++i) p.table.emplace_back(0.5f, 0.5f, 0.5f, u(rng));

  const Bounds bounds = p.grid.worldBounds();
  Camera cam;
  if (c.eyeInside) {
    // The eye inside the grid looking along +x at a box in front of it.
    cam.eye = glm::vec3(-0.2f, 0.01f, 0.02f);
    cam.target = glm::vec3(0.6f, 0.05f, 0.f);
    const Bounds front{glm::vec3(0.1f, -0.2f, -0.15f), glm::vec3(0.6f, 0.2f, 0.15f)};
    p.view = FrustumGrid::forCamera(cam, 21, 18, front, 40, p.grid.minSpacing());
  } else {
    cam.eye = glm::vec3(0.5f, -2.f, 0.8f);
    cam.target = glm::vec3(0.f);
    p.view = FrustumGrid::forCamera(cam, 37, 30, bounds, 0, p.grid.minSpacing());
  }
  PointLight l;
  l.position = glm::vec3(-1.5f, 1.f, 1.8f);
  p.light = FrustumGrid::forLight(l, bounds, glm::ivec3(19, 19, 0), p.grid.minSpacing());
  GridSpec fv, fl;
  fv.dims = frustumStorageDims(p.view.dims);
  fl.dims = frustumStorageDims(p.light.dims);
  p.dView = randomField("d_V", fv, c.precision, rng, -1.f, 1.f);
  p.dLight = randomField("d_L", fl, c.precision, rng, -1.f, 1.f);
  return p;
}

ExtinctionStep stepOf(Problem& p, const Case& c) {
  ExtinctionStep s;
  ExtinctionGradient& g = s.gradient;
  g.volume = GridMap(p.grid);
  g.mu = FieldView(p.mu);
  if (c.transferBase) {
    g.base.scalars = FieldView(p.scalars);
    g.base.transfer.table = p.table.data();
    g.base.transfer.size = int(p.table.size());
  } else {
    g.base.field = FieldView(p.base);
  }
  g.rho = 0.7f;
  g.q = 40.f;
  g.r = c.light ? 12.f : 0.f;
  g.view = FrustumMap(p.view);
  g.light = FrustumMap(p.light);
  g.dView = FrustumFieldView(p.dView, p.view.dims);
  if (c.light) g.dLight = FrustumFieldView(p.dLight, p.light.dims);
  s.state.m1 = FieldView(p.m1);
  s.state.rms = FieldView(p.rms);
  if (c.ademamix) s.state.m2 = FieldView(p.m2);
  OptimizerCoefficients& k = s.coefficients;
  k.ademamix = c.ademamix;
  k.lr = 0.2f;
  k.beta3 = 0.995f;
  k.alpha = 2.5f;
  k.biasCorrection1 = 0.271f;
  k.biasCorrection2 = 0.0561f;
  s.muMax = 3.5f;  // below some of mu: the projection clamps
  s.voxelVolume = 0.05f * 0.07f * 0.06f;
  s.gradientScale = 0.37f;
  return s;
}

void expectClose(const Field3D& a, const Field3D& b, const char* what, float relTol) {
  ASSERT_EQ(a.size(), b.size());
  int bad = 0;
  for (size_t v = 0; v < a.size() && bad < 5; ++v) {
    const float x = a.get(v), y = b.get(v);
    if (!(std::abs(x - y) <= relTol * std::max(1.f, std::abs(y)))) {
      ADD_FAILURE() << what << " at voxel " << v << ": rows " << x << ", reference " << y;
      ++bad;
    }
  }
}

class ExtinctionStepRows : public ::testing::TestWithParam<Case> {};

TEST_P(ExtinctionStepRows, MatchesThePerVoxelReference) {
  const Case c = GetParam();
  Problem ref = makeProblem(c), rows = makeProblem(c);
  const ExtinctionStep refStep = stepOf(ref, c), rowStep = stepOf(rows, c);
  const StepSums expected =
      exec::reduce("reference step", int64_t(ref.grid.voxelCount()), StepSums{}, refStep,
                   [](const StepSums& a, const StepSums& b) { return a + b; });
  const StepSums got = extinctionStepOnHost("rows step", rowStep);

  // The same operations; the compiler contracts the frustum mapping into FMAs differently in
  // the vectorised loop, which moves a sample's position by float round-off (~1e-6 of a frustum
  // coordinate). The random frustum fields here change by up to 2 between cells and q = 40
  // amplifies that into the gradient (~1e-4 absolute of |g| ~ 15; a wrong or missing term is
  // off by 1-50). fp16: a stored half can also flip by one unit (2^-11 relative).
  const float tol = c.precision == Precision::FP16 ? 1e-3f : 1e-4f;
  expectClose(rows.mu, ref.mu, "mu", tol);
  expectClose(rows.m1, ref.m1, "m1", tol);
  expectClose(rows.rms, ref.rms, "rms", tol);
  if (c.ademamix) expectClose(rows.m2, ref.m2, "m2", tol);
  EXPECT_NEAR(got.energyRho, expected.energyRho, 1e-9 * std::abs(expected.energyRho));
  EXPECT_NEAR(got.step2, expected.step2, 1e-4 * expected.step2 + 1e-12);

  // The step did something, and the projection was active: neither path is a no-op.
  size_t changed = 0, clamped = 0;
  const Problem before = makeProblem(c);
  for (size_t v = 0; v < rows.mu.size(); ++v) {
    changed += rows.mu.get(v) != before.mu.get(v) ? 1 : 0;
    clamped += rows.mu.get(v) == 0.f || rows.mu.get(v) == 3.5f ? 1 : 0;
  }
  EXPECT_GT(changed, rows.mu.size() / 2);
  EXPECT_GT(clamped, 0u);
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (Precision p : {Precision::FP32, Precision::FP16})
    for (bool adem : {true, false})
      for (bool light : {false, true})
        for (bool transfer : {false, true}) out.push_back({p, adem, light, transfer, false});
  out.push_back({Precision::FP32, true, true, true, true});
  out.push_back({Precision::FP16, true, false, false, true});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Cases, ExtinctionStepRows, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name(); });

// Mixed precisions take the per-voxel path inside extinctionStepOnHost: still the reference.
TEST(ExtinctionStepRowsMixed, FallsBackToThePerVoxelStep) {
  const Case c{Precision::FP32, true, true, false, false};
  Problem ref = makeProblem(c), rows = makeProblem(c);
  rows.m2 = Field3D("m2", rows.grid, Precision::FP16);
  ref.m2 = Field3D("m2", ref.grid, Precision::FP16);
  for (size_t v = 0; v < rows.m2.size(); ++v) rows.m2.set(v, 0.1f), ref.m2.set(v, 0.1f);
  const ExtinctionStep refStep = stepOf(ref, c), rowStep = stepOf(rows, c);
  exec::reduce("reference step", int64_t(ref.grid.voxelCount()), StepSums{}, refStep,
               [](const StepSums& a, const StepSums& b) { return a + b; });
  extinctionStepOnHost("rows step", rowStep);
  expectClose(rows.mu, ref.mu, "mu", 0.f);
  expectClose(rows.m2, ref.m2, "m2", 0.f);
}

}  // namespace
