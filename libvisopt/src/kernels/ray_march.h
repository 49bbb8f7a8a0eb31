// The volume part of the single-scattering renderer, paper 000 Eqs. 6-9:
//   L(x0 <- w) = integral T_V(x) f_p(x, wL <-> w) mu_s(x) L_i(x) dx + T_V(x_s) L_background,
//   mu_s = mu_t * a (Eq. 3), L_i(x) = T_L(g_L(x)) L_e (Eq. 9).
// Each march segment of length h is integrated exactly for constant mu over the segment:
// its in-scattering weight is T_V * (1 - exp(-mu h)) (= integral of T_V mu over the segment),
// then T_V *= exp(-mu h). The phase function f_p blends Henyey-Greenstein with normalised
// Blinn-Phong about the scalar gradient (as Ament et al. 2017 combine them).
// The surface term (Eq. 8) will enter here as the reduced surface radiance at the first hit.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/ray_box.h"
#include "kernels/transfer_lookup.h"

namespace visopt {

constexpr float kPi = 3.14159265358979f;

VISOPT_HD inline float henyeyGreenstein(float cosTheta, float g) {
  float d = 1.f + g * g - 2.f * g * cosTheta;
  return (1.f - g * g) / (4.f * kPi * d * sqrtf(d));
}

// Normalised Blinn-Phong with the cosine factor, two-sided about n.
VISOPT_HD inline float blinnPhong(glm::vec3 n, glm::vec3 toLight, glm::vec3 toEye, float kd,
                                  float ks, float shininess) {
  if (glm::dot(n, toEye) < 0.f) n = -n;
  float cosL = glm::dot(n, toLight);
  if (cosL <= 0.f) return 0.f;
  glm::vec3 h = glm::normalize(toLight + toEye);
  float cosH = fmaxf(glm::dot(n, h), 0.f);
  return (kd / kPi + ks * (shininess + 8.f) / (8.f * kPi) * powf(cosH, shininess)) * cosL;
}

// A small integer hash for per-pixel jitter (deterministic for a seed).
VISOPT_HD inline float hashToUnit(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return float(x >> 8) * (1.f / 16777216.f);
}

struct RayMarchParams {
  FrustumMap camera;  // dims.x, dims.y = image size
  GridMap volume;
  FieldView scalars;     // normalised scalars
  FieldView extinction;  // optimised mu; invalid -> mu_bar from the transfer function
  TransferLookup transfer;
  FrustumMap light;
  FieldView lightTransmittance;  // T_L on the light frustum grid; invalid -> unshadowed
  glm::vec3 lightPosition{0.f};
  glm::vec3 lightRadiance{1.f};  // L_e times colour
  float step = 1.f;              // world units
  bool jitter = true;
  uint32_t seed = 1;
  float hg = 0.f, kd = 1.f, ks = 0.f, shininess = 1.f, surfaceGradient = 0.04f;
  float ambient = 0.f;
  glm::vec3 background{0.f};
  float earlyStop = 1e-4f;
  glm::vec3* pixels = nullptr;  // row 0 at the top
};

struct RayMarchKernel {
  RayMarchParams p;

  VISOPT_HD float extinctionAt(glm::vec3 idx, float tfExtinction) const {
    return p.extinction.valid() ? p.extinction.sample(idx) : tfExtinction;
  }

  // At surface-like samples (bias = the Blinn-Phong weight) T_L is looked up up to one light-grid
  // cell towards the light: like a shadow map's depth bias, this keeps an opaque surface from
  // shadowing itself through the grid's discretisation (moiré rings where the light grid's cells
  // cut the surface). Homogeneous media (bias 0) keep the exact lookup.
  VISOPT_HD float lightTransmittanceAt(glm::vec3 x, glm::vec3 toLight, float bias) const {
    if (!p.lightTransmittance.valid()) return 1.f;
    glm::vec3 y = p.light.toGrid(x + (bias * p.light.ds) * toLight);
    if (!p.lightTransmittance.inside(y)) return 1.f;
    return p.lightTransmittance.sample(y);
  }

