// ClearView (Krüger, Schneider, Westermann 2006): a context-preserving hotspot. Surface layers
// (the first hit of each view ray with a context and a focus surface: position, normal, depth)
// and an optional volume layer (the matter in front of them) are extracted once per view; the
// compositing then makes the context transparent around a focus point where it is flat and
// keeps it where it curves or bends away at silhouettes (§3.2), in milliseconds. Moving the
// hotspot, its size, the measure, the shaders or the light re-runs the compositing only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace visopt {

// Where a surface layer comes from.
enum class ClearViewLayerKind {
  Isosurface,      // the volume's isosurface at `isovalue` (data units), inside where higher
  ContextSurface,  // the zero set of the Engine's context surface `surface` (paper 000's phi)
  Importance,      // the isosurface of the importance g at `isovalue` (in (0, 1]), inside higher
};
const char* toString(ClearViewLayerKind kind);

struct ClearViewLayer {
  ClearViewLayerKind kind = ClearViewLayerKind::Isosurface;
  double isovalue = 0.0;
  int surface = 0;
  bool operator==(const ClearViewLayer&) const = default;
};

// The importance measures of §3.2.1-3.2.3: what keeps the context opaque besides the distance
// |C - P| / s from the focus point.
enum class ClearViewMeasure {
  Curvature,     // the image-space curvature of the context layer (the default)
  Distance,      // the distance from the context to the focus surface along the context normal
  ViewDistance,  // the same distance along the view ray
};
const char* toString(ClearViewMeasure measure);

// The deferred shaders of §3.2.5-3.2.7.
enum class ClearViewShader { Diffuse, CoolWarm, Skin, Bone };
const char* toString(ClearViewShader shader);

// At most this many context and this many focus surface layers.
inline constexpr int kClearViewMaxLayers = 4;

struct ClearViewSettings {
  int width = 512, height = 512;
  ClearViewLayer context;  // the nearest semi-transparent context surface
  // Further context surfaces behind it, front to back (§3.1: "one or more context layers"). Each
  // is found along the ray from where the one before it was hit (from where the ray enters the
  // volume where that one has no hit), so the user orders them front to back, as the paper asks;
  // each is made transparent about the focus point by its own measure, and they are blended
  // back to front. At most kClearViewMaxLayers - 1.
  std::vector<ClearViewLayer> deeperContexts;
  ClearViewLayer focus{ClearViewLayerKind::Importance, 0.5, 0};  // an opaque focus surface
  // Further opaque focus surfaces ("one or more focus layers"): each pixel shows the nearest hit
  // of all focus surfaces, and the focus point C is the cursor's pixel on that nearest one. At
  // most kClearViewMaxLayers - 1.
  std::vector<ClearViewLayer> moreFoci;
  // Also a volume context layer: all matter in front of the first context or focus surface,
  // composited front to back with the transfer function (emission-absorption: the albedo as
  // emitted colour, no shading), made transparent around the focus point like the surface but
  // kept where its colour changes from pixel to pixel (the paper's high-pass filter).
  bool volumeLayer = false;

  ClearViewMeasure measure = ClearViewMeasure::Curvature;
  ClearViewShader contextShader = ClearViewShader::Skin;
  ClearViewShader focusShader = ClearViewShader::Bone;
  // The hotspot: the pixel the user points at (x right, y down from the top-left corner; a
  // negative coordinate means the image centre) and the radius s of the focus region in world
  // units (0: automatic, twice the depth of the focus point below the context along the focus
  // pixel's ray, so that the context there is half opaque; half the volume's bounding
  // radius where that pixel does not see the context in front of the focus).
  glm::vec2 focusPixel{-1.f, -1.f};
  float size = 0.f;
  // The weight of the measure against the distance term (Tuvok's "context scale"): the curvature
  // (summed normal differences, 0..8) or the distance measures (distance / distanceScale).
  float weight = 1.f;
  // World units at which the distance measures reach 1 (0: the hotspot's size s).
  float distanceScale = 0.f;
  // §3.2.4: darken the context where its distance to the focus point lies in [0.95 s, s].
  bool border = true;
  float ambient = 0.15f;  // the diffuse and cool-to-warm shaders' ambient term, 0..1
  // The light at the camera (the paper's default: best contrast, silhouettes for free), else
  // the scene's point light.
  bool headlight = true;
  // Diffuse and cool-to-warm base colours (linear RGB) of the context and focus layers.
  glm::vec3 contextColor{0.93f, 0.75f, 0.64f};
  glm::vec3 focusColor{0.92f, 0.89f, 0.80f};
  glm::vec3 background{0.06f, 0.065f, 0.075f};
};

struct ClearViewStats {
  bool extracted = false;    // this call extracted the layers (else it reused them)
  int64_t extractions = 0;   // layer extractions since the Engine was made
  double extractMs = 0.0;    // this call's extraction (0 when reused)
  double compositeMs = 0.0;  // this call's compositing
  bool hasFocusPoint = false;
  glm::vec3 focusPoint{0.f};  // C in world units, when the focus pixel sees the focus layer
  // Pixels where the first context surface and where any focus surface was hit.
  int64_t contextPixels = 0, focusPixels = 0;
  std::vector<int64_t> deeperContextPixels;  // the same per deeper context surface
  float size = 0.f;  // the hotspot radius s used, world units (the automatic one when size was 0)
};

// Throws Error(Usage) naming what is wrong (image size, size, weights, colours, the layers'
// values); the Engine also checks the layers against its scene.
void checkClearViewSettings(const ClearViewSettings& settings);

}  // namespace visopt
