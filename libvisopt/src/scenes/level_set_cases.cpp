// Paper 000's Fig. 3 ("level-set-cases"): the three ways an important object can lie relative to
// an opaque context surface, side by side across x, seen from -y (the camera looks along +y).
//
//   left   (x < 0): the important object is in front of the context surface. The surface hides
//                   nothing important, so its isocontour does not change.
//   middle (x = 0): the important object is nested inside a hollow context shell. The level set
//                   evolves inward where the shell's front wall hides the object and opens it;
//                   the back wall, behind the object, stays.
//   right  (x > 0): the important object is behind a context rod. The rod's occluding middle
//                   shrinks from its front and back until the isocontour splits into two parts;
//                   the stumps keep their shape, and the rod returns to its initial shape when
//                   the occlusion is gone (the camera turned to the other side).
//
// Data values are ordered important (-0.8) < air (0) < context (1), as in earth-mantle, so the
// smooth edge between air and context never passes through the important range: the context
// surface is the isosurface at 0.6 (inside-high, filled), the importance marks the important
// shapes themselves (the region of values below about -0.45).
#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {

constexpr float kContextValue = 1.f, kImportantValue = -0.8f;
constexpr float kCaseX = 0.62f;  // |x| of the left and right cases' centres

// Left: an important ball in front of a solid context ball.
const SoftEllipsoid kLeftImportant({-kCaseX, -0.35f, 0.f}, glm::vec3(0.12f), 0.f);
const SoftEllipsoid kLeftContext({-kCaseX, 0.1f, 0.f}, glm::vec3(0.24f), 0.f);

// Middle: a hollow context shell (walls 8 mm, 2.5 voxels at 64^3) around an important disc
// facing the camera.
constexpr float kShellOuter = 0.3f, kShellInner = 0.22f;
const SoftEllipsoid kMiddleImportant({0.f, 0.f, 0.f}, {0.16f, 0.04f, 0.16f}, 0.f);

// Right: a vertical context rod (a capsule along z) in front of an important ball.
constexpr float kRodX = 0.54f, kRodY = -0.3f, kRodRadius = 0.08f, kRodHalfLength = 0.4f;
const SoftEllipsoid kRightImportant({kCaseX, 0.25f, 0.f}, glm::vec3(0.18f), 0.f);

float rodDistance(glm::vec3 p) {
  const float z = glm::clamp(p.z, -kRodHalfLength, kRodHalfLength);
  return glm::length(p - glm::vec3(kRodX, kRodY, z)) - kRodRadius;
}

}  // namespace

BuiltinScene makeLevelSetCases(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("level-set-cases", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);

  auto important = [=](glm::vec3 p) {
    const float a = softInside(kLeftImportant.distance(p), w);
    const float b = softInside(kMiddleImportant.distance(p), w);
    const float c = softInside(kRightImportant.distance(p), w);
    return 1.f - (1.f - a) * (1.f - b) * (1.f - c);
  };
  auto context = [=](glm::vec3 p) {
    const float a = softInside(kLeftContext.distance(p), w);
    const float r = glm::length(p);
    const float shellHalf = 0.5f * (kShellOuter - kShellInner);
    const float b = softInside(std::abs(r - (kShellOuter - shellHalf)) - shellHalf, w);
    const float c = softInside(rodDistance(p), w);
    return 1.f - (1.f - a) * (1.f - b) * (1.f - c);
  };

  BuiltinScene scene;
  scene.volume =
      generateVolume("level-set-cases", grid, precision, ledger, -1.0, 1.0, [=](glm::vec3 p) {
        float v = 0.f;
        v += (kImportantValue - v) * important(p);
        v += (kContextValue - v) * context(p);
        return v;
      });
  scene.importance = generateImportance(grid, precision, ledger, important);

  TransferFunction& tf = scene.transferFunction;
  tf.name = "level-set-cases";
  tf.unitDistance = 2.f;  // mm
  tf.opacity = {{-1.0, 0.9f}, {-0.5, 0.9f}, {-0.35, 0.f}, {0.5, 0.f}, {0.6, 0.97f}, {1.0, 0.97f}};
  tf.color = {{-1.0, {0.85f, 0.25f, 0.2f}},
              {-0.35, {0.95f, 0.55f, 0.3f}},
              {0.5, {0.75f, 0.8f, 0.9f}},
              {1.0, {0.75f, 0.8f, 0.9f}}};
  tf.validate("scene level-set-cases");
  // With context surfaces the context material is a surface, transparent in the volume.
  scene.contextSurfaces = {
      ContextSurfaceSpec{"iso:0.6:inside-high", true, 0.f, glm::vec3(0.72f, 0.78f, 0.88f), true}};
  scene.contextTransferFunction = tf;
  scene.contextTransferFunction.opacity = {{-1.0, 0.9f}, {-0.5, 0.9f}, {-0.35, 0.f}, {1.0, 0.f}};
  scene.azimuthDeg = 0.f;
  scene.elevationDeg = 0.f;
  scene.distanceInRadii = 2.4f;
  // Important: values below about -0.45 (normalised t < 0.275), as the importance field marks.
  scene.importanceCurve = {{0.f, 1.f}, {0.25f, 1.f}, {0.3f, 0.f}, {1.f, 0.f}};
  return scene;
}

}  // namespace visopt::scenes
