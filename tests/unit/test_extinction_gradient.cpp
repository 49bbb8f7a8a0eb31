// The analytic gradient of the extinction energy (Himmler & Günther 2026, Eqs. 10-13,
// docs/methods.md §1) against central finite differences of the discrete energy
// (kernels/visibility_scan.h).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/frustum_map.h"
#include "optimize/extinction_optimizer.h"

using namespace visopt;

namespace {

struct Problem {
  GridSpec grid;
  Field3D mu, g, base;
  ExtinctionProblem p;
};

void fill(Field3D& f, std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  for (size_t i = 0; i < f.size(); ++i) f.set(i, u(rng));
}

// A camera far away along -y whose rays pass through the voxel columns' centres and whose depth
// cells coincide with the voxel planes: the frustum is aligned with the grid.
FrustumGrid alignedFrustum(const GridSpec& g, float distance, int axis) {
  FrustumGrid f;
  const glm::vec3 c = g.worldBounds().center();
  glm::vec3 fwd(0.f), right(0.f), up(0.f);
  int a = axis, b = (axis + 1) % 3, e = (axis + 2) % 3;
  fwd[a] = 1.f;
  right[b] = 1.f;
  up[e] = 1.f;
  f.eye = c - distance * fwd;
  f.forward = fwd;
  f.right = right;
  f.up = up;
  f.dims = glm::ivec3(g.dims[b], g.dims[e], g.dims[a]);
  f.tanHalfFovX = float(g.dims[b]) * g.spacing[b] / (2.f * distance);
  f.tanHalfFovY = float(g.dims[e]) * g.spacing[e] / (2.f * distance);
  const float firstPlane = g.worldBounds().lo[a];
  f.sNear = (firstPlane - f.eye[a]) - 0.5f * g.spacing[a];
  f.sFar = f.sNear + float(g.dims[a]) * g.spacing[a];
  return f;
}

double energyAt(Problem& pr) {
  return evaluateProblem(pr.p, Precision::FP32).energy();
}

Problem makeProblem(glm::ivec3 dims, glm::vec3 spacing, uint32_t seed) {
  Problem pr;
  pr.grid.dims = dims;
  pr.grid.spacing = spacing;
  pr.grid.origin = -0.5f * glm::vec3(dims - 1) * spacing;
  pr.mu = Field3D("mu", pr.grid, Precision::FP32);
  pr.g = Field3D("g", pr.grid, Precision::FP32);
  pr.base = Field3D("base", pr.grid, Precision::FP32);
  std::mt19937 rng(seed);
  fill(pr.mu, rng, 0.05f, 0.4f);
  fill(pr.g, rng, 0.f, 1.f);
  fill(pr.base, rng, 0.05f, 0.4f);
  pr.p.grid = pr.grid;
  pr.p.mu = &pr.mu;
  pr.p.importance = &pr.g;
  pr.p.baseField = &pr.base;
  return pr;
}

}  // namespace

TEST(ExtinctionGradient, MatchesFiniteDifferencesWhereTheFrustumIsAligned) {
  Problem pr = makeProblem({5, 7, 4}, {1.f, 1.f, 1.f}, 7);
  pr.p.rho = 0.7f;
  pr.p.q = 1.3f;
  pr.p.r = 0.6f;
  pr.p.view = alignedFrustum(pr.grid, 5000.f, 1);   // camera along +y
  pr.p.light = alignedFrustum(pr.grid, 5000.f, 0);  // light along +x
  const std::vector<float> grad = analyticGradient(pr.p, Precision::FP32);
  const float dV = 1.f;
  float maxAbs = 0.f;
  for (float v : grad) maxAbs = std::max(maxAbs, std::abs(v));
  ASSERT_GT(maxAbs, 0.f);
  const float h = 2e-3f;
  for (size_t v = 0; v < pr.mu.size(); ++v) {
    const float m = pr.mu.get(v);
    pr.mu.set(v, m + h);
    const double ep = energyAt(pr);
    pr.mu.set(v, m - h);
    const double em = energyAt(pr);
    pr.mu.set(v, m);
    const double fd = (ep - em) / (2.0 * h);
    // Cell volumes differ from voxel volumes by (1 +- extent/distance)^2, ~0.1 % here.
    EXPECT_NEAR(grad[v] * dV, fd, 2e-3 * maxAbs + 3e-3 * std::abs(fd)) << "voxel " << v;
  }
}

