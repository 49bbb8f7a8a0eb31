// The Marschner–Lobb test signal (Marschner & Lobb 1994) on [-1, 1]^3 with fM = 6, alpha = 0.25:
// rho(x,y,z) = (1 - sin(pi z / 2) + alpha (1 + cos(2 pi fM cos(pi r / 2)))) / (2 (1 + alpha)),
// r = sqrt(x^2 + y^2); values in [0, 1].
#pragma once

#include <glm/glm.hpp>

namespace visopt::scenes {

constexpr double kMarschnerLobbFM = 6.0;
constexpr double kMarschnerLobbAlpha = 0.25;

double marschnerLobb(glm::dvec3 p);

}  // namespace visopt::scenes
