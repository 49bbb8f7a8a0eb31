// Volume occlusion without a surface ("wall-and-membrane", called "occluded-blob" until
// 2026-12-04): a dense wall of unimportant matter stands between the camera and an optically thin
// important disc (a "membrane"), which it hides completely at first; what the extinction
// optimisation of Himmler & Günther's predecessor [9] opens. It is not paper 000's Fig. 3, whose
// cases are about a context surface.
//
// Why a thin disc: the energy rewards g mu T_V (Eq. 12), so inside an important structure the
// optimisation raises mu towards mu_max, and a thick structure then shades its own back; its
// importance-weighted visibility V = ∫ g mu T_V / ∫ g mu is bounded by (1 - e^-tau) / tau with
// tau = mu_max times its depth. Here the disc is at most a voxel deep (3 mm at 64^3), so tau
// stays below about 0.25 and V can rise from ~0.03 (the wall's transmittance) to above 0.8.
//
// Units: the scene spans 200 mm; normalised coordinates are world / 100 mm. The wall's
// extinction (0.06 / mm) is the transfer function's maximum, i.e. mu_max of Eq. 14.
#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {

// Data values (normalised axis [0, 1]).
constexpr float kWallValue = 1.f;
constexpr float kDiscValue = 0.4f;

// The wall: a box across x and z, 60 mm deep along y (the camera looks along +y).
constexpr float kWallY0 = -0.65f, kWallY1 = -0.05f, kWallHalfWidth = 0.8f;
// The disc behind it, facing the camera.
constexpr float kDiscY = 0.3f, kDiscRadius = 0.4f;
constexpr float kDiscHalfThickness = 0.015f;  // 3 mm deep, but never less than one voxel

// Approximate signed distance (normalised units) to an axis-aligned box of half-extents h.
float boxDistance(glm::vec3 p, glm::vec3 centre, glm::vec3 h) {
  const glm::vec3 q = glm::abs(p - centre) - h;
  return glm::length(glm::max(q, glm::vec3(0.f))) +
         glm::min(glm::max(q.x, glm::max(q.y, q.z)), 0.f);
}

}  // namespace

BuiltinScene makeWallAndMembrane(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("wall-and-membrane", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);  // one voxel
  const glm::vec3 wallCentre(0.f, 0.5f * (kWallY0 + kWallY1), 0.f);
  const glm::vec3 wallHalf(kWallHalfWidth, 0.5f * (kWallY1 - kWallY0), kWallHalfWidth);
  // The disc is a membrane: 3 mm deep, but never less than one voxel, with its centre on the
  // voxel plane nearest kDiscY and a sharp edge (half-width half a voxel) across its depth, so
  // at coarse resolutions exactly one plane of voxels holds it, at full value and importance.
  // A softer edge would spread the importance over three planes, each of which the energy
  // drives to mu_max, and triple the disc's optical depth.
  const float h = w;  // the voxel size, normalised units
  const float discY = -1.f + std::round((kDiscY + 1.f) / h) * h;
  const float discHalf = glm::max(kDiscHalfThickness, 0.5f * h);
  const float discEdge = 0.5f * h;
  const SoftEllipsoid disc(glm::vec3(0.f, discY, 0.f),
                           glm::vec3(kDiscRadius, discHalf, kDiscRadius), 0.f);

  BuiltinScene scene;
  scene.volume =
      generateVolume("wall-and-membrane", grid, precision, ledger, 0.0, 1.0, [=](glm::vec3 p) {
        return kWallValue * softInside(boxDistance(p, wallCentre, wallHalf), w) +
               kDiscValue * softInside(disc.distance(p), discEdge);
      });
  // Importance from the disc's geometry, so the wall's soft faces (which pass through the disc's
  // value) stay at exactly 0.
  scene.importance = generateImportance(
      grid, precision, ledger, [=](glm::vec3 p) { return softInside(disc.distance(p), discEdge); });

  TransferFunction& tf = scene.transferFunction;
  tf.name = "wall-and-membrane";
  tf.unitDistance = 10.f;  // mm: an opacity is what 10 mm of the material absorbs
  // The wall: mu = 0.06 / mm (alpha 0.451 per 10 mm), 60 mm deep: transmittance e^-3.6 = 0.027.
  // The disc: mu_bar = 0.005 / mm (alpha 0.049 per 10 mm), faint on its own.
  tf.opacity = {{0.0, 0.f},  {0.25, 0.f}, {0.32, 0.049f}, {0.48, 0.049f},
                {0.55, 0.f}, {0.8, 0.f},  {0.9, 0.451f},  {1.0, 0.451f}};
  tf.color = {{0.0, {0.60f, 0.60f, 0.65f}},
              {0.3, {0.95f, 0.35f, 0.15f}},
              {0.5, {0.95f, 0.35f, 0.15f}},
              {0.8, {0.70f, 0.75f, 0.80f}},
              {1.0, {0.70f, 0.75f, 0.80f}}};
  tf.validate("scene wall-and-membrane");
  // No context surface: this is the volume form of the scenario. The level-set flow of Eq. 23
  // moves a surface by its curvature (F = -ghat kappa) and by grad ghat . grad phi, both zero on
  // the flat faces of a wall, so the wall as a surface would never open in front of the disc.
  // Straight on: the camera on -y looks along +y through the wall at the disc.
  scene.azimuthDeg = 0.f;
  scene.elevationDeg = 0.f;
  scene.distanceInRadii = 2.8f;
  scene.importanceCurve = {{0.f, 0.f},   {0.3f, 0.f}, {0.35f, 1.f},
                           {0.45f, 1.f}, {0.5f, 0.f}, {1.f, 0.f}};
  return scene;
}

}  // namespace visopt::scenes
