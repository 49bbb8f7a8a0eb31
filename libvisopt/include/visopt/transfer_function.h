// Piecewise-linear transfer function over the data values (Himmler & Günther 2026, Eq. 3): it gives
// the scattering albedo a(x) (the colour) and the base extinction mu_bar(x).
//
// Opacity is specified the way ParaView does: an opacity alpha means "a slab of thickness
// `unitDistance` (world units) lets 1 - alpha of the light through", so the extinction is
// mu = -ln(1 - alpha) / unitDistance, independent of any sampling step. alpha is clamped to
// 1 - 1e-4 so an opacity of 1 gives a large but finite extinction.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace visopt {

struct OpacityPoint {
  double value = 0.0;
  float opacity = 0.f;  // [0, 1]
};

struct ColorPoint {
  double value = 0.0;
  glm::vec3 rgb{1.f};  // linear, [0, 1]
};

// A baked lookup table over normalised values t in [0, 1]: entry i is at t = i / (size - 1).
struct TransferTable {
  std::vector<glm::vec4> albedoExtinction;  // rgb albedo, extinction (1 / world unit)
  float maxExtinction = 0.f;
};

class TransferFunction {
 public:
  std::string name;
  std::vector<OpacityPoint> opacity;  // sorted by value (normalize() sorts)
  std::vector<ColorPoint> color;      // sorted by value
  float unitDistance = 0.f;           // world units; 0 means "the volume's smallest spacing"
  // Refuses (Error BadInput, naming `origin`) NaN, opacity outside [0, 1], colours outside
  // [0, 1], empty point lists, unitDistance < 0; sorts points by value.
  void validate(const std::string& origin = "transfer function");

  float opacityAt(double value) const;
  glm::vec3 colorAt(double value) const;
  // Base extinction mu_bar at a data value, given the unit distance to use when unitDistance==0.
  float extinctionAt(double value, float defaultUnitDistance) const;
  // Bakes over [valueMin, valueMax] (the volume's range) into `size` entries.
  TransferTable bake(double valueMin, double valueMax, float defaultUnitDistance,
                     int size = 1024) const;

  // JSON: {"format":"visopt-transfer-function","version":1,"name":..,"unitDistance":..,
  //        "opacity":[[value,alpha],...],"color":[[value,r,g,b],...]}
  std::string toJson() const;
  // Accepts the visopt format and ParaView's exported colour-map JSON (a list of objects with
  // "RGBPoints" [v,r,g,b,...] and optionally "Points" [v,alpha,mid,sharp,...]); `origin` names
  // the source in error messages.
  static TransferFunction fromJson(const std::string& json, const std::string& origin);
  static TransferFunction load(const std::string& path);
  void save(const std::string& path) const;  // atomic

  // Built-in presets, in data units: "ct-skin-bone", "ct-bone", "mri", "generic".
  // "generic" spans [valueMin, valueMax] of the data and must be given that range.
  static std::vector<std::string> presetNames();
  // The importance a preset is made to be used with, as a curve of (value, g) in data units:
  // bone (g rising from 0 at 200 HU to 1 at 300 HU, where ct-skin-bone and ct-bone turn bone
  // opaque) for the CT presets; empty for the others.
  static std::vector<glm::dvec2> presetImportance(const std::string& name);
  // The isovalue of the surface a preset shows as context, in data units: the skin at -400 HU
  // (inside ct-skin-bone's -500..-150 HU skin layer) for ct-skin-bone; none for the others.
  // With presetImportance it makes "skin as context, bone as importance" one step.
  static std::optional<double> presetContextIsovalue(const std::string& name);
  static TransferFunction preset(const std::string& name, double valueMin = 0.0,
                                 double valueMax = 1.0);
};

}  // namespace visopt
