// Analytic fields and a camera for the ClearView tests (test_clearview, test_clearview_layers):
// a 64^3 unit-spacing grid centred at the origin, inside-high balls, and the exact first hit of a
// pixel's ray with a sphere.
#pragma once

#include <cmath>
#include <functional>

#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/frustum.h"
#include "visopt/grid.h"
#include "visopt/volume.h"

namespace visopt {

inline constexpr int kN = 64;  // voxels per side, unit spacing, centred at the origin

inline GridSpec cubeGrid() {
  GridSpec g;
  g.dims = {kN, kN, kN};
  g.origin = glm::vec3(-0.5f * float(kN - 1));
  return g;
}

inline Field3D fieldOf(const std::function<float(glm::vec3)>& f,
                       Precision precision = Precision::FP32) {
  const GridSpec g = cubeGrid();
  Field3D out("field", g, precision);
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i)
        out.set(g.linearIndex(i, j, k), f(g.indexToWorld(glm::vec3(i, j, k))));
  return out;
}

// Inside-high ball of radius r about the origin (the value is the distance to the sphere).
inline float ball(glm::vec3 x, float r) {
  return r - glm::length(x);
}

inline Volume volumeOf(Field3D field, double lo, double hi) {
  Volume v;
  v.name = "analytic";
  v.sourcePath = "test:analytic";
  v.scalarType = "float32";
  v.valueMin = lo;
  v.valueMax = hi;
  v.normalized = std::move(field);
  return v;
}

inline Camera frontCamera() {
  Camera c;
  c.eye = glm::vec3(0.f, -120.f, 10.f);
  c.target = glm::vec3(0.f);
  c.up = glm::vec3(0.f, 0.f, 1.f);
  c.fovYDegrees = 30.f;
  return c;
}

// The exact first intersection of the ray of pixel (x, row) with the sphere |p| = r.
inline bool exactSphereHit(const Camera& cam, const Bounds& bounds, int w, int h, int x, int row,
                           float r, glm::vec3& hit) {
  const FrustumGrid f = FrustumGrid::forCamera(cam, w, h, bounds, 1, 1.f);
  const glm::vec3 d = f.rayDirection(float(x), float(h - 1 - row));
  const glm::vec3 o = cam.eye;
  const float b = glm::dot(o, d), c = glm::dot(o, o) - r * r;
  const float disc = b * b - c;
  if (disc < 0.f) return false;
  hit = o + (-b - std::sqrt(disc)) * d;
  return true;
}

}  // namespace visopt