  // Returns the number of volume samples taken for pixel `pixel`.
  VISOPT_HD int64_t operator()(int64_t pixel) const {
    const int w = p.camera.dims.x, h = p.camera.dims.y;
    const int px = int(pixel % w), row = int(pixel / w);
    const int py = h - 1 - row;
    const glm::vec3 dir = p.camera.rayDirection(float(px), float(py));
    const glm::vec3 o = p.volume.toIndex(p.camera.eye);
    const glm::vec3 d = p.volume.directionToIndex(dir);  // index units per world unit

    const RayInterval box = intersectBox(o, d, glm::vec3(p.volume.dims - 1));
    const float t0 = box.t0, t1 = box.t1;
    glm::vec3 radiance(0.f);
    float transmittance = 1.f;
    int64_t samples = 0;
    if (t1 > t0) {
      const int count = int(ceilf((t1 - t0) / p.step));
      const float seg = (t1 - t0) / float(count);
      const float offset = p.jitter ? hashToUnit(uint32_t(pixel) * 9781u + p.seed * 6271u) : 0.5f;
      const glm::vec3 toEye = -dir;
      for (int s = 0; s < count && transmittance > p.earlyStop; ++s) {
        const float t = t0 + (float(s) + offset) * seg;
        const glm::vec3 idx = o + t * d;
        ++samples;
        const float value = p.scalars.sample(idx);
        const glm::vec4 tf = p.transfer.at(value);
        const float mu = extinctionAt(idx, tf.w);
        const float opticalDepth = mu * seg;
        if (opticalDepth < 1e-7f) continue;
        const float alpha = 1.f - expf(-opticalDepth);
        const glm::vec3 albedo(tf.x, tf.y, tf.z);
        const glm::vec3 x = p.volume.toWorld(idx);

        // Phase function: HG blended with Blinn-Phong about the gradient.
        const glm::vec3 toLight = glm::normalize(p.lightPosition - x);
        float phase = henyeyGreenstein(glm::dot(toLight, dir), p.hg);
        float surfaceWeight = 0.f;
        // Gradient shading only where the sample can still be seen: below that its effect on
        // the pixel is under 1e-4 of the light's radiance.
        if ((p.kd > 0.f || p.ks > 0.f) && transmittance * alpha > 1e-4f) {
          glm::vec3 gi(p.scalars.sample(idx + glm::vec3(1, 0, 0)) - p.scalars.sample(idx - glm::vec3(1, 0, 0)),
                       p.scalars.sample(idx + glm::vec3(0, 1, 0)) - p.scalars.sample(idx - glm::vec3(0, 1, 0)),
                       p.scalars.sample(idx + glm::vec3(0, 0, 1)) - p.scalars.sample(idx - glm::vec3(0, 0, 1)));
          gi *= 0.5f;  // normalised value change per voxel along each index axis
          const float perVoxel = glm::length(gi);
          const float weight = fminf(perVoxel / p.surfaceGradient, 1.f);
          surfaceWeight = weight;
          if (weight > 0.f) {
            const glm::vec3 gw = p.volume.direction * (gi / p.volume.spacing);
            const glm::vec3 n = glm::normalize(gw);
            phase = (1.f - weight) * phase +
                    weight * blinnPhong(n, toLight, toEye, p.kd, p.ks, p.shininess);
          }
        }
        const float lightT = lightTransmittanceAt(x, toLight, surfaceWeight);
        radiance += transmittance * alpha * albedo *
                    (phase * lightT * p.lightRadiance + glm::vec3(p.ambient));
        transmittance *= 1.f - alpha;
      }
    }
    radiance += transmittance * p.background;
    p.pixels[pixel] = radiance;
    return samples;
  }
};

}  // namespace visopt
