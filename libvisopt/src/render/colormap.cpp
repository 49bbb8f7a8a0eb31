#include "visopt/colormap.h"

#include <cctype>

#include "core/colormap_eval.h"
#include "visopt/error.h"

namespace visopt {

namespace {
constexpr Colormap kAllColormaps[] = {Colormap::Viridis, Colormap::Magma, Colormap::Inferno,
                                      Colormap::CoolWarm, Colormap::Grey};
}

const char* toString(Colormap map) {
  switch (map) {
    case Colormap::Viridis:
      return "viridis";
    case Colormap::Magma:
      return "magma";
    case Colormap::Inferno:
      return "inferno";
    case Colormap::CoolWarm:
      return "coolwarm";
    case Colormap::Grey:
      return "grey";
  }
  return "unknown";
}

Colormap parseColormap(const std::string& name) {
  std::string lower = name;
  for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  for (Colormap map : kAllColormaps)
    if (lower == toString(map)) return map;
  if (lower == "gray") return Colormap::Grey;
  std::string valid;
  for (Colormap map : kAllColormaps)
    valid += std::string(valid.empty() ? "" : ", ") + toString(map);
  throw Error(ErrorKind::Usage, "unknown colormap \"" + name + "\" (valid: " + valid + ")");
}

std::vector<std::string> colormapNames() {
  std::vector<std::string> names;
  for (Colormap map : kAllColormaps) names.emplace_back(toString(map));
  return names;
}

glm::vec3 evaluateColormap(Colormap map, float t) {
  return colormapColor(map, t);
}

}  // namespace visopt
