// ClearView's deferred shaders (Krüger, Schneider, Westermann 2006, §3.2.5-3.2.7). N is the
// surface's outward unit normal, L the unit direction to the light, V the unit direction to the
// eye; colours are display (sRGB-encoded) values, as the paper's shaders wrote them to the
// framebuffer; the compositor blends in that space and decodes the result to linear light.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/hd.h"
#include "core/min_max.h"

namespace visopt {

enum class ClearViewShaderKind : int { Diffuse = 0, CoolWarm = 1, Skin = 2, Bone = 3 };

VISOPT_HD inline float cvSaturate(float x) {
  return minOf(maxOf(x, 0.f), 1.f);
}

// A 1D table of four evenly spaced entries, linearly interpolated at t in [0, 1].
struct ClearViewLut {
  glm::vec3 c[4];
  VISOPT_HD glm::vec3 at(float t) const {
    const float x = cvSaturate(t) * 3.f;
    const int i = x >= 3.f ? 2 : int(x);
    const float f = x - float(i);
    return c[i] + f * (c[i + 1] - c[i]);
  }
};

// The paper's tables are shown only as a figure (Fig. 12): these are our own, from shadow to
// highlight. Skin: dark red-brown, flesh, light peach, near white; bone: grey-brown to ivory.
VISOPT_HD inline ClearViewLut clearViewSkinLut() {
  return ClearViewLut{{glm::vec3(0.30f, 0.12f, 0.08f), glm::vec3(0.72f, 0.45f, 0.36f),
                       glm::vec3(0.93f, 0.74f, 0.63f), glm::vec3(1.00f, 0.95f, 0.90f)}};
}
VISOPT_HD inline ClearViewLut clearViewBoneLut() {
  return ClearViewLut{{glm::vec3(0.22f, 0.19f, 0.16f), glm::vec3(0.56f, 0.51f, 0.44f),
                       glm::vec3(0.86f, 0.82f, 0.72f), glm::vec3(0.99f, 0.97f, 0.90f)}};
}

// §3.2.5: diffuse with an ambient term.
VISOPT_HD inline glm::vec3 clearViewDiffuse(glm::vec3 N, glm::vec3 L, glm::vec3 albedo,
                                            float ambient) {
  return albedo * (ambient + (1.f - ambient) * maxOf(glm::dot(N, L), 0.f));
}

// §3.2.6: cool to warm (Gooch et al. 1998) through a 1D table indexed by the diffuse term
// (1 + N.L) / 2; the table runs from k_cool = (0, 0, 0.55) + 0.25 kd to k_warm = (0.3, 0.3, 0)
// + 0.5 kd (Gooch's constants), so it is linear and evaluated directly.
VISOPT_HD inline glm::vec3 clearViewCoolWarm(glm::vec3 N, glm::vec3 L, glm::vec3 albedo) {
  const glm::vec3 cool = glm::vec3(0.f, 0.f, 0.55f) + 0.25f * albedo;
  const glm::vec3 warm = glm::vec3(0.3f, 0.3f, 0.f) + 0.5f * albedo;
  const float t = 0.5f + 0.5f * glm::dot(N, L);
  return cool + t * (warm - cool);
}

// §3.2.7, bone: A = 0.5 L.N + 0.5, B = 0.7 - 0.3 L.V, C = B (0.5 - 0.5 V.N), one lookup at
// saturate(0.6 A + 0.5 C).
VISOPT_HD inline glm::vec3 clearViewBone(glm::vec3 N, glm::vec3 L, glm::vec3 V) {
  const float A = 0.5f * glm::dot(L, N) + 0.5f;
  const float B = 0.7f - 0.3f * glm::dot(L, V);
  const float C = B * (0.5f - 0.5f * glm::dot(V, N));
  return clearViewBoneLut().at(cvSaturate(0.6f * A + 0.5f * C));
}

// The parts of the skin shader, for tests.
struct ClearViewSkinTerms {
  float A, B, Bprime, C, D;
  float redShift;  // 0 for A > 0.5, rising to 1 at A = 0
};

// §3.2.7, skin: A = 0.5 L.N + 0.45, B = 0.6 - 0.4 L.V, B' = saturate(R.L)^4, C = 0.5 B B' + 0.5,
// D = 0.9 saturate(1 - N.V)^3.
// Reconstructed: the text has B' = saturate(reflect(V, N).L)^4. With V pointing to the eye (as
// the other terms need: 1 - N.V is 0 facing the viewer and 1 at silhouettes), GLSL's
// reflect(V, N) = V - 2 (N.V) N is the mirror direction negated, so the term would vanish where
// a headlight's highlight belongs and peak at silhouettes; we use the mirror direction
// R = reflect(-V, N) = 2 (N.V) N - V, which gives the specular highlight of Fig. 12.
VISOPT_HD inline ClearViewSkinTerms clearViewSkinTerms(glm::vec3 N, glm::vec3 L, glm::vec3 V) {
  ClearViewSkinTerms t;
  const float nv = glm::dot(N, V);
  const glm::vec3 R = 2.f * nv * N - V;
  t.A = 0.5f * glm::dot(L, N) + 0.45f;
  t.B = 0.6f - 0.4f * glm::dot(L, V);
  const float rl = cvSaturate(glm::dot(R, L));
  t.Bprime = (rl * rl) * (rl * rl);
  t.C = 0.5f * t.B * t.Bprime + 0.5f;
  const float s = cvSaturate(1.f - nv);
  t.D = 0.9f * s * s * s;
  // The red shift of shadowed skin (blood under the skin): reconstructed as a blend towards a
  // redder tint that starts at A = 0.5 and is complete at A = 0, since the paper gives only its
  // condition (A <= 0.5), not its amount.
  t.redShift = t.A <= 0.5f ? cvSaturate((0.5f - t.A) * 2.f) : 0.f;
  return t;
}

VISOPT_HD inline glm::vec3 clearViewSkin(glm::vec3 N, glm::vec3 L, glm::vec3 V) {
  const ClearViewSkinTerms t = clearViewSkinTerms(N, L, V);
  const ClearViewLut lut = clearViewSkinLut();
  glm::vec3 diff = lut.at(t.A);
  const glm::vec3 reddened = diff * glm::vec3(1.f, 0.55f, 0.5f);
  diff = diff + t.redShift * (reddened - diff);
  const glm::vec3 side = (1.f - glm::dot(N, V)) * lut.at(t.C);
  const glm::vec3 hi = lut.at(t.D);
  // Color_final = 0.8 C_diff + 0.25 C_side + 0.15 C_hi + 0.1 B' (B' expanded to rgb).
  return 0.8f * diff + 0.25f * side + 0.15f * hi + glm::vec3(0.1f * t.Bprime);
}

VISOPT_HD inline glm::vec3 clearViewShade(ClearViewShaderKind kind, glm::vec3 N, glm::vec3 L,
                                          glm::vec3 V, glm::vec3 albedo, float ambient) {
  switch (kind) {
    case ClearViewShaderKind::CoolWarm:
      return clearViewCoolWarm(N, L, albedo);
    case ClearViewShaderKind::Skin:
      return clearViewSkin(N, L, V);
    case ClearViewShaderKind::Bone:
      return clearViewBone(N, L, V);
    default:
      return clearViewDiffuse(N, L, albedo, ambient);
  }
}

}  // namespace visopt
