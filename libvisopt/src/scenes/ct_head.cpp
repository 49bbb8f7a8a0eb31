// A CT-like head at small size, built to reproduce what real head scans do to the optimisation
// (issue: real scans stay hidden). It has what the Cranium CT has and the Shepp-Logan phantom
// has not: the context surface is the *skin* isosurface (-400 HU) of the data, so the whole
// head is inside it, with a thick layer of soft tissue between the skin and a thick skull, and
// the skull (bone) is what the importance marks. Values are Hounsfield units.
//
// Layers from outside in (normalised units, 1 = 100 mm): skin and subcutaneous soft tissue
// 6 mm, skull 7 mm of bone, 3 mm of cerebrospinal fluid, the brain. The head is an ellipsoid
// of 150 x 180 x 170 mm (x: ear to ear, y: back to face, z: up), cut flat at the neck.
#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {

constexpr float kAir = -1000.f, kSoftTissue = 40.f, kBone = 1300.f, kCsf = 10.f, kBrain = 35.f;
constexpr float kSkinHalfThickness = 2.f;  // mm, each side of the skin isosurface
constexpr float kBoneFrom = 200.f;         // HU: the importance's threshold
constexpr float kScalp = 0.06f, kSkull = 0.07f, kCsfGap = 0.03f;
const glm::vec3 kHeadAxes(0.75f, 0.9f, 0.85f);
const glm::vec3 kHeadCentre(0.f, 0.f, 0.05f);
constexpr float kNeckZ = -0.6f;  // the scan ends here (the neck cut)

// The layer boundaries as ellipsoids shrunk by a constant distance (approximately parallel
// surfaces; exact enough for layers much thinner than the axes).
SoftEllipsoid inset(float d) {
  return SoftEllipsoid(kHeadCentre, kHeadAxes - glm::vec3(d), 0.f);
}

}  // namespace

BuiltinScene makeCtHead(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("ct-head", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);
  const SoftEllipsoid skin = inset(0.f);
  const SoftEllipsoid skullOuter = inset(kScalp);
  const SoftEllipsoid skullInner = inset(kScalp + kSkull);
  const SoftEllipsoid brain = inset(kScalp + kSkull + kCsfGap);
  // Soft indicators of each region; the neck cut is a plane.
  auto below = [=](glm::vec3 p) { return softInside(kNeckZ - p.z, w); };  // 1 above the cut
  auto inHead = [=](glm::vec3 p) { return softInside(skin.distance(p), w) * below(p); };
  auto inBoneShell = [=](glm::vec3 p) {
    return softInside(skullOuter.distance(p), w) * (1.f - softInside(skullInner.distance(p), w)) *
           below(p);
  };

  auto value = [=](glm::vec3 p) {
    const float head = inHead(p);
    const float bone = inBoneShell(p);
    const float inside = softInside(skullInner.distance(p), w) * below(p);
    const float br = softInside(brain.distance(p), w) * below(p);
    // Soft tissue where the head is, bone over it, CSF inside the skull, the brain in it.
    float v = kAir + head * (kSoftTissue - kAir);
    v += bone * (kBone - kSoftTissue);
    v += inside * (kCsf - kSoftTissue);
    v += br * (kBrain - kCsf);
    return v;
  };
  BuiltinScene scene;
  scene.volume = generateVolume("ct-head", grid, precision, ledger, -1024.0, 2000.0, value);
  // Importance: bone by its value, as a user marks it on a CT's histogram: every voxel the
  // transfer function below makes opaque (from ~200 HU up) counts, so the partial-volume rim of
  // the skull is part of the structure rather than an occluder in front of it.
  scene.importance = generateImportance(grid, precision, ledger, [=](glm::vec3 p) {
    return smoothStep(kBoneFrom, kBoneFrom + 60.f, value(p));
  });

  // The Cranium preset's colours and opacities: skin a semi-opaque layer, soft tissue faint,
  // bone opaque ivory (ct-skin-bone).
  TransferFunction& tf = scene.transferFunction;
  tf.name = "ct-head";
  tf.unitDistance = 3.f;
  tf.opacity = {{-1024, 0.f}, {-700, 0.f},  {-500, 0.25f}, {-150, 0.25f},
                {-50, 0.03f}, {200, 0.03f}, {350, 0.85f},  {2000, 0.95f}};
  tf.color = {{-1024, {0.55f, 0.25f, 0.15f}}, {-500, {0.93f, 0.66f, 0.54f}},
              {-100, {0.93f, 0.66f, 0.54f}},  {100, {0.80f, 0.35f, 0.30f}},
              {300, {0.95f, 0.92f, 0.82f}},   {2000, {1.f, 1.f, 0.95f}}};
  tf.validate("scene ct-head");
  // With the skin as the context surface (the isosurface at -400 HU), the
  // volume shows what lies inside: soft tissue faint, bone opaque.
  // The skin as a thin shell 4 mm thick (defaultContextSurfaceSpec says why not filled).
  scene.contextSurfaces = {ContextSurfaceSpec{"iso:-400:inside-high", false, kSkinHalfThickness,
                                              glm::vec3(0.93f, 0.72f, 0.6f), true}};
  scene.contextTransferFunction = tf;
  scene.contextTransferFunction.opacity = {{-1024, 0.f}, {-150, 0.f},  {-50, 0.03f},
                                           {200, 0.03f}, {350, 0.85f}, {2000, 0.95f}};
  // The face, a little from above, as the Cranium CT's README command.
  scene.azimuthDeg = 0.f;
  scene.elevationDeg = 10.f;
  scene.distanceInRadii = 2.6f;
  const float lo = float((double(kBoneFrom) + 1024.0) / (2000.0 + 1024.0));
  const float hi = float((double(kBoneFrom) + 60.0 + 1024.0) / (2000.0 + 1024.0));
  scene.importanceCurve = {{0.f, 0.f}, {lo, 0.f}, {hi, 1.f}, {1.f, 1.f}};
  return scene;
}

}  // namespace visopt::scenes
