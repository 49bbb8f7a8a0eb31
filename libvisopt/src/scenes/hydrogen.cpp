// A hydrogen-orbital-like field: the probability density of the 3d_z2 orbital,
// |psi_320|^2 ~ r^4 exp(-2r/3) (3 cos^2 theta - 1)^2 (r in Bohr radii, the volume spans
// +-20), normalised to its maximum (1 on the lobes along z, 1/4 on the equatorial torus).
// The torus is drawn as an opaque context ring; the lobes are what the importance marks.
#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {

constexpr double kBohrPerUnit = 20.0;
// The lobes' marked core: density above this fraction of the peak (the torus peaks at 1/4).
constexpr double kLobeLevel = 0.4;

// |psi_320|^2 at p (normalised coordinates) divided by its maximum. The maximum of
// r^4 exp(-2r/3) is at r = 6; (3 cos^2 - 1)^2 peaks at 4 on the z axis.
double orbitalDensity(glm::dvec3 p) {
  const double peak = 4.0 * 1296.0 * std::exp(-4.0);
  const glm::dvec3 q = p * kBohrPerUnit;
  const double r2 = glm::dot(q, q);
  const double angular = 3.0 * q.z * q.z - r2;  // r^2 (3 cos^2 - 1)
  return angular * angular * std::exp(-2.0 * std::sqrt(r2) / 3.0) / peak;
}

}  // namespace

BuiltinScene makeHydrogen(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("hydrogen", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);
  BuiltinScene scene;
  scene.volume = generateVolume("hydrogen", grid, precision, ledger, 0.0, 1.0, [](glm::vec3 p) {
    return static_cast<float>(orbitalDensity(glm::dvec3(p)));
  });
  // Importance: the two lobes along z, as the soft region where the analytic density exceeds
  // kLobeLevel (the torus never does), each wrapped in its own semi-opaque low-density envelope.
  scene.importance = generateImportance(grid, precision, ledger, [=](glm::vec3 p) {
    return softAbove(orbitalDensity, p, kLobeLevel, w);
  });
  TransferFunction& tf = scene.transferFunction;
  tf.name = "hydrogen";
  tf.unitDistance = 2.f;
  tf.opacity = {{0.0, 0.f},   {0.03, 0.f}, {0.12, 0.25f}, {0.25, 0.5f},
                {0.35, 0.1f}, {0.6, 0.4f}, {1.0, 0.7f}};
  tf.color = {{0.0, {0.20f, 0.40f, 0.90f}},
              {0.25, {0.30f, 0.55f, 0.95f}},
              {0.5, {0.95f, 0.75f, 0.30f}},
              {1.0, {0.95f, 0.40f, 0.15f}}};
  tf.validate("scene hydrogen");
  scene.azimuthDeg = 15.f;
  scene.elevationDeg = 10.f;
  scene.distanceInRadii = 2.8f;
  scene.importanceCurve = {{0.f, 0.f}, {0.35f, 0.f}, {0.5f, 1.f}, {1.f, 1.f}};
  return scene;
}

}  // namespace visopt::scenes
