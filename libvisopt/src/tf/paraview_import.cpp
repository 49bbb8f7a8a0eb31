// Import of ParaView's exported colour maps ("Export color map" / presets JSON). ParaView writes
// a JSON array of objects such as
//   {"ColorSpace": "Diverging", "Name": "Preset", "RGBPoints": [v, r, g, b, ...],
//    "Points": [v, alpha, midpoint, sharpness, ...]}
// Colours are interpolated linearly in RGB whatever "ColorSpace" says; opacity midpoint and
// sharpness are ignored (they are 0.5 / 0 for ParaView's piecewise-linear default). Without
// "Points" the opacity is a linear ramp 0 -> 1 over the RGBPoints range.
#include <algorithm>

#include <nlohmann/json.hpp>

#include "tf/json_read.h"
#include "visopt/error.h"

namespace visopt::tfjson {

namespace {

const nlohmann::json& pickPreset(const nlohmann::json& doc, const std::string& origin) {
  if (doc.is_object()) return doc;
  if (!doc.is_array() || doc.empty())
    throwBadInput(origin, "expected a ParaView colour map (a non-empty list of objects)");
  for (const auto& entry : doc)
    if (entry.is_object() && entry.contains("RGBPoints")) return entry;
  throwBadInput(origin,
                "no entry with \"RGBPoints\" (indexed/categorical colour maps are not supported)");
}

std::vector<double> readFlatList(const nlohmann::json& obj, const char* key, size_t stride,
                                 const std::string& origin) {
  const auto& list = obj.at(key);
  const std::string what = std::string("\"") + key + "\"";
  if (!list.is_array()) throwBadInput(origin, what + " is not a list");
  if (list.empty()) throwBadInput(origin, what + " is empty");
  if (list.size() % stride != 0)
    throwBadInput(origin, what + " has " + std::to_string(list.size()) +
                              " numbers, not a multiple of " + std::to_string(stride));
  std::vector<double> out;
  out.reserve(list.size());
  for (size_t i = 0; i < list.size(); ++i)
    out.push_back(readNumber(list[i], origin, what + "[" + std::to_string(i) + "]"));
  return out;
}

}  // namespace

TransferFunction fromParaView(const nlohmann::json& doc, const std::string& origin) {
  const nlohmann::json& preset = pickPreset(doc, origin);
  if (!preset.contains("RGBPoints"))
    throwBadInput(origin, "no \"RGBPoints\" in the ParaView colour map");

  TransferFunction tf;
  if (preset.contains("Name")) {
    if (!preset["Name"].is_string()) throwBadInput(origin, "\"Name\" is not a string");
    tf.name = preset["Name"].get<std::string>();
  }
  const std::vector<double> rgb = readFlatList(preset, "RGBPoints", 4, origin);
  for (size_t i = 0; i < rgb.size(); i += 4)
    tf.color.push_back(
        ColorPoint{rgb[i], glm::vec3(static_cast<float>(rgb[i + 1]), static_cast<float>(rgb[i + 2]),
                                     static_cast<float>(rgb[i + 3]))});
  if (preset.contains("Points")) {
    const std::vector<double> pts = readFlatList(preset, "Points", 4, origin);
    for (size_t i = 0; i < pts.size(); i += 4)
      tf.opacity.push_back(OpacityPoint{pts[i], static_cast<float>(pts[i + 1])});
  } else {
    double lo = rgb[0], hi = rgb[0];
    for (size_t i = 0; i < rgb.size(); i += 4) {
      lo = std::min(lo, rgb[i]);
      hi = std::max(hi, rgb[i]);
    }
    tf.opacity.push_back(OpacityPoint{lo, 0.f});
    if (hi > lo) tf.opacity.push_back(OpacityPoint{hi, 1.f});
  }
  if (preset.contains("ScalarOpacityUnitDistance")) {
    const double unit =
        readNumber(preset["ScalarOpacityUnitDistance"], origin, "\"ScalarOpacityUnitDistance\"");
    tf.unitDistance = static_cast<float>(unit);
  }
  tf.validate(origin);
  return tf;
}

}  // namespace visopt::tfjson
