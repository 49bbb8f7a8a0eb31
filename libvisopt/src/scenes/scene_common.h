// Shared helpers for the procedural scenes: the scene grid (a cube of fixed physical size,
// centred at the origin, voxel centres spanning it), a parallel generator that samples a value
// function at every voxel centre and stores it normalised, and smooth (anti-aliased) shapes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "exec/parallel.h"
#include "visopt/grid.h"
#include "visopt/precision.h"
#include "visopt/volume.h"

namespace visopt {
class MemoryLedger;
}

namespace visopt::scenes {

// Physical edge length of every built-in scene (world units, mm). Scene code works in
// normalised coordinates [-1, 1]^3, i.e. world / (kSceneSize / 2).
constexpr float kSceneSize = 200.f;
constexpr float kSceneHalf = 0.5f * kSceneSize;

// Throws Error(Usage) unless 2 <= resolution <= 1024.
void checkResolution(const std::string& scene, int resolution);

// A resolution^3 grid whose voxel centres span [-kSceneHalf, kSceneHalf]^3, direction identity.
GridSpec sceneGrid(int resolution);

// Half-width (normalised units) of the smooth edge of shapes: one voxel. A narrower edge shows
// the voxel terraces in gradient-based shading as moiré rings on smooth surfaces.
inline float edgeHalfWidth(const GridSpec& grid) {
  return 1.0f * grid.minSpacing() / kSceneHalf;
}

// Hermite smoothstep, 0 below e0 and 1 above e1.
inline float smoothStep(float e0, float e1, float x) {
  float t = glm::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

// Soft inside-indicator from an (approximate) signed distance d (< 0 inside), edge half-width w.
inline float softInside(float d, float w) {
  return 1.f - smoothStep(-w, w, d);
}

// Samples f(p) (p in normalised coordinates) at every voxel centre of `field`, in parallel, and
// stores offset + scale * f(p) clamped to [0, 1].
template <class F>
void sampleIntoField(Field3D& field, float offset, float scale, F f) {
  const FieldView view(field);
  const GridSpec g = field.grid();
  const int64_t nx = g.dims.x, ny = g.dims.y;
  exec::parallelFor("scene-generate", static_cast<int64_t>(g.voxelCount()), [=](int64_t idx) {
    const int64_t i = idx % nx, j = (idx / nx) % ny, k = idx / (nx * ny);
    const glm::vec3 world = g.indexToWorld(
        glm::vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)));
    view.store(static_cast<size_t>(idx),
               glm::clamp(offset + scale * f(world / kSceneHalf), 0.f, 1.f));
  });
}

// Samples value(p) (p in normalised coordinates, value in data units) at every voxel centre and
// stores (value - valueMin) / (valueMax - valueMin), clamped to [0, 1], in Field3D "volume".
template <class F>
Volume generateVolume(const std::string& name, const GridSpec& grid, Precision precision,
                      MemoryLedger* ledger, double valueMin, double valueMax, F value) {
  Volume vol;
  vol.name = name;
  vol.sourcePath = "builtin:" + name;
  vol.scalarType = "float32";
  vol.valueMin = valueMin;
  vol.valueMax = valueMax;
  vol.normalized = Field3D("volume", grid, precision, ledger);
  const float invSpan = static_cast<float>(1.0 / (valueMax - valueMin));
  sampleIntoField(vol.normalized, -static_cast<float>(valueMin) * invSpan, invSpan, value);
  return vol;
}

// The scene's importance g(p) in [0, 1] (clamped), sampled like the volume on the same grid and
// at the same precision, in Field3D "importance".
template <class F>
Field3D generateImportance(const GridSpec& grid, Precision precision, MemoryLedger* ledger,
                           F importance) {
  Field3D field("importance", grid, precision, ledger);
  sampleIntoField(field, 0.f, 1.f, importance);
  return field;
}

// Soft indicator of {f > level} for a smooth analytic f (normalised coordinates), from the
// first-order signed distance (level - f) / |grad f| with a central-difference gradient, so the
// edge is about 2w wide wherever the level set is regular.
template <class F>
float softAbove(F f, glm::vec3 p, double level, float w) {
  const glm::dvec3 q(p);
  constexpr double h = 1e-4;
  const double fx = f(q + glm::dvec3(h, 0, 0)) - f(q - glm::dvec3(h, 0, 0));
  const double fy = f(q + glm::dvec3(0, h, 0)) - f(q - glm::dvec3(0, h, 0));
  const double fz = f(q + glm::dvec3(0, 0, h)) - f(q - glm::dvec3(0, 0, h));
  const double grad = std::sqrt(fx * fx + fy * fy + fz * fz) / (2.0 * h);
  const double d = (level - f(q)) / std::max(grad, 1e-9);
  return softInside(static_cast<float>(glm::clamp(d, -1e3, 1e3)), w);
}

}  // namespace visopt::scenes

namespace visopt::scenes {

// An ellipsoid (normalised coordinates) rotated by `angleDeg` about +z, with an approximate
// signed distance (|q| - 1) / |grad |q|| that is exact on the surface, so soft edges have the
// same width everywhere.
struct SoftEllipsoid {
  glm::vec3 center{0.f};
  glm::vec3 invAxes{1.f};
  float cosA = 1.f, sinA = 0.f;

  SoftEllipsoid() = default;
  SoftEllipsoid(glm::vec3 c, glm::vec3 semiAxes, float angleDeg)
      : center(c),
        invAxes(1.f / semiAxes),
        cosA(std::cos(glm::radians(angleDeg))),
        sinA(std::sin(glm::radians(angleDeg))) {}

  glm::vec3 local(glm::vec3 p) const {
    const glm::vec3 d = p - center;
    return glm::vec3(cosA * d.x + sinA * d.y, -sinA * d.x + cosA * d.y, d.z);
  }
  bool contains(glm::vec3 p) const {
    const glm::vec3 q = local(p) * invAxes;
    return glm::dot(q, q) <= 1.f;
  }
  float distance(glm::vec3 p) const {
    const glm::vec3 q = local(p) * invAxes;
    const float s = glm::length(q);
    if (s < 1e-6f) return -1.f / glm::max(invAxes.x, glm::max(invAxes.y, invAxes.z));
    return (s - 1.f) / glm::length(q * invAxes / s);
  }
};

}  // namespace visopt::scenes
