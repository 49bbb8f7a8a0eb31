// Evaluation of the piecewise-linear transfer function: validation, lookups, the ParaView
// "scalar opacity unit distance" extinction (mu = -ln(1 - alpha) / unitDistance) and baking.
#include "visopt/transfer_function.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "visopt/error.h"

namespace visopt {

namespace {

constexpr float kMaxAlpha = 1.f - 1e-4f;

std::string formatNumber(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Index of the first point whose value is greater than `value` (points sorted by value).
template <class Points>
size_t upperIndex(const Points& points, double value) {
  auto it = std::upper_bound(points.begin(), points.end(), value,
                             [](double v, const auto& p) { return v < p.value; });
  return static_cast<size_t>(it - points.begin());
}

template <class Points>
double segmentFraction(const Points& points, size_t hi, double value) {
  const double v0 = points[hi - 1].value, v1 = points[hi].value;
  return (value - v0) / (v1 - v0);  // v1 > value >= v0, so v1 > v0
}

float checkedUnit(float unitDistance, float defaultUnitDistance) {
  const float unit = unitDistance > 0.f ? unitDistance : defaultUnitDistance;
  if (!(unit > 0.f) || !std::isfinite(unit))
    throw Error(ErrorKind::Usage,
                "transfer function: no unit distance (neither the function's nor a default > 0)");
  return unit;
}

}  // namespace

void TransferFunction::validate(const std::string& origin) {
  const std::string where = origin.empty() ? std::string("transfer function") : origin;
  if (opacity.empty()) throwBadInput(where, "no opacity points");
  if (color.empty()) throwBadInput(where, "no colour points");
  if (!std::isfinite(unitDistance) || unitDistance < 0.f)
    throwBadInput(where,
                  "unitDistance must be finite and >= 0 (got " + formatNumber(unitDistance) + ")");
  for (size_t i = 0; i < opacity.size(); ++i) {
    const auto& p = opacity[i];
    const std::string at = "opacity point " + std::to_string(i);
    if (!std::isfinite(p.value)) throwBadInput(where, at + ": value is not finite");
    if (!std::isfinite(p.opacity) || p.opacity < 0.f || p.opacity > 1.f)
      throwBadInput(where, at + ": opacity " + formatNumber(p.opacity) + " is outside [0, 1]");
  }
  for (size_t i = 0; i < color.size(); ++i) {
    const auto& p = color[i];
    const std::string at = "colour point " + std::to_string(i);
    if (!std::isfinite(p.value)) throwBadInput(where, at + ": value is not finite");
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(p.rgb[c]) || p.rgb[c] < 0.f || p.rgb[c] > 1.f)
        throwBadInput(where,
                      at + ": colour component " + formatNumber(p.rgb[c]) + " is outside [0, 1]");
  }
  std::stable_sort(opacity.begin(), opacity.end(),
                   [](const OpacityPoint& a, const OpacityPoint& b) { return a.value < b.value; });
  std::stable_sort(color.begin(), color.end(),
                   [](const ColorPoint& a, const ColorPoint& b) { return a.value < b.value; });
}

float TransferFunction::opacityAt(double value) const {
  if (opacity.empty()) return 0.f;
  const size_t hi = upperIndex(opacity, value);
  if (hi == 0) return opacity.front().opacity;
  if (hi == opacity.size()) return opacity.back().opacity;
  const double f = segmentFraction(opacity, hi, value);
  const double a0 = opacity[hi - 1].opacity, a1 = opacity[hi].opacity;
  return static_cast<float>(a0 + f * (a1 - a0));
}

glm::vec3 TransferFunction::colorAt(double value) const {
  if (color.empty()) return glm::vec3(1.f);
  const size_t hi = upperIndex(color, value);
  if (hi == 0) return color.front().rgb;
  if (hi == color.size()) return color.back().rgb;
  const float f = static_cast<float>(segmentFraction(color, hi, value));
  return color[hi - 1].rgb + f * (color[hi].rgb - color[hi - 1].rgb);
}

float TransferFunction::extinctionAt(double value, float defaultUnitDistance) const {
  const float unit = checkedUnit(unitDistance, defaultUnitDistance);
  const float alpha = std::clamp(opacityAt(value), 0.f, kMaxAlpha);
  return -std::log1p(-alpha) / unit;
}

TransferTable TransferFunction::bake(double valueMin, double valueMax, float defaultUnitDistance,
                                     int size) const {
  if (size < 2) throw Error(ErrorKind::Usage, "transfer function: bake needs at least 2 entries");
  if (!std::isfinite(valueMin) || !std::isfinite(valueMax) || valueMax < valueMin)
    throw Error(ErrorKind::Usage, "transfer function: bake needs a finite range with min <= max");
  checkedUnit(unitDistance, defaultUnitDistance);
  TransferTable table;
  table.albedoExtinction.resize(static_cast<size_t>(size));
  for (int i = 0; i < size; ++i) {
    const double t = double(i) / double(size - 1);
    const double value = valueMin + t * (valueMax - valueMin);
    const float mu = extinctionAt(value, defaultUnitDistance);
    table.albedoExtinction[static_cast<size_t>(i)] = glm::vec4(colorAt(value), mu);
    table.maxExtinction = std::max(table.maxExtinction, mu);
  }
  return table;
}

}  // namespace visopt
