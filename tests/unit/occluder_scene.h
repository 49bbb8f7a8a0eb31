// A small scene built in code for optimisation tests: a dense slab between the camera (on -y)
// and an important blob behind it, on an n^3 grid of unit spacing centred at the origin.
#pragma once

#include <cmath>

#include "visopt/engine.h"

namespace visopt::testing {

struct OccluderScene {
  static constexpr float kSlabValue = 1.f, kBlobValue = 0.5f;
  int n = 40;
  float slabY0 = -12.f, slabY1 = -2.f;  // the occluding slab, across x and z
  // The important structure: a thin disc facing the camera. The energy raises mu inside
  // important structures up to mu_max (Eq. 12 rewards g mu T), so only an optically thin one can
  // reach a high importance-weighted visibility V = ∫ g mu T / ∫ g mu.
  glm::vec3 blobCentre{0.f, 6.5f, 0.f};  // on a voxel plane (centres at half-integers)
  float blobRadius = 5.f;
  float blobHalfThickness = 0.4f;  // along y, one voxel plane; a sphere when = radius
};

inline Volume makeOccluderVolume(const OccluderScene& s, Precision precision) {
  GridSpec g;
  g.dims = glm::ivec3(s.n);
  g.origin = glm::vec3(-0.5f * float(s.n - 1));
  Volume v;
  v.name = "occluder";
  v.sourcePath = "test:occluder";
  v.scalarType = "float32";
  v.valueMin = 0.0;
  v.valueMax = 1.0;
  v.normalized = Field3D("volume", g, precision);
  for (int k = 0; k < s.n; ++k)
    for (int j = 0; j < s.n; ++j)
      for (int i = 0; i < s.n; ++i) {
        const glm::vec3 x = g.indexToWorld(glm::vec3(float(i), float(j), float(k)));
        float value = 0.f;
        if (x.y >= s.slabY0 && x.y <= s.slabY1) value = OccluderScene::kSlabValue;
        const glm::vec3 d = x - s.blobCentre;
        if (std::hypot(d.x, d.z) <= s.blobRadius && std::abs(d.y) <= s.blobHalfThickness &&
            glm::length(d) <= s.blobRadius)
          value = OccluderScene::kBlobValue;
        v.normalized.set(g.linearIndex(i, j, k), value);
      }
  return v;
}

// Slab: extinction 0.3 per unit (10 units: T = 0.05) = mu_max; blob: 0.02 per unit; empty: 0.
inline TransferFunction occluderTransferFunction() {
  TransferFunction tf;
  tf.name = "occluder";
  tf.unitDistance = 1.f;
  auto alpha = [](float mu) { return 1.f - std::exp(-mu); };
  tf.opacity = {
      {0.0, 0.f}, {0.25, 0.f}, {0.5, alpha(0.02f)}, {0.75, alpha(0.02f)}, {1.0, alpha(0.3f)}};
  tf.color = {{0.0, glm::vec3(0.8f)}, {0.5, glm::vec3(0.9f, 0.2f, 0.1f)}, {1.0, glm::vec3(0.8f)}};
  return tf;
}

// g = 1 on the blob's values only.
inline std::vector<glm::dvec2> blobImportance() {
  return {{0.0, 0.0}, {0.4, 0.0}, {0.45, 1.0}, {0.55, 1.0}, {0.6, 0.0}, {1.0, 0.0}};
}

// A thin-shell sphere's SDF (Eq. 26) on a grid: |(|x| - radius)| - shell.
inline Field3D shellSphereSdf(const GridSpec& g, float radius, float shell) {
  Field3D phi("sphere", g, Precision::FP32);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::vec3 x = g.indexToWorld(glm::vec3(float(i), float(j), float(k)));
        phi.set(g.linearIndex(i, j, k), std::abs(glm::length(x) - radius) - shell);
      }
  return phi;
}

inline void loadOccluderScene(Engine& engine, const OccluderScene& s = {}) {
  engine.setVolume(makeOccluderVolume(s, engine.precision()));
  engine.setTransferFunction(occluderTransferFunction());
  engine.setImportanceCurve(blobImportance());
  engine.setCamera(Camera::orbit({0, 0, 0}, 0.f, 0.f, 90.f));  // on -y, looking along +y
  PointLight light;
  light.position = {0.f, -90.f, 0.f};
  engine.setLight(light);
  engine.setViewportSize(64, 64);
}

}  // namespace visopt::testing
