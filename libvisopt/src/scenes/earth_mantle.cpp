// An Earth-mantle-like temperature anomaly in [-1, 1]: an opaque crust shell (marker value 1),
// a hot core (0.7), a nearly neutral mantle (about 0) and cold subducting slabs (-0.8) sinking
// from the crust, plus detached cold blobs (-0.6). Cold is what matters: the importance marks it.
// The values are ordered slabs < mantle/space < core < crust, so the smooth transition between
// two materials never passes through the cold range.
#include <array>
#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {

constexpr float kCrustOuter = 1.f, kCrustInner = 0.94f, kCoreRadius = 0.5f;
constexpr float kCrustValue = 1.f, kCoreValue = 0.7f, kSlabValue = -0.8f, kBlobValue = -0.6f;

// A sheet sinking from the crust: centred on the surface direction n0, extending +-halfAngle
// along the strike t, and bending towards b = n0 x t as it sinks (dipAngle at the bottom).
struct Slab {
  glm::vec3 n0{0.f, 0.f, 1.f}, t{1.f, 0.f, 0.f}, b{0.f, 1.f, 0.f};
  float halfAngle = 0.4f, halfThickness = 0.035f, bottom = 0.55f, dipAngle = 0.3f;
  float cosCap = 0.f;  // cheap rejection: dot(dir, capAxis) < cosCap is outside

  Slab() = default;
  Slab(glm::vec3 normal, glm::vec3 strikeHint, float halfAngleRad, float bottomRadius, float dip)
      : halfAngle(halfAngleRad), bottom(bottomRadius), dipAngle(dip) {
    n0 = glm::normalize(normal);
    t = glm::normalize(strikeHint - glm::dot(strikeHint, n0) * n0);
    b = glm::cross(n0, t);
    cosCap = std::cos(halfAngle + std::abs(dipAngle) + 0.25f);
  }

  // Soft indicator at p (|p| = r, dir = p / r), edge half-width w.
  float inside(glm::vec3 dir, float r, float w) const {
    if (r < bottom - 2.f * w || r > kCrustInner + 0.02f) return 0.f;
    if (glm::dot(dir, n0) < cosCap) return 0.f;
    const float depth = glm::clamp((kCrustInner + 0.01f - r) / (kCrustInner - bottom), 0.f, 1.f);
    const float along = std::atan2(glm::dot(dir, b), glm::dot(dir, n0));
    const float strike = std::asin(glm::clamp(glm::dot(dir, t), -1.f, 1.f));
    // Thinner and narrower with depth (a tongue), and buckled along the strike.
    const float thickness = halfThickness * (1.f - 0.35f * depth);
    const float buckle = 0.06f * depth * std::sin(3.f * strike / halfAngle);
    const float dThick = std::abs(along - dipAngle * depth * depth - buckle) * r - thickness;
    const float dStrike = std::abs(strike) * r - halfAngle * (1.f - 0.4f * depth * depth) * r;
    const float dBottom = bottom - r;
    return softInside(dThick, w) * softInside(dStrike, 2.f * w) * softInside(dBottom, 2.f * w);
  }
};

// Small smooth mantle heterogeneity, +-0.05: nowhere near the cold or hot ranges.
float mantleNoise(glm::vec3 p) {
  return 0.025f * std::sin(7.f * p.x + 1.3f) * std::sin(6.f * p.y + 0.7f) *
             std::sin(5.f * p.z + 2.1f) +
         0.02f * std::sin(11.f * (p.x + p.y) + 0.4f) * std::cos(9.f * p.z - 0.3f);
}

}  // namespace

