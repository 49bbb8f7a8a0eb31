// Analytic fields on grids for the level-set tests (test_level_set, test_level_set_band): a
// field sampled at voxel centres, spheres, the equivalent radius of {phi < 0}, evenly spread
// directions.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "visopt/field.h"
#include "visopt/grid.h"

namespace visopt::testing_fixtures {

using Fn = std::function<float(glm::vec3)>;  // of the world position of a voxel centre

inline GridSpec cube(int n, glm::vec3 spacing = glm::vec3(1.f)) {
  GridSpec g;
  g.dims = glm::ivec3(n);
  g.spacing = spacing;
  return g;
}

inline Field3D makeField(const char* name, const GridSpec& g, Precision p, const Fn& f) {
  Field3D out(name, g, p);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i)
        out.set(g.linearIndex(i, j, k), f(g.indexToWorld(glm::vec3(i, j, k))));
  return out;
}

inline Fn sphere(glm::vec3 centre, float radius) {
  return [=](glm::vec3 x) { return glm::length(x - centre) - radius; };
}
inline Fn constant(float c) {
  return [=](glm::vec3) { return c; };
}

// Volume of {phi < 0} with a linear partial-voxel fraction at the interface, as the radius
// of the sphere of that volume.
inline double equivalentRadius(const Field3D& phi) {
  const glm::vec3 h = phi.grid().spacing;
  const double hMin = phi.grid().minSpacing();
  double volume = 0.0;
  for (size_t v = 0; v < phi.size(); ++v)
    volume += std::clamp(0.5 - double(phi.get(v)) / hMin, 0.0, 1.0);
  volume *= double(h.x) * h.y * h.z;
  return std::cbrt(3.0 * volume / (4.0 * std::numbers::pi));
}

// Evenly spread unit directions (a Fibonacci sphere).
inline std::vector<glm::vec3> directions(int n) {
  std::vector<glm::vec3> out;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    out.emplace_back(float(r * std::cos(golden * i)), float(r * std::sin(golden * i)), float(z));
  }
  return out;
}

}  // namespace visopt::testing_fixtures
