// The renderer's two scattering functions, written once (Himmler & Günther 2026, Eqs. 5 and 8;
// Ament, Zirr and Dachsbacher 2017 blend them in the volume): the Henyey–Greenstein phase function
// (Henyey and Greenstein 1941) and the normalised Blinn–Phong BRDF (Blinn 1977; normalised as in
// Akenine- Möller, Haines and Hoffman, Real-Time Rendering). Each takes its per-launch constants
// once and evaluates with a square-root and power function of the caller's choice: the ray marcher
// passes its fast host forms (kernels/ray_fast_math.h), surface shading the library's; test_shading
// holds both to the closed forms.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/hd.h"

namespace visopt {

constexpr float kPi = 3.14159265358979f;

struct ExactMath {
  VISOPT_HD VISOPT_INLINE float rsqrt(float x) const { return 1.f / sqrtf(x); }
  VISOPT_HD VISOPT_INLINE float pow(float x, float y) const { return powf(x, y); }
};

// p(cos theta) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2)), normalised over the sphere;
// g = 0 is isotropic (1 / 4 pi).
struct HenyeyGreenstein {
  float norm = 1.f / (4.f * kPi);  // (1 - g^2) / (4 pi)
  float a = 1.f, b = 0.f;          // the denominator's d = a - b cos theta
  HenyeyGreenstein() = default;
  VISOPT_HD explicit HenyeyGreenstein(float g)
      : norm((1.f - g * g) / (4.f * kPi)), a(1.f + g * g), b(2.f * g) {}
  template <class Math = ExactMath>
  VISOPT_HD VISOPT_INLINE float operator()(float cosTheta, const Math& math = {}) const {
    const float d = a - b * cosTheta;
    const float r = math.rsqrt(d);
    return b == 0.f ? norm : norm * (r * r * r);
  }
};

// f_r = kd / pi + ks (n + 8) / (8 pi) cos^n(theta_h), and with the cosine factor (n . l)+: the
// radiance a unit light sends towards the eye. One-sided: 0 when the light is behind n (the
// volume's gradient shading flips n towards the eye first, two-sided).
struct NormalisedBlinnPhong {
  float diffuse = 1.f / kPi;  // kd / pi
  float specular = 0.f;       // ks (n + 8) / (8 pi)
  float shininess = 1.f;
  NormalisedBlinnPhong() = default;
  VISOPT_HD NormalisedBlinnPhong(float kd, float ks, float n)
      : diffuse(kd / kPi), specular(ks * (n + 8.f) / (8.f * kPi)), shininess(n) {}

  // The lobe at cos theta_h (of the half vector with the normal), clamped at 0.
  template <class Math = ExactMath>
  VISOPT_HD VISOPT_INLINE float lobe(float cosH, const Math& math = {}) const {
    return diffuse +
           (specular > 0.f ? specular * math.pow(cosH > 0.f ? cosH : 0.f, shininess) : 0.f);
  }
  // f_r (n . l)+ for unit vectors n, toLight and toEye.
  template <class Math = ExactMath>
  VISOPT_HD VISOPT_INLINE float cosWeighted(glm::vec3 n, glm::vec3 toLight, glm::vec3 toEye,
                                            const Math& math = {}) const {
    const float cosL = glm::dot(n, toLight);
    if (cosL <= 0.f) return 0.f;
    float cosH = 0.f;
    if (specular > 0.f) {
      const glm::vec3 sum = toLight + toEye;
      cosH = glm::dot(n, sum * math.rsqrt(glm::dot(sum, sum)));
    }
    return lobe(cosH, math) * cosL;
  }
};

}  // namespace visopt