BuiltinScene makeEarthMantle(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("earth-mantle", resolution);
  const GridSpec grid = sceneGrid(resolution);
  // Slab edges are softened over a little more than a voxel: they are blobby, not machined.
  const float w = edgeHalfWidth(grid);
  const float ws = glm::max(w, 0.012f);
  const std::array<Slab, 4> slabs = {
      Slab({0.3f, -0.8f, 0.5f}, {1.f, 0.2f, 0.f}, 0.45f, 0.55f, 0.35f),
      Slab({-0.6f, -0.6f, 0.1f}, {0.f, 0.f, 1.f}, 0.35f, 0.6f, -0.3f),
      Slab({0.7f, 0.2f, -0.4f}, {0.f, 1.f, 0.3f}, 0.5f, 0.58f, 0.25f),
      Slab({-0.2f, 0.5f, 0.8f}, {1.f, -0.3f, 0.f}, 0.4f, 0.62f, 0.3f),
  };
  const std::array<SoftEllipsoid, 3> blobs = {
      SoftEllipsoid({0.25f, -0.55f, -0.1f}, {0.08f, 0.06f, 0.14f}, 30.f),
      SoftEllipsoid({-0.45f, -0.35f, 0.35f}, {0.1f, 0.07f, 0.07f}, -20.f),
      SoftEllipsoid({0.05f, -0.6f, 0.4f}, {0.06f, 0.06f, 0.09f}, 0.f),
  };

  BuiltinScene scene;
  scene.volume =
      generateVolume("earth-mantle", grid, precision, ledger, -1.0, 1.0, [=](glm::vec3 p) {
        const float r = glm::length(p);
        if (r > kCrustOuter + 2.f * w) return 0.f;
        float v = mantleNoise(p);
        const glm::vec3 dir = r > 1e-6f ? p / r : glm::vec3(0.f, 0.f, 1.f);
        for (const Slab& s : slabs) v += (kSlabValue - v) * s.inside(dir, r, ws);
        for (const SoftEllipsoid& e : blobs) v += (kBlobValue - v) * softInside(e.distance(p), ws);
        v += (kCoreValue - v) * softInside(r - kCoreRadius, w);
        const float crustHalf = 0.5f * (kCrustOuter - kCrustInner);
        v += (kCrustValue - v) * softInside(std::abs(r - (kCrustOuter - crustHalf)) - crustHalf, w);
        // Empty space outside the crust is neutral.
        return v * softInside(r - kCrustOuter, w);
      });

  // Importance: the cold material, i.e. the union of the slabs and blobs with the same soft
  // edges, less where the core and the crust overwrite it (as in the volume above).
  scene.importance = generateImportance(grid, precision, ledger, [=](glm::vec3 p) {
    const float r = glm::length(p);
    if (r > kCrustInner + 0.02f + 2.f * w) return 0.f;
    const glm::vec3 dir = r > 1e-6f ? p / r : glm::vec3(0.f, 0.f, 1.f);
    float warm = 1.f;  // the fraction not covered by any cold body
    for (const Slab& s : slabs) warm *= 1.f - s.inside(dir, r, ws);
    for (const SoftEllipsoid& e : blobs) warm *= 1.f - softInside(e.distance(p), ws);
    const float crustHalf = 0.5f * (kCrustOuter - kCrustInner);
    const float core = softInside(r - kCoreRadius, w);
    const float crust = softInside(std::abs(r - (kCrustOuter - crustHalf)) - crustHalf, w);
    return (1.f - warm) * (1.f - core) * (1.f - crust);
  });

  TransferFunction& tf = scene.transferFunction;
  tf.name = "earth-mantle";
  tf.unitDistance = 2.f;  // mm
  tf.opacity = {{-1.0, 0.6f}, {-0.5, 0.45f}, {-0.3, 0.f},  {0.3, 0.f},
                {0.55, 0.5f}, {0.8, 0.7f},   {0.9, 0.95f}, {1.0, 0.97f}};
  tf.color = {{-1.0, {0.15f, 0.35f, 0.95f}}, {-0.45, {0.40f, 0.65f, 1.00f}},
              {0.0, {0.90f, 0.90f, 0.90f}},  {0.55, {1.00f, 0.55f, 0.15f}},
              {0.8, {0.95f, 0.30f, 0.10f}},  {0.9, {0.45f, 0.55f, 0.30f}},
              {1.0, {0.35f, 0.50f, 0.25f}}};
  tf.validate("scene earth-mantle");
  // With context surfaces: the crust becomes a surface, transparent in the volume.
  scene.contextSurfaces = {
      ContextSurfaceSpec{"iso:0.85:inside-high", true, 0.f, glm::vec3(0.40f, 0.55f, 0.32f), true}};
  scene.contextTransferFunction = tf;
  scene.contextTransferFunction.opacity = {{-1.0, 0.6f}, {-0.5, 0.45f}, {-0.3, 0.f}, {0.3, 0.f},
                                           {0.55, 0.5f}, {0.8, 0.7f},   {0.85, 0.f}, {1.0, 0.f}};
  scene.azimuthDeg = 20.f;
  scene.elevationDeg = 25.f;
  scene.distanceInRadii = 2.8f;
  // Cold: values below about -0.45 (normalised t < 0.275).
  scene.importanceCurve = {{0.f, 1.f}, {0.25f, 1.f}, {0.35f, 0.f}, {1.f, 0.f}};
  return scene;
}

}  // namespace visopt::scenes
