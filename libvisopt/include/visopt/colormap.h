// Colormaps for scalar overlays (the deviation view of Himmler & Günther 2026, Fig. 5 and the
// workstation's legends): a few perceptually ordered maps and a diverging one, evaluated in linear
// RGB.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace visopt {

enum class Colormap { Viridis, Magma, Inferno, CoolWarm, Grey };

// Lower-case names: "viridis", "magma", "inferno", "coolwarm", "grey".
const char* toString(Colormap map);
// The inverse of toString (case-insensitive); a Usage error listing the valid names otherwise.
Colormap parseColormap(const std::string& name);
std::vector<std::string> colormapNames();
// The colour at t (clamped to [0, 1]) in linear RGB, for the renderer and for display after the
// usual sRGB encoding.
glm::vec3 evaluateColormap(Colormap map, float t);

}  // namespace visopt
