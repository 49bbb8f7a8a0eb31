#include "clearview_spec.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <vector>

#include "visopt/error.h"

namespace visopt::cli {

namespace {

constexpr const char* kKeys =
    "context, focus, volume, measure, shader, focus-shader, at, size, weight, distance-scale, "
    "border, ambient, light";

// "--clearview: 'ELEMENT': PROBLEM" — every message names the option and the element.
[[noreturn]] void fail(std::string_view element, const std::string& problem) {
  throw Error(ErrorKind::Usage, "--clearview: '" + std::string(element) + "': " + problem);
}

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

// A finite decimal number, the whole of `text` (a leading '+' allowed; no "nan", "inf", hex).
std::optional<double> toNumber(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty() || text.front() == '+') return std::nullopt;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

double number(std::string_view element, std::string_view text, const char* what) {
  const auto v = toNumber(text);
  if (!v) fail(element, "'" + std::string(text) + "' is not a finite number (" + what + ")");
  return *v;
}

float floatNumber(std::string_view element, std::string_view text, const char* what) {
  const double v = number(element, text, what);
  if (std::abs(v) > double(std::numeric_limits<float>::max()))
    fail(element, "'" + std::string(text) + "' is too large (" + what + ")");
  return static_cast<float>(v);
}

bool flag(std::string_view element, std::string_view text) {
  if (text == "1") return true;
  if (text == "0") return false;
  fail(element, "expected 0 or 1");
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string surfaceRange(size_t count) {
  if (count == 0) return "this scene has no context surface";
  if (count == 1) return "this scene has 1 context surface (surface:0)";
  return "this scene has " + std::to_string(count) + " context surfaces (surface:0.." +
         std::to_string(count - 1) + ")";
}

// context= / focus=: iso:V, surface:N, importance:G (focus also a bare `importance`).
ClearViewLayer parseLayer(const Engine& engine, std::string_view element, std::string_view key,
                          std::string_view value) {
  const bool isFocus = key == "focus";
  const std::string forms = isFocus ? "iso:VALUE, surface:N, importance:G or importance"
                                    : "iso:VALUE, surface:N or importance:G";
  ClearViewLayer layer;
  if (isFocus && value == "importance") value = "importance:0.5";
  const size_t colon = value.find(':');
  if (colon == std::string_view::npos) fail(element, "expected " + forms);
  const std::string_view kind = value.substr(0, colon), arg = value.substr(colon + 1);
  if (kind == "iso") {
    layer.kind = ClearViewLayerKind::Isosurface;
    layer.isovalue = number(element, arg, "an isovalue in data units");
  } else if (kind == "surface") {
    layer.kind = ClearViewLayerKind::ContextSurface;
    // A plain non-negative integer: no sign, no fraction, no exponent.
    int n = 0;
    const auto [end, ec] = std::from_chars(arg.data(), arg.data() + arg.size(), n);
    if (arg.empty() || arg.front() == '-' || ec != std::errc() || end != arg.data() + arg.size())
      fail(element, "'" + std::string(arg) + "' is not a context-surface index (0, 1, ...)");
    const size_t count = engine.contextSurfaces().size();
    if (size_t(n) >= count) fail(element, surfaceRange(count));
    layer.surface = n;
  } else if (kind == "importance") {
    layer.kind = ClearViewLayerKind::Importance;
    layer.isovalue = number(element, arg, "an importance in (0, 1]");
    if (!(layer.isovalue > 0.0 && layer.isovalue <= 1.0))
      fail(element, "the importance isovalue must lie in (0, 1]");
    if (!engine.hasImportance())
      fail(element, "this scene has no importance (give " + std::string(key) + "=iso:VALUE)");
  } else {
    fail(element, "expected " + forms);
  }
  return layer;
}

ClearViewMeasure parseMeasure(std::string_view element, std::string_view value) {
  if (value == "curvature") return ClearViewMeasure::Curvature;
  if (value == "distance") return ClearViewMeasure::Distance;
  if (value == "view-distance") return ClearViewMeasure::ViewDistance;
  fail(element, "expected curvature, distance or view-distance");
}

ClearViewShader parseShader(std::string_view element, std::string_view value) {
  if (value == "diffuse") return ClearViewShader::Diffuse;
  if (value == "cool-warm") return ClearViewShader::CoolWarm;
  if (value == "skin") return ClearViewShader::Skin;
  if (value == "bone") return ClearViewShader::Bone;
  fail(element, "expected diffuse, cool-warm, skin or bone");
}

}  // namespace

Error asClearViewOptionError(const Error& error) {
  std::string message = error.what();
  const std::string prefix = "ClearView: ";  // the library's own prefix
  if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
  return Error(error.kind(), "--clearview: " + message);
}

std::string describeClearViewLayer(const ClearViewLayer& layer) {
  switch (layer.kind) {
    case ClearViewLayerKind::Isosurface:
      return "iso:" + fmt(layer.isovalue);
    case ClearViewLayerKind::ContextSurface:
      return "surface:" + std::to_string(layer.surface);
    case ClearViewLayerKind::Importance:
      return "importance:" + fmt(layer.isovalue);
  }
  return "?";
}

ClearViewSettings parseClearViewSpec(const Engine& engine, const std::string& spec,
                                     glm::ivec2 imageSize, const ClearViewSettings* base) {
  ClearViewSettings s = base ? *base : ClearViewSettings{};
  s.width = imageSize.x;
  s.height = imageSize.y;
  std::set<std::string, std::less<>> seen;

  // An empty SPEC keeps every default; otherwise every element is a key=value.
  std::vector<std::string_view> elements;
  if (!trim(spec).empty()) {
    std::string_view rest = spec;
    while (true) {
      const size_t comma = rest.find(',');
      elements.push_back(rest.substr(0, comma));
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  for (size_t i = 0; i < elements.size(); ++i) {
    const std::string_view element = trim(elements[i]);
    if (element.empty())
      throw Error(ErrorKind::Usage, "--clearview: empty element " + std::to_string(i + 1) +
                                        " in '" + spec + "' (expected key=value,key=value,...)");
    const size_t eq = element.find('=');
    if (eq == std::string_view::npos) fail(element, "expected key=value");
    const std::string_view key = trim(element.substr(0, eq));
    const std::string_view value = trim(element.substr(eq + 1));
    if (key.empty()) fail(element, "no key before '='");
    if (value.empty()) fail(element, "no value after '='");
    const bool layerKey = key == "context" || key == "focus";
    const bool first = seen.insert(std::string(key)).second;
    if (!first && !layerKey) fail(element, "'" + std::string(key) + "' is given twice");

    if (layerKey) {
      // The first context= (focus=) replaces the defaults' layers; each further one adds a layer
      // behind it (another focus surface), in the order given.
      const bool context = key == "context";
      std::vector<ClearViewLayer>& more = context ? s.deeperContexts : s.moreFoci;
      if (first) more.clear();
      if (!first && more.size() + 1 >= size_t(kClearViewMaxLayers))
        fail(element,
             "at most " + std::to_string(kClearViewMaxLayers) + " " + std::string(key) + " layers");
      const ClearViewLayer layer = parseLayer(engine, element, key, value);
      if (first)
        (context ? s.context : s.focus) = layer;
      else
        more.push_back(layer);
    } else if (key == "volume") {
      s.volumeLayer = flag(element, value);
    } else if (key == "measure") {
      s.measure = parseMeasure(element, value);
    } else if (key == "shader") {
      s.contextShader = parseShader(element, value);
    } else if (key == "focus-shader") {
      s.focusShader = parseShader(element, value);
    } else if (key == "at") {
      const size_t colon = value.find(':');
      if (colon == std::string_view::npos) fail(element, "expected at=PX:PY (pixels)");
      const char* what = "a pixel coordinate from the top-left corner";
      const glm::vec2 p{floatNumber(element, value.substr(0, colon), what),
                        floatNumber(element, value.substr(colon + 1), what)};
      // A negative coordinate means the image centre (visopt/clearview.h).
      if (p.x >= float(imageSize.x) || p.y >= float(imageSize.y))
        fail(element, "outside the " + std::to_string(imageSize.x) + "x" +
                          std::to_string(imageSize.y) + " image");
      s.focusPixel = p;
    } else if (key == "size") {
      s.size = floatNumber(element, value, "world units");
      if (!(s.size > 0.f)) fail(element, "the hotspot size must be > 0 (world units)");
    } else if (key == "weight") {
      s.weight = floatNumber(element, value, "the measure's weight");
      if (!(s.weight >= 0.f)) fail(element, "the weight must be >= 0");
    } else if (key == "distance-scale") {
      s.distanceScale = floatNumber(element, value, "world units");
      if (!(s.distanceScale >= 0.f))
        fail(element, "the distance scale must be >= 0 (0: the hotspot size)");
    } else if (key == "border") {
      s.border = flag(element, value);
    } else if (key == "ambient") {
      s.ambient = floatNumber(element, value, "the ambient term");
      if (!(s.ambient >= 0.f && s.ambient <= 1.f)) fail(element, "ambient must lie in [0, 1]");
    } else if (key == "light") {
      if (value == "camera")
        s.headlight = true;
      else if (value == "scene")
        s.headlight = false;
      else
        fail(element, "expected camera or scene");
    } else {
      fail(element, "unknown key '" + std::string(key) + "' (keys: " + kKeys + ")");
    }
  }

  // The layers' defaults follow the scene (a session's settings carry their own layers).
  if (!seen.count("context") && !base) {
    if (engine.contextSurfaces().empty())
      throw Error(ErrorKind::Usage,
                  "--clearview: give context=iso:VALUE (this scene has no context surface)");
    s.context = ClearViewLayer{ClearViewLayerKind::ContextSurface, 0.0, 0};
  }
  if (!seen.count("focus") && !base) {
    if (!engine.hasImportance())
      throw Error(ErrorKind::Usage,
                  "--clearview: give focus=iso:VALUE (this scene has no importance)");
    s.focus = ClearViewLayer{ClearViewLayerKind::Importance, 0.5, 0};
  }

  // What the library checks besides (image size, colours, ...), named as this option's.
  try {
    checkClearViewSettings(s);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Usage) throw;
    throw asClearViewOptionError(e);
  }
  return s;
}

}  // namespace visopt::cli
