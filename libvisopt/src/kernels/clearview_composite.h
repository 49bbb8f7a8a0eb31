// ClearView's compositing (Krüger, Schneider, Westermann 2006, §3.2): per pixel, the context's
// opacity from the focus point and the importance measure, the shaders, the focus border, and
// the blend of the volume layer, the context surfaces (back to front, each by its own opacity),
// the nearest focus surface and the background.
//   curvature (§3.2.1): sum over the 4 neighbours of |N(p) - N(q)| (the umbrella operator in
//     image space); a neighbour without a hit counts as the largest difference of two unit
//     normals, 2, so silhouettes stay opaque;
//   opacity = saturate(max(|C - P| / s, weight * measure(P)))   (trans = 1 - opacity);
//   measure: curvature, normalDistance / D (§3.2.2) or |surfF - surfC| / D (§3.2.3).
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/hd.h"
#include "core/min_max.h"
#include "kernels/clearview_extract.h"
#include "kernels/clearview_shading.h"

namespace visopt {

inline constexpr int kClearViewDecodeEntries = 4096;

enum class ClearViewMeasureKind : int { Curvature = 0, Distance = 1, ViewDistance = 2 };

struct ClearViewContextView {
  const glm::vec3 *position = nullptr, *normal = nullptr;
  const float* depth = nullptr;
  const float* normalDistance = nullptr;
};

struct ClearViewLayersView {
  ClearViewContextView contexts[kClearViewMaxLayers];  // nearest first
  int contextCount = 1;
  const glm::vec3 *focusPosition = nullptr, *focusNormal = nullptr;
  const float* focusDepth = nullptr;
  const glm::vec4* volume = nullptr;  // null without a volume layer
};

struct ClearViewCompositeParams {
  int width = 0, height = 0;
  ClearViewLayersView layers;
  glm::vec3 eye{0.f};
  bool headlight = true;
  glm::vec3 lightPosition{0.f};
  bool hasFocusPoint = false;
  glm::vec3 focusPoint{0.f};
  float invSize = 1.f;      // 1 / s
  float invDistance = 1.f;  // 1 / D
  float weight = 1.f;
  ClearViewMeasureKind measure = ClearViewMeasureKind::Curvature;
  ClearViewShaderKind contextShader = ClearViewShaderKind::Skin;
  ClearViewShaderKind focusShader = ClearViewShaderKind::Bone;
  glm::vec3 contextColor{0.8f}, focusColor{0.8f};  // display values
  glm::vec3 background{0.f};                       // display value
  float ambient = 0.15f;
  bool border = true;
  const float* decode = nullptr;  // kClearViewDecodeEntries display -> linear values
  glm::vec3* out = nullptr;       // linear light
};

// The image-space curvature of a surface layer at pixel (x, y) (§3.1, Fig. 5).
VISOPT_HD inline float clearViewCurvature(const glm::vec3* normal, const float* depth, int w, int h,
                                          int x, int y) {
  const int64_t i = int64_t(y) * w + x;
  const glm::vec3 n = normal[i];
  float sum = 0.f;
  const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  for (int k = 0; k < 4; ++k) {
    const int qx = x + dx[k], qy = y + dy[k];
    if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;  // the image's edge is no silhouette
    const int64_t q = int64_t(qy) * w + qx;
    sum += depth[q] >= kClearViewNoHit ? 2.f : glm::length(n - normal[q]);
  }
  return sum;
}

// The volume layer's high-pass (§3.1: "an image-based high-pass filter to enhance regions
// exhibiting high color gradients"): the summed distances of the pixel's premultiplied colour to
// its 4 neighbours', the volume layer's counterpart of the surface curvature (the paper names
// the filter, not its kernel; this is the same umbrella form).
VISOPT_HD inline float clearViewColorEdges(const glm::vec4* volume, int w, int h, int x, int y) {
  const glm::vec3 c = glm::vec3(volume[int64_t(y) * w + x]);
  float sum = 0.f;
  const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  for (int k = 0; k < 4; ++k) {
    const int qx = x + dx[k], qy = y + dy[k];
    if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
    sum += glm::length(c - glm::vec3(volume[int64_t(qy) * w + qx]));
  }
  return sum;
}

// The opacity of context layer `layer` at a pixel where it has a hit (the measure's term and the
// distance term), before the border.
VISOPT_HD inline float clearViewContextOpacity(const ClearViewCompositeParams& p, int layer, int x,
                                               int y) {
  const int64_t i = int64_t(y) * p.width + x;
  const ClearViewContextView& C = p.layers.contexts[layer];
  const float* focusDepth = p.layers.focusDepth;
  if (!p.hasFocusPoint) return 1.f;
  const float near = glm::length(p.focusPoint - C.position[i]) * p.invSize;
  float m = 0.f;
  switch (p.measure) {
    case ClearViewMeasureKind::Distance:
      m = C.normalDistance[i] >= kClearViewNoHit ? 1.f : C.normalDistance[i] * p.invDistance;
      break;
    case ClearViewMeasureKind::ViewDistance:
      m = focusDepth[i] >= kClearViewNoHit ? 1.f
                                           : fabsf(focusDepth[i] - C.depth[i]) * p.invDistance;
      break;
    default:
      m = clearViewCurvature(C.normal, C.depth, p.width, p.height, x, y);
  }
  return cvSaturate(maxOf(near, p.weight * m));
}

struct ClearViewCompositeKernel {
  ClearViewCompositeParams p;

