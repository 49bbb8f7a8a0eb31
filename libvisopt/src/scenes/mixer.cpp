// A stirred tank like the paper's ROTATING MIXER: a cylindrical tank (wall and bottom), a central
// rod with a paddle, and vortex tubes in the fluid (a double helix trailing from the paddle tips
// and two ring vortices) carrying a vorticity-magnitude-like value in [0, 1]. Solids carry the
// marker value -1, below empty space (0) and quiet fluid (~0.05), so no solid/fluid transition
// passes through the vortex range, which the importance marks.
#include <array>
#include <cmath>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"

namespace visopt::scenes {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kTankInner = 0.82f, kWall = 0.05f, kTankBottom = -0.9f, kTankTop = 0.85f;
constexpr float kFluidTop = 0.75f;
constexpr float kRodRadius = 0.05f, kRodBottom = -0.6f;
constexpr float kSolidValue = -1.f;

float maxOf(float a, float b) {
  return a > b ? a : b;
}
float minOf(float a, float b) {
  return a < b ? a : b;
}

// Signed distance to the tank (side wall open at the top, closed bottom), rod and paddle.
float solidDistance(glm::vec3 p, float rho) {
  const float wallMid = kTankInner + 0.5f * kWall;
  const float side =
      maxOf(std::abs(rho - wallMid) - 0.5f * kWall, maxOf(p.z - kTankTop, kTankBottom - p.z));
  const float bottom = maxOf(rho - (kTankInner + kWall),
                             std::abs(p.z - (kTankBottom + 0.5f * kWall)) - 0.5f * kWall);
  const float rod = maxOf(rho - kRodRadius, kRodBottom - p.z);
  // Paddle: a flat blade across the rod's foot, turned 30 degrees about z.
  const float c = std::cos(kPi / 6.f), s = std::sin(kPi / 6.f);
  const float u = c * p.x + s * p.y, v = -s * p.x + c * p.y;
  const float paddle =
      maxOf(maxOf(std::abs(u) - 0.45f, std::abs(v) - 0.025f), std::abs(p.z - kRodBottom) - 0.06f);
  return minOf(minOf(side, bottom), minOf(rod, paddle));
}

struct Ring {
  float radius, z, core, strength;
};

// The vortex tubes: a double helix trailing from the paddle tips and two ring vortices, each a
// centre line with a Gaussian core.
struct VortexTubes {
  std::array<Ring, 2> rings = {Ring{0.68f, -0.68f, 0.07f, 0.8f}, Ring{0.35f, 0.45f, 0.06f, 0.7f}};
  // Double helix: radius, pitch, core radius, strength, z range (faded out at both ends).
  float helixR = 0.45f, pitch = 0.5f, helixCore = 0.06f, helixStrength = 0.95f;
  float helixLo = -0.5f, helixHi = 0.35f;
  float cosLead = std::cos(std::atan(pitch / (2.f * kPi * helixR)));

  // Calls f(squared distance to the centre line, core radius, peak strength, fade) per tube; the
  // vorticity is strength * fade * exp(-d^2 / core^2), fade in [0, 1] ending the helix.
  template <class F>
  void visit(glm::vec3 p, float rho, F f) const {
    const float theta = std::atan2(p.y, p.x);
    const float fade = softInside(maxOf(helixLo - p.z, p.z - helixHi), 0.08f);
    for (int arm = 0; arm < 2; ++arm) {
      float dz = p.z - helixLo - pitch * (theta / (2.f * kPi) + 0.5f * float(arm));
      dz -= pitch * std::round(dz / pitch);
      f((rho - helixR) * (rho - helixR) + dz * cosLead * dz * cosLead, helixCore, helixStrength,
        fade);
    }
    for (const Ring& ring : rings)
      f((rho - ring.radius) * (rho - ring.radius) + (p.z - ring.z) * (p.z - ring.z), ring.core,
        ring.strength, 1.f);
  }
};

// Inside the tank up to the free surface, soft edge w.
float fluidInside(glm::vec3 p, float rho, float w) {
  return softInside(maxOf(rho - kTankInner, maxOf(p.z - kFluidTop, kTankBottom + kWall - p.z)), w);
}

}  // namespace

BuiltinScene makeMixer(int resolution, Precision precision, MemoryLedger* ledger) {
  checkResolution("mixer", resolution);
  const GridSpec grid = sceneGrid(resolution);
  const float w = edgeHalfWidth(grid);
  const VortexTubes tubes;

  BuiltinScene scene;
  scene.volume = generateVolume("mixer", grid, precision, ledger, -1.0, 1.0, [=](glm::vec3 p) {
    const float rho = std::sqrt(p.x * p.x + p.y * p.y);
    // Quiet fluid with a little swirl, inside the tank up to the free surface.
    float vort = 0.05f + 0.03f * std::sin(6.f * p.z + 3.f * rho);
    tubes.visit(p, rho, [&](float d2, float core, float strength, float fade) {
      vort = maxOf(vort, strength * fade * std::exp(-d2 / (core * core)));
    });
    const float v = fluidInside(p, rho, w) * vort;
    return v + (kSolidValue - v) * softInside(solidDistance(p, rho), w);
  });
  // Importance: the vortex tubes, each the soft solid cylinder (torus) of its core radius around
  // its centre line (where the vorticity is above about a third of its peak), ending where
  // the helix fades, and only in the fluid, not where a solid cuts them.
  scene.importance = generateImportance(grid, precision, ledger, [=](glm::vec3 p) {
    const float rho = std::sqrt(p.x * p.x + p.y * p.y);
    float g = 0.f;
    tubes.visit(p, rho, [&](float d2, float core, float /*strength*/, float fade) {
      g = maxOf(g, fade * softInside(std::sqrt(d2) - core, w));
    });
    return g * fluidInside(p, rho, w) * (1.f - softInside(solidDistance(p, rho), w));
  });

  TransferFunction& tf = scene.transferFunction;
  tf.name = "mixer";
  tf.unitDistance = 2.f;  // mm
  tf.opacity = {{-1.0, 0.97f}, {-0.75, 0.9f}, {-0.5, 0.f}, {0.15, 0.f},
                {0.3, 0.08f},  {0.6, 0.4f},   {1.0, 0.6f}};
  tf.color = {{-1.0, {0.62f, 0.66f, 0.72f}},
              {-0.5, {0.62f, 0.66f, 0.72f}},
              {0.2, {0.95f, 0.85f, 0.30f}},
              {0.6, {0.95f, 0.45f, 0.15f}},
              {1.0, {0.80f, 0.10f, 0.10f}}};
  tf.validate("scene mixer");
  // With context surfaces: the tank wall, rod and paddle become a surface.
  scene.contextSurfaces = {
      ContextSurfaceSpec{"iso:-0.5:inside-low", true, 0.f, glm::vec3(0.62f, 0.66f, 0.72f), true}};
  scene.contextTransferFunction = tf;
  scene.contextTransferFunction.opacity = {
      {-1.0, 0.f}, {0.15, 0.f}, {0.3, 0.08f}, {0.6, 0.4f}, {1.0, 0.6f}};
  scene.azimuthDeg = 30.f;
  scene.elevationDeg = 20.f;
  scene.distanceInRadii = 2.8f;
  // Vortex tubes: vorticity above about 0.3 (normalised t > 0.65).
  scene.importanceCurve = {{0.f, 0.f}, {0.62f, 0.f}, {0.7f, 1.f}, {1.f, 1.f}};
  return scene;
}

}  // namespace visopt::scenes
