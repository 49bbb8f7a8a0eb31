// The Marschner–Lobb scene: a reconstruction-filter benchmark; its transfer function shows the
// rho = 0.5 level as a semi-opaque layer over the high values, whose inner, rippled part (within
// a central sphere) the importance marks.
#include "scenes/marschner_lobb.h"

#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {
constexpr double kImportantLevel = 0.75;
constexpr float kImportantRadius = 0.6f;
}  // namespace

double marschnerLobb(glm::dvec3 p) {
  constexpr double pi = 3.14159265358979323846;
  const double r = std::sqrt(p.x * p.x + p.y * p.y);
  const double rhoR = std::cos(2.0 * pi * kMarschnerLobbFM * std::cos(pi * r / 2.0));
  return (1.0 - std::sin(pi * p.z / 2.0) + kMarschnerLobbAlpha * (1.0 + rhoR)) /
         (2.0 * (1.0 + kMarschnerLobbAlpha));
}

BuiltinScene makeMarschnerLobb(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("marschner-lobb", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);
  BuiltinScene scene;
  scene.volume =
      generateVolume("marschner-lobb", grid, precision, ledger, 0.0, 1.0,
                     [](glm::vec3 p) { return static_cast<float>(marschnerLobb(glm::dvec3(p))); });
  // Importance: the inner high-value lobes, {rho > kImportantLevel} within the central sphere
  // |p| < kImportantRadius: the rippled lower lobes under the rho = 0.5 sheet. The sphere keeps
  // them away from the volume's sides, so every view from above sees them through the sheet.
  scene.importance = generateImportance(grid, precision, ledger, [=](glm::vec3 p) {
    const float sphere = softInside(glm::length(p) - kImportantRadius, w);
    if (sphere <= 0.f) return 0.f;
    return sphere * softAbove(marschnerLobb, p, kImportantLevel, w);
  });
  TransferFunction& tf = scene.transferFunction;
  tf.name = "marschner-lobb";
  tf.unitDistance = 2.f;
  tf.opacity = {{0.0, 0.f}, {0.42, 0.f}, {0.5, 0.5f}, {0.58, 0.f},
                {0.7, 0.f}, {0.8, 0.2f}, {1.0, 0.4f}};
  tf.color = {{0.0, {0.20f, 0.35f, 0.80f}},
              {0.5, {0.85f, 0.85f, 0.85f}},
              {0.75, {0.95f, 0.60f, 0.20f}},
              {1.0, {0.90f, 0.20f, 0.10f}}};
  tf.validate("scene marschner-lobb");
  scene.azimuthDeg = 30.f;
  scene.elevationDeg = 35.f;
  scene.distanceInRadii = 2.8f;
  scene.importanceCurve = {{0.f, 0.f}, {0.7f, 0.f}, {0.8f, 1.f}, {1.f, 1.f}};
  return scene;
}

}  // namespace visopt::scenes