  VISOPT_HD void operator()(int64_t pixel) const {
    const int x = int(pixel % p.width), y = int(pixel / p.width);
    const ClearViewLayersView& L = p.layers;
    const float tf = L.focusDepth[pixel];
    glm::vec3 color = p.background;
    float near = 1.f;  // the distance term of the front-most layer drawn, for the volume layer
    if (tf < kClearViewNoHit) {
      const glm::vec3 P = L.focusPosition[pixel];
      color = clearViewShade(p.focusShader, L.focusNormal[pixel], lightAt(P), eyeAt(P),
                             p.focusColor, p.ambient);
      if (p.hasFocusPoint) near = cvSaturate(glm::length(p.focusPoint - P) * p.invSize);
    }
    // The context surfaces, back to front, each over what lies behind it unless the focus is in
    // front of it.
    for (int k = L.contextCount - 1; k >= 0; --k) {
      const ClearViewContextView& C = L.contexts[k];
      const float tc = C.depth[pixel];
      if (!(tc < kClearViewNoHit) || tf < tc) continue;
      const glm::vec3 P = C.position[pixel];
      glm::vec3 c = clearViewShade(p.contextShader, C.normal[pixel], lightAt(P), eyeAt(P),
                                   p.contextColor, p.ambient);
      const float alpha = clearViewContextOpacity(p, k, x, y);
      if (p.hasFocusPoint) {
        const float d = glm::length(p.focusPoint - P) * p.invSize;
        near = cvSaturate(d);
        // §3.2.4: the border where the sphere about C meets the surface, darkened.
        if (p.border && d >= 0.95f && d <= 1.f) c *= 0.3f;
      }
      color = alpha * c + (1.f - alpha) * color;
    }
    if (L.volume) {  // premultiplied, made transparent about the focus point like the surface
      const glm::vec4 v = L.volume[pixel];
      const float keep =
          p.hasFocusPoint ? cvSaturate(maxOf(near, p.weight * clearViewColorEdges(L.volume, p.width,
                                                                                  p.height, x, y)))
                          : 1.f;
      color = keep * glm::vec3(v) + (1.f - keep * v.w) * color;
    }
    p.out[pixel] = glm::vec3(toLinear(color.r), toLinear(color.g), toLinear(color.b));
  }

  VISOPT_HD float toLinear(float v) const {
    return p.decode[int(cvSaturate(v) * float(kClearViewDecodeEntries - 1) + 0.5f)];
  }

  VISOPT_HD glm::vec3 eyeAt(glm::vec3 P) const {
    const glm::vec3 v = p.eye - P;
    const float len = glm::length(v);
    return len > 0.f ? v / len : glm::vec3(0.f, 0.f, 1.f);
  }
  VISOPT_HD glm::vec3 lightAt(glm::vec3 P) const {
    if (p.headlight) return eyeAt(P);
    const glm::vec3 v = p.lightPosition - P;
    const float len = glm::length(v);
    return len > 0.f ? v / len : eyeAt(P);
  }
};

}  // namespace visopt
