// Shading of the context surfaces (paper 000 Eq. 8 and §III-E): the reduced surface radiance
//   L_r = T_V f_r (n . wL)+ L_i,  L_i = T_L L_e  (Eq. 9),
// with a normalised Blinn-Phong BRDF f_r, ambient occlusion from the SDF and from the volume. The
// deviation view's colormaps live in core/colormap_eval.h.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/surface_set.h"

namespace visopt {

// Normalised Blinn-Phong BRDF times the cosine: kd/pi + ks (n+8)/(8 pi) cos^n(h) — Eq. 8's
// f_r (n . wL)+ for albedo kd.
VISOPT_HD inline float surfaceBrdfCos(glm::vec3 n, glm::vec3 toLight, glm::vec3 toEye, float kd,
                                      float ks, float shininess) {
  const float cosL = glm::dot(n, toLight);
  if (cosL <= 0.f) return 0.f;
  const glm::vec3 h = glm::normalize(toLight + toEye);
  const float cosH = fmaxf(glm::dot(n, h), 0.f);
  return (kd / 3.14159265f + ks * (shininess + 8.f) / (8.f * 3.14159265f) * powf(cosH, shininess)) *
         cosL;
}

// Outward unit normal of surface s at index position p: grad phi by central differences over
// +-1.5 voxels in world units. The wider stencil smooths the voxel-scale ripples a redistanced
// SDF keeps, which Blinn-Phong highlights would otherwise show as rings.
VISOPT_HD inline glm::vec3 surfaceNormal(const FieldView& phi, glm::vec3 p, const GridMap& grid) {
  const float o = 1.5f;
  glm::vec3 g(
      (phi.sample(p + glm::vec3(o, 0, 0)) - phi.sample(p - glm::vec3(o, 0, 0))) / grid.spacing.x,
      (phi.sample(p + glm::vec3(0, o, 0)) - phi.sample(p - glm::vec3(0, o, 0))) / grid.spacing.y,
      (phi.sample(p + glm::vec3(0, 0, o)) - phi.sample(p - glm::vec3(0, 0, o))) / grid.spacing.z);
  g = grid.direction * g;
  const float len = glm::length(g);
  return len > 1e-12f ? g / len : glm::vec3(0.f, 0.f, 1.f);
}

// SDF ambient occlusion (Evans 2006 style): at distances d_i along the normal an unoccluded
// point has phi = d_i; the shortfall, halved per step, darkens. `union` is the SDF of all
// surfaces; distances in world units.
VISOPT_HD inline float sdfOcclusion(const SurfaceSet& surfaces, const GridMap& grid,
                                    glm::vec3 world, glm::vec3 n, float radius) {
  float occlusion = 0.f, weight = 0.5f;
  for (int i = 1; i <= 4; ++i) {
    const float d = radius * float(i) / 4.f;
    const float phi = surfaces.unionAt(grid.toIndex(world + d * n));
    occlusion += weight * fmaxf(d - phi, 0.f) / d;
    weight *= 0.5f;
  }
  return fminf(fmaxf(1.f - occlusion, 0.f), 1.f);
}

}  // namespace visopt