TEST(ExtinctionGradient, EachTermAloneMatchesFiniteDifferences) {
  // rho only, q only, r only: a wrong sign or a missing term in any one of them fails here.
  for (int term = 0; term < 3; ++term) {
    Problem pr = makeProblem({4, 6, 4}, {1.f, 1.f, 1.f}, 11 + uint32_t(term));
    pr.p.rho = term == 0 ? 1.f : 0.f;
    pr.p.q = term == 1 ? 1.f : 0.f;
    pr.p.r = term == 2 ? 1.f : 0.f;
    pr.p.view = alignedFrustum(pr.grid, 5000.f, 1);
    pr.p.light = alignedFrustum(pr.grid, 5000.f, 2);
    const std::vector<float> grad = analyticGradient(pr.p, Precision::FP32);
    for (size_t v : {size_t(0), size_t(17), size_t(40), pr.mu.size() - 1}) {
      const float m = pr.mu.get(v), h = 2e-3f;
      pr.mu.set(v, m + h);
      const double ep = energyAt(pr);
      pr.mu.set(v, m - h);
      const double em = energyAt(pr);
      pr.mu.set(v, m);
      const double fd = (ep - em) / (2.0 * h);
      EXPECT_NEAR(grad[v], fd, 3e-3 * std::max(1.0, std::abs(fd)))
          << "term " << term << " voxel " << v;
    }
  }
}

// General position: a perspective camera and light at oblique angles, frustum cells smaller than
// the voxels. The gradient gathers per-unit-volume densities by interpolation (not the exact
// adjoint of the sampling), so only the directional derivative along the gradient is compared.
TEST(ExtinctionGradient, DirectionalDerivativeMatchesInGeneralPosition) {
  Problem pr = makeProblem({8, 8, 8}, {1.f, 1.2f, 0.9f}, 3);
  // Smooth fields: the gather's interpolation error is small for smooth integrands.
  const GridMap map(pr.grid);
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const size_t v = pr.grid.linearIndex(i, j, k);
        const glm::vec3 x = map.toWorld(glm::vec3(float(i), float(j), float(k)));
        pr.mu.set(v, 0.2f + 0.1f * std::sin(0.4f * x.x) * std::cos(0.3f * x.y + 0.2f * x.z));
        pr.base.set(v, 0.25f);
        pr.g.set(v, std::exp(-0.05f * glm::dot(x - glm::vec3(1, 2, 0), x - glm::vec3(1, 2, 0))));
      }
  pr.p.rho = 0.5f;
  pr.p.q = 2.f;
  pr.p.r = 1.f;
  const Bounds b = pr.grid.worldBounds();
  Camera cam = Camera::orbit(b.center(), 35.f, 25.f, 22.f);
  pr.p.view = FrustumGrid::forCamera(cam, 96, 96, b, 0, 0.5f);
  PointLight light;
  light.position = b.center() + glm::vec3(-15.f, 9.f, 12.f);
  pr.p.light = FrustumGrid::forLight(light, b, {96, 96, 0}, 0.5f);
  const std::vector<float> grad = analyticGradient(pr.p, Precision::FP32);
  const float dV = 1.f * 1.2f * 0.9f;
  double analytic = 0.0;
  for (float gv : grad) analytic -= double(gv) * double(gv) * dV;  // along delta = -grad
  const double h = 1e-3;
  auto shifted = [&](double s) {
    Field3D copy("mu", pr.grid, Precision::FP32);
    for (size_t v = 0; v < pr.mu.size(); ++v) copy.set(v, pr.mu.get(v) - float(s) * grad[v]);
    ExtinctionProblem p2 = pr.p;
    p2.mu = &copy;
    return evaluateProblem(p2, Precision::FP32).energy();
  };
  const double fd = (shifted(h) - shifted(-h)) / (2.0 * h);
  ASSERT_LT(analytic, 0.0);
  EXPECT_LT(fd, 0.0) << "the energy must fall along the negative gradient";
  EXPECT_NEAR(fd / analytic, 1.0, 0.05);
}
