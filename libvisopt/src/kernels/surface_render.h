// What the ray marcher needs to draw context surfaces (Himmler & Günther 2026, Eq. 8, §III-E) and
// the comparison baselines (Fig. 10), grouped so the volume-only path carries one small struct.
#pragma once

#include <glm/glm.hpp>

#include "core/bit_mask_view.h"
#include "core/colormap_eval.h"
#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/surface_march.h"
#include "kernels/surface_set.h"
#include "kernels/surface_shading.h"

namespace visopt {

enum class RayMethod : int { Optimized = 0, MaxImportance = 1, CutAway = 2, Transparency = 3 };

struct SurfaceRenderParams {
  SurfaceSet surfaces;                   // visible surfaces, current phi
  FieldView bases[kMaxContextSurfaces];  // phi0 of the same surfaces (deviation view)
  glm::vec3 colors[kMaxContextSurfaces];
  bool deviationView = false;
  float deviationScale = 0.1f;  // 1 / (voxel size * deviationMaxVoxels)
  Colormap deviationColormap = Colormap::Viridis;
  float ks = 0.3f, shininess = 32.f;
  bool ambientOcclusion = true;
  float aoRadius = 6.f;   // world units
  float minStep = 0.25f;  // surface tracing's smallest step, world units
  // Baselines: the method, ghat (Eq. 19) and g on the volume grid.
  RayMethod method = RayMethod::Optimized;
  FieldView importanceBehind, importance;
  float cutThreshold = 0.3f;
  // Overlays (RenderSettings::importanceOverlay, worldMaskOverlay): the weight of the
  // importance tint (0 = off) and the world mask (invalid = no mask tint).
  float importanceOverlay = 0.f;
  BitMaskView worldMask;
};

// The overlays' tints of an albedo at index position idx: towards the importance highlight by
// g * importanceOverlay (volume samples only), then towards magenta by 40 % inside the world
// mask. With both overlays off the albedo is returned unchanged.
VISOPT_HD inline glm::vec3 overlayAlbedo(const SurfaceRenderParams& s, glm::vec3 idx,
                                         glm::vec3 albedo, bool volumeSample) {
  if (volumeSample && s.importanceOverlay > 0.f && s.importance.valid()) {
    const float g = fminf(fmaxf(s.importance.sample(idx), 0.f), 1.f);
    albedo += (g * s.importanceOverlay) * (glm::vec3(1.f, 0.45f, 0.05f) - albedo);
  }
  if (s.worldMask.valid() && s.worldMask.nearest(idx))
    albedo += 0.4f * (glm::vec3(1.f, 0.f, 1.f) - albedo);
  return albedo;
}

// Radiance leaving the surface point towards the eye (Eq. 8 without T_V): Blinn-Phong lit through
// T_L plus ambient light darkened by ambient occlusion. lightT: T_L at the point, looked up just
// outside the surface.
VISOPT_HD inline glm::vec3 surfaceRadiance(const SurfaceRenderParams& s, const GridMap& grid,
                                           int surface, glm::vec3 idx, glm::vec3 world, glm::vec3 n,
                                           glm::vec3 toLight, glm::vec3 toEye, float lightT,
                                           glm::vec3 lightRadiance, float ambient,
                                           float volumeOcclusion) {
  glm::vec3 color = s.colors[surface];
  if (s.deviationView && s.bases[surface].valid())
    color =
        colormapColor(s.deviationColormap, fabsf(s.bases[surface].sample(idx)) * s.deviationScale);
  color = overlayAlbedo(s, idx, color, false);
  const float brdf = NormalisedBlinnPhong(1.f, s.ks, s.shininess).cosWeighted(n, toLight, toEye);
  float ao = 1.f;
  if (s.ambientOcclusion)
    ao = sdfOcclusion(s.surfaces, grid, world, n, s.aoRadius) * volumeOcclusion;
  return color * (brdf * lightT * lightRadiance + glm::vec3(ambient * ao * 3.f));
}

}  // namespace visopt
