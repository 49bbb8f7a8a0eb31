#include <cmath>
#include <string>

#include "visopt/clearview.h"
#include "visopt/error.h"

namespace visopt {

const char* toString(ClearViewLayerKind kind) {
  switch (kind) {
    case ClearViewLayerKind::Isosurface:
      return "iso";
    case ClearViewLayerKind::ContextSurface:
      return "surface";
    case ClearViewLayerKind::Importance:
      return "importance";
  }
  return "unknown";
}

const char* toString(ClearViewMeasure measure) {
  switch (measure) {
    case ClearViewMeasure::Curvature:
      return "curvature";
    case ClearViewMeasure::Distance:
      return "distance";
    case ClearViewMeasure::ViewDistance:
      return "view-distance";
  }
  return "unknown";
}

const char* toString(ClearViewShader shader) {
  switch (shader) {
    case ClearViewShader::Diffuse:
      return "diffuse";
    case ClearViewShader::CoolWarm:
      return "cool-warm";
    case ClearViewShader::Skin:
      return "skin";
    case ClearViewShader::Bone:
      return "bone";
  }
  return "unknown";
}

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw Error(ErrorKind::Usage, "ClearView: " + what);
}

bool colour(glm::vec3 c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) && c.r >= 0.f &&
         c.g >= 0.f && c.b >= 0.f;
}

void checkLayer(const ClearViewLayer& layer, const std::string& r) {
  require(std::isfinite(layer.isovalue), "the " + r + " layer's isovalue must be finite");
  if (layer.kind == ClearViewLayerKind::Importance)
    require(layer.isovalue > 0.0 && layer.isovalue <= 1.0,
            "the " + r + " layer's importance level must lie in (0, 1]");
  if (layer.kind == ClearViewLayerKind::ContextSurface)
    require(layer.surface >= 0, "the " + r + " layer's context surface index must be >= 0");
}

}  // namespace

void checkClearViewSettings(const ClearViewSettings& s) {
  require(s.width >= 1 && s.height >= 1 && s.width <= 16384 && s.height <= 16384,
          "the image size must be 1..16384 pixels per side");
  checkLayer(s.context, "context");
  checkLayer(s.focus, "focus");
  require(s.deeperContexts.size() < size_t(kClearViewMaxLayers) &&
              s.moreFoci.size() < size_t(kClearViewMaxLayers),
          "at most " + std::to_string(kClearViewMaxLayers) + " context and " +
              std::to_string(kClearViewMaxLayers) + " focus layers");
  for (size_t i = 0; i < s.deeperContexts.size(); ++i)
    checkLayer(s.deeperContexts[i], "context " + std::to_string(i + 2));
  for (size_t i = 0; i < s.moreFoci.size(); ++i)
    checkLayer(s.moreFoci[i], "focus " + std::to_string(i + 2));
  require(std::isfinite(s.focusPixel.x) && std::isfinite(s.focusPixel.y),
          "the focus pixel must be finite");
  require(std::isfinite(s.size) && s.size >= 0.f, "the hotspot size must be finite, >= 0");
  require(std::isfinite(s.weight) && s.weight >= 0.f, "the weight must be finite, >= 0");
  require(std::isfinite(s.distanceScale) && s.distanceScale >= 0.f,
          "the distance scale must be finite, >= 0");
  require(std::isfinite(s.ambient) && s.ambient >= 0.f && s.ambient <= 1.f,
          "the ambient term must lie in [0, 1]");
  require(colour(s.contextColor) && colour(s.focusColor) && colour(s.background),
          "colours must be finite and >= 0");
}

}  // namespace visopt
