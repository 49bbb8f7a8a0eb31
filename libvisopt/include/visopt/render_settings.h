// How an image is rendered: single scattering of one point light (Himmler & Günther 2026, Eqs.
// 6-9).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "visopt/colormap.h"

namespace visopt {

// The comparison baselines of Himmler & Günther 2026, Fig. 10, and ours.
enum class RenderMethod {
  Optimized,                // ours: the optimised extinction and surfaces
  MaxImportanceProjection,  // rays start at their most important volume, cutting what is in front
  CutAway,                  // surfaces and volume removed where ghat exceeds a threshold
  TransparencyModulation,   // surfaces and volume made transparent in proportion to ghat
};
const char* toString(RenderMethod method);

// The ray-march steps a render accepts, in units of the smallest voxel spacing: finer than 1/20
// of a voxel changes no pixel visibly and multiplies the time (a step of 1e-6 ran for hours);
// coarser than 16 voxels skips whole structures.
inline constexpr float kMinStepFactor = 0.05f;
inline constexpr float kMaxStepFactor = 16.f;

struct RenderSettings {
  RenderMethod method = RenderMethod::Optimized;
  float cutAwayThreshold = 0.3f;  // ghat above this is cut away
  int width = 512, height = 512;
  // Ray-marching step, in units of the smallest voxel spacing. Each pixel's samples are
  // stratified with a per-pixel random offset (jitter) against wood-grain artefacts.
  float stepFactor = 0.5f;  // kMinStepFactor..kMaxStepFactor
  bool jitter = true;
  uint32_t seed = 1;
  // Preview: render at 1/previewFactor of the size with twice the step, then upscale.
  bool preview = false;
  int previewFactor = 4;

  // Phase function: a blend of Henyey-Greenstein (anisotropy hgAnisotropy) and normalised
  // Blinn-Phong about the scalar gradient; the blend weight grows with the gradient magnitude
  // (per voxel, in normalised units) up to `surfaceGradient` where shading is all Blinn-Phong.
  float hgAnisotropy = 0.1f;
  float diffuse = 0.9f, specular = 0.25f, shininess = 40.f;
  float surfaceGradient = 0.04f;
  // Unshadowed ambient light in-scattered isotropically; 0 for pure single scattering.
  float ambient = 0.12f;
  glm::vec3 background{0.06f, 0.065f, 0.075f};
  float exposure = 1.f;

  // Light-space frustum grid for T_L (Himmler & Günther 2026, Eq. 5): rays per side, depth cells (0
  // = one per voxel along the volume's diagonal).
  int lightGridSize = 192;  // kMinLightGridSize..kMaxLightGridSize
  int lightGridDepth = 0;   // 0..kMaxLightGridDepth
  // Stop marching once the view transmittance drops below this.
  float earlyStop = 1e-4f;

  // Context surfaces (Himmler & Günther 2026, Eq. 8 and §III-E): shaded with normalised
  // Blinn-Phong, shadowed through T_L, darkened by ambient occlusion from the volume and the SDF.
  // Ambient occlusion (R4, Fig. 6) also darkens the ambient light of the volume's samples: the
  // mean transmittance of six axis rays of ambientOcclusionRadius from each voxel.
  float surfaceSpecular = 0.3f, surfaceShininess = 32.f;
  bool ambientOcclusion = true;
  float ambientOcclusionRadius = 6.f;  // in voxels
  // Deviation view (Fig. 5): colour the surfaces by |phi0| at the hit, in voxels, through
  // deviationColormap over [0, deviationMaxVoxels].
  bool deviationView = false;
  float deviationMaxVoxels = 10.f;
  Colormap deviationColormap = Colormap::Viridis;

  // Workstation overlays, off by default (and then without any effect on the image).
  // importanceOverlay in [0, 1]: each volume sample's albedo is blended towards a highlight
  // colour by g(x) * importanceOverlay (needs an importance). worldMaskOverlay: volume samples
  // and surface points in a voxel of the world mask are tinted magenta (40 %).
  float importanceOverlay = 0.f;
  bool worldMaskOverlay = false;
};

inline constexpr int kMinLightGridSize = 16, kMaxLightGridSize = 1024, kMaxLightGridDepth = 4096;

// Throws Error(Usage) naming the setting unless every value is in the range stated next to it
// (finite, non-negative weights; the step, the image and light-grid sizes in their ranges).
// Engine::render checks before it allocates anything.
void checkRenderSettings(const RenderSettings& settings);

struct RenderStats {
  double milliseconds = 0.0;
  double lightMilliseconds = 0.0;  // T_L update, when it ran
  // The volume's ambient occlusion field, when it was recomputed (Engine::render; it is kept
  // while the extinction, the surfaces and the settings it reads stay the same).
  double occlusionMilliseconds = 0.0;
  int64_t samples = 0;        // volume samples taken
  int width = 0, height = 0;  // actual rendered resolution (smaller in preview)
};

}  // namespace visopt
