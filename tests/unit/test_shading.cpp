// The renderer's scattering functions (kernels/shading.h) against their closed forms: the
// Henyey–Greenstein phase function integrates to 1 over the sphere with mean cosine g; the
// normalised Blinn–Phong BRDF's diffuse part reflects kd of a normally incident light, its value
// at the mirror direction is kd/pi + ks (n+8)/(8 pi) times the cosine, and it is one-sided. The ray
// marcher's evaluation with its fast host math (RayMarchKernel) matches the exact one.
#include <cmath>

#include <gtest/gtest.h>

#include "kernels/ray_march.h"
#include "kernels/shading.h"

using namespace visopt;

namespace {

// 2 pi * integral over mu = cos theta in [-1, 1] of f(mu), midpoint rule.
template <class F>
double overSphere(F f, int n = 400000) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double mu = -1.0 + (double(i) + 0.5) * 2.0 / double(n);
    sum += double(f(float(mu)));
  }
  return 2.0 * M_PI * sum * 2.0 / double(n);
}

}  // namespace

TEST(Shading, HenyeyGreensteinIsNormalisedWithMeanCosineG) {
  for (float g : {-0.8f, -0.3f, 0.f, 0.5f, 0.9f}) {
    const HenyeyGreenstein p(g);
    EXPECT_NEAR(overSphere([&](float mu) { return p(mu); }), 1.0, 2e-4) << "g = " << g;
    EXPECT_NEAR(overSphere([&](float mu) { return mu * p(mu); }), double(g), 2e-4) << "g = " << g;
    // The closed form at a few angles.
    for (float mu : {-1.f, -0.2f, 0.f, 0.7f, 1.f}) {
      const double d = 1.0 + double(g) * g - 2.0 * double(g) * mu;
      const double expected = (1.0 - double(g) * g) / (4.0 * M_PI * d * std::sqrt(d));
      EXPECT_NEAR(p(mu), expected, 1e-5 * expected) << "g = " << g << ", cos = " << mu;
    }
  }
  EXPECT_FLOAT_EQ(HenyeyGreenstein(0.f)(0.3f), float(1.0 / (4.0 * M_PI)));
}

TEST(Shading, NormalisedBlinnPhongClosedForms) {
  const glm::vec3 n(0.f, 0.f, 1.f);
  // Diffuse only: a light along the normal is reflected with albedo kd over the hemisphere.
  const NormalisedBlinnPhong diffuse(0.7f, 0.f, 16.f);
  const double reflected = overSphere([&](float mu) {
    if (mu <= 0.f) return 0.f;
    const glm::vec3 toEye(std::sqrt(1.f - mu * mu), 0.f, mu);
    // f_r for a light along n: cosWeighted with toLight = n gives f_r * 1; times cos(out).
    return diffuse.cosWeighted(n, n, toEye) * mu;
  });
  EXPECT_NEAR(reflected, 0.7, 1e-4);

  // The mirror direction: the half vector is the normal, cos theta_h = 1.
  const float kd = 0.6f, ks = 0.3f, shininess = 24.f;
  const NormalisedBlinnPhong brdf(kd, ks, shininess);
  const glm::vec3 toLight = glm::normalize(glm::vec3(0.5f, 0.f, 1.f));
  const glm::vec3 toEye = glm::normalize(glm::vec3(-0.5f, 0.f, 1.f));
  const float cosL = glm::dot(n, toLight);
  const double mirror = (kd / M_PI + ks * (shininess + 8.0) / (8.0 * M_PI)) * cosL;
  EXPECT_NEAR(brdf.cosWeighted(n, toLight, toEye), mirror, 1e-5 * mirror);
  // Off the mirror direction: cos^n of the half vector's angle.
  const glm::vec3 eye2 = glm::normalize(glm::vec3(0.2f, 0.3f, 1.f));
  const double cosH = glm::dot(n, glm::normalize(toLight + eye2));
  const double off =
      (kd / M_PI + ks * (shininess + 8.0) / (8.0 * M_PI) * std::pow(cosH, shininess)) * cosL;
  EXPECT_NEAR(brdf.cosWeighted(n, toLight, eye2), off, 1e-5 * off);
  // One-sided: nothing from a light behind the surface, whatever the eye.
  EXPECT_EQ(brdf.cosWeighted(n, -toLight, toEye), 0.f);
}

TEST(Shading, TheRayMarchersFastMathMatchesTheExactForms) {
  RayMarchParams params;
  params.hg = 0.45f;
  params.kd = 0.8f;
  params.ks = 0.35f;
  params.shininess = 20.f;
  const RayMarchKernel kernel(params);
  const HenyeyGreenstein exactPhase(0.45f);
  for (float mu = -1.f; mu <= 1.f; mu += 0.05f)
    EXPECT_NEAR(kernel.phaseHG(mu), exactPhase(mu), 2e-4 * exactPhase(mu)) << "cos = " << mu;
  const NormalisedBlinnPhong exact(0.8f, 0.35f, 20.f);
  const glm::vec3 n = glm::normalize(glm::vec3(0.1f, -0.2f, 1.f));
  for (float a = 0.f; a < 6.28f; a += 0.3f) {
    const glm::vec3 toLight = glm::normalize(glm::vec3(std::cos(a), std::sin(a), 0.8f));
    const glm::vec3 toEye = glm::normalize(glm::vec3(-0.3f, 0.4f, 1.f));
    const float want = exact.cosWeighted(n, toLight, toEye);
    EXPECT_NEAR(kernel.brdf.cosWeighted(n, toLight, toEye, kernel.fastMath), want,
                2e-4 * want + 1e-7)
        << "light azimuth " << a;
  }
}
