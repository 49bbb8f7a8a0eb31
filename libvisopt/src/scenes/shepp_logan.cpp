// The default scene: the 3D Shepp–Logan phantom rendered with a transfer function that makes
// the outer shell ("skin") nearly opaque, hiding the tumours inside, which the importance marks.
#include "scenes/shepp_logan.h"

#include <array>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {
constexpr size_t kEllipsoids = 10;
// Table rows 4..9 are the tumours (density +0.1 on the brain's 0.2: 0.3 in all).
constexpr size_t kFirstTumour = 4;
constexpr size_t kTumours = kEllipsoids - kFirstTumour;
}  // namespace

const std::vector<PhantomEllipsoid>& sheppLoganEllipsoids() {
  // centre, semi-axes, rotation about z (degrees), density
  static const std::vector<PhantomEllipsoid> table = {
      {{0.f, 0.f, 0.f}, {0.69f, 0.92f, 0.81f}, 0.f, 1.0f},           // outer shell
      {{0.f, -0.0184f, 0.f}, {0.6624f, 0.874f, 0.78f}, 0.f, -0.8f},  // brain
      {{0.22f, 0.f, 0.f}, {0.11f, 0.31f, 0.22f}, -18.f, -0.2f},      // right ventricle
      {{-0.22f, 0.f, 0.f}, {0.16f, 0.41f, 0.28f}, 18.f, -0.2f},      // left ventricle
      {{0.f, 0.35f, -0.15f}, {0.21f, 0.25f, 0.41f}, 0.f, 0.1f},      // large tumour
      {{0.f, 0.1f, 0.25f}, {0.046f, 0.046f, 0.05f}, 0.f, 0.1f},      // small tumours
      {{0.f, -0.1f, 0.25f}, {0.046f, 0.046f, 0.05f}, 0.f, 0.1f},
      {{-0.08f, -0.605f, 0.f}, {0.046f, 0.023f, 0.05f}, 0.f, 0.1f},
      {{0.f, -0.606f, 0.f}, {0.023f, 0.023f, 0.02f}, 0.f, 0.1f},
      {{0.06f, -0.605f, 0.f}, {0.023f, 0.046f, 0.02f}, 0.f, 0.1f},
  };
  return table;
}

float sheppLoganDensity(glm::vec3 p) {
  float sum = 0.f;
  for (const auto& e : sheppLoganEllipsoids())
    if (SoftEllipsoid(e.center, e.semiAxes, e.angleDeg).contains(p)) sum += e.density;
  return sum;
}

BuiltinScene makeSheppLogan(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("shepp-logan", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);
  std::array<SoftEllipsoid, kEllipsoids> shapes;
  std::array<float, kEllipsoids> density{};
  const auto& table = sheppLoganEllipsoids();
  for (size_t n = 0; n < kEllipsoids; ++n) {
    shapes[n] = SoftEllipsoid(table[n].center, table[n].semiAxes, table[n].angleDeg);
    density[n] = table[n].density;
  }
  BuiltinScene scene;
  scene.volume = generateVolume("shepp-logan", grid, precision, ledger, 0.0, 1.0, [=](glm::vec3 p) {
    // Outside the head nothing contributes.
    if (shapes[0].distance(p) > w) return 0.f;
    float sum = 0.f;
    for (size_t n = 0; n < kEllipsoids; ++n)
      sum += density[n] * softInside(shapes[n].distance(p), w);
    return sum;
  });

  // Importance: the union of the tumour ellipsoids, from their geometry rather than their value,
  // so the shell's edges (which pass through 0.3) stay at exactly 0. A tumour thinner than two
  // voxels is dilated until the voxels around its centre reach 1 (the small ones at low
  // resolutions). The tumours lie at least 0.2 inside the brain; to keep even a dilated edge off
  // the shell, g is also cut to exactly 0 within two voxels of the brain's surface.
  std::array<SoftEllipsoid, kTumours> tumours;
  std::array<float, kTumours> dilation{};
  for (size_t n = 0; n < kTumours; ++n) {
    const glm::vec3 axes = table[kFirstTumour + n].semiAxes;
    tumours[n] = shapes[kFirstTumour + n];
    dilation[n] = glm::max(0.f, 2.f * w - glm::min(axes.x, glm::min(axes.y, axes.z)));
  }
  const SoftEllipsoid brain = shapes[1];
  scene.importance = generateImportance(grid, precision, ledger, [=](glm::vec3 p) {
    const float inBrain = softInside(brain.distance(p) + 3.f * w, w);
    if (inBrain <= 0.f) return 0.f;
    float g = 0.f;
    for (size_t n = 0; n < kTumours; ++n)
      g = glm::max(g, softInside(tumours[n].distance(p) - dilation[n], w));
    return g * inBrain;
  });

  TransferFunction& tf = scene.transferFunction;
  tf.name = "shepp-logan";
  tf.unitDistance = 2.f;  // mm
  // Ventricles and air clear, brain a faint haze, tumours (0.3) red, the shell nearly opaque
  // from 0.42 up: the shell is only about 3 mm thick, so at coarse resolutions its smoothed
  // profile peaks well below 1, and it must still hide the tumours.
  tf.opacity = {{0.0, 0.f},    {0.1, 0.f},  {0.2, 0.005f}, {0.25, 0.005f}, {0.28, 0.35f},
                {0.32, 0.35f}, {0.36, 0.f}, {0.42, 0.9f},  {0.8, 0.95f},   {1.0, 0.97f}};
  tf.color = {{0.0, {0.50f, 0.50f, 0.55f}},  {0.2, {0.75f, 0.70f, 0.70f}},
              {0.25, {0.75f, 0.70f, 0.70f}}, {0.28, {0.95f, 0.30f, 0.20f}},
              {0.32, {0.95f, 0.30f, 0.20f}}, {0.38, {0.93f, 0.70f, 0.58f}},
              {1.0, {0.98f, 0.85f, 0.75f}}};
  tf.validate("scene shepp-logan");
  // With context surfaces: the skull shell becomes a surface (the wall between the isovalue 0.5
  // on both faces, filled), and the volume shows only what is inside it.
  scene.contextSurfaces = {
      ContextSurfaceSpec{"iso:0.5:inside-high", true, 0.f, glm::vec3(0.93f, 0.74f, 0.62f), true}};
  scene.contextTransferFunction = tf;
  scene.contextTransferFunction.opacity = {{0.0, 0.f},     {0.1, 0.f},    {0.2, 0.005f},
                                           {0.25, 0.005f}, {0.28, 0.35f}, {0.32, 0.35f},
                                           {0.36, 0.f},    {1.0, 0.f}};
  scene.azimuthDeg = 25.f;
  scene.elevationDeg = 20.f;
  scene.distanceInRadii = 2.8f;
  // The tumours (density 0.3 on the normalised axis [0, 1]). The band is narrow because every
  // shell voxel's smooth edge also passes through 0.3 (air 0 -> shell 1 -> brain 0.2); the
  // narrower the band, the thinner that unwanted layer.
  scene.importanceCurve = {{0.f, 0.f},   {0.27f, 0.f}, {0.29f, 1.f},
                           {0.31f, 1.f}, {0.33f, 0.f}, {1.f, 0.f}};
  return scene;
}

}  // namespace visopt::scenes
