// The volume part of the single-scattering renderer, Himmler & Günther 2026, Eqs. 6-9:
//   L(x0 <- w) = integral T_V(x) f_p(x, wL <-> w) mu_s(x) L_i(x) dx + T_V(x_s) L_background,
//   mu_s = mu_t * a (Eq. 3), L_i(x) = T_L(g_L(x)) L_e (Eq. 9).
// Each march segment of length h is integrated exactly for constant mu over the segment:
// its in-scattering weight is T_V * (1 - exp(-mu h)) (= integral of T_V mu over the segment),
// then T_V *= exp(-mu h). The phase function f_p blends Henyey-Greenstein with normalised
// Blinn-Phong about the scalar gradient (as Ament et al. 2017 combine them).
// Besides Eqs. 6-9 each sample scatters an unshadowed ambient light, darkened by the volume's
// ambient-occlusion field when there is one (R4; kernels/volume_occlusion.h).
// The surface term (Eq. 8) enters as the reduced surface radiance at the first hit of a context
// surface, found by sphere tracing before the volume march, which then stops there.
// Baselines of Fig. 10 (§IV-A): cut-away drops the surface where ghat > threshold; transparency
// modulation gives the first surface opacity 1 - ghat and blends it with what lies behind; both
// draw the volume as given (the Engine gives them the extinction optimised as in [9], with the
// surfaces held at phi0). Maximum importance projection shows the sample (volume or surface) of
// highest g.
//
// Performance notes (the arithmetic is the same as the straightforward formulation):
//  - value and central-difference gradient come from one 32-voxel neighbourhood
//    (kernels/ray_stencil.h) instead of seven trilinear samples;
//  - everything that is linear along the ray (world position, its offset from the light, the
//    light frustum's projection numerators) is set up once per ray: a T_L lookup costs one
//    square root and two divisions, and the surface bias towards the light (along the light's
//    own ray) only shortens the depth coordinate;
//  - exp and pow use short polynomials on the host (kernels/ray_fast_math.h);
//  - pixels are launched in 8x8 tiles in scanline order within a tile, so that neighbouring
//    rays (and, on the GPU, a warp's threads) share the voxels they fetch.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/ray_box.h"
#include "kernels/ray_fast_math.h"
#include "kernels/ray_skip.h"
#include "kernels/ray_stencil.h"
#include "kernels/shading.h"
#include "kernels/surface_render.h"
#include "kernels/transfer_lookup.h"
#include "kernels/volume_extinction.h"

namespace visopt {

// The fast host forms of kernels/shading.h's square root and power (kernels/ray_fast_math.h).
struct RayFastMath {
  int shininessInt = 0;  // see rayWholeExponent
  VISOPT_HD VISOPT_INLINE float rsqrt(float x) const { return rayRsqrt(x); }
  VISOPT_HD VISOPT_INLINE float pow(float x, float y) const {
    return rayPowUnit(x, y, shininessInt);
  }
};

// A small integer hash for per-pixel jitter (deterministic for a seed).
VISOPT_HD inline float hashToUnit(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return float(x >> 8) * (1.f / 16777216.f);
}

// Pixels are launched in tiles of kRayTile x kRayTile, row by row within a tile.
constexpr int kRayTile = 8;
// The least importance the maximum importance projection starts a ray at (below it the ray shows
// the base scene).
constexpr float kMipMinImportance = 0.05f;

// Launch items for a w x h image (whole tiles; items outside the image do nothing).
inline int64_t rayMarchItems(int w, int h) {
  const int64_t tilesX = (w + kRayTile - 1) / kRayTile, tilesY = (h + kRayTile - 1) / kRayTile;
  return tilesX * tilesY * kRayTile * kRayTile;
}

struct RayMarchParams {
  FrustumMap camera;  // dims.x, dims.y = image size
  GridMap volume;
  FieldView scalars;  // normalised scalars
  // The optimised mu as its change to mu_bar per voxel (kernels/volume_extinction.h);
  // invalid -> mu_bar from the transfer function alone.
  FieldView extinctionChange;
  TransferLookup transfer;
  FrustumMap light;
  FieldView lightTransmittance;  // T_L on the light frustum grid; invalid -> unshadowed
  glm::vec3 lightPosition{0.f};
  glm::vec3 lightRadiance{1.f};  // L_e times colour
  float step = 1.f;              // world units
  bool jitter = true;
  uint32_t seed = 1;
  float hg = 0.f, kd = 1.f, ks = 0.f, shininess = 1.f, surfaceGradient = 0.04f;
  float ambient = 0.f;
  // The ambient light's transmittance at each voxel (kernels/volume_occlusion.h, R4 of Himmler &
  // Günther 2026), trilinear at the samples; invalid -> unoccluded.
  FieldView volumeOcclusion;
  glm::vec3 background{0.f};
  float earlyStop = 1e-4f;
  glm::vec3* pixels = nullptr;  // row 0 at the top
  RaySkipGrid skip;             // empty blocks of the volume (kernels/ray_skip.h); optional
  SurfaceRenderParams surf;     // context surfaces and baselines (kernels/surface_render.h)
};

struct RayMarchKernel {
  RayMarchParams p;
  // Derived once on the host (see the constructor).
  glm::mat3 gradientToWorld{1.f};      // index-space gradient -> world direction
  bool lightAtFrustumEye = false;      // the light frustum's eye is the light (the fast T_L lookup)
  HenyeyGreenstein phaseFunction;      // kernels/shading.h, constants folded once
  NormalisedBlinnPhong brdf;           // the gradient-shading lobe
  RayFastMath fastMath;                // what both evaluate with
  float halfInvSurfaceGradient = 1.f;  // 0.5 / surfaceGradient
  float lightGridScaleX = 1.f, lightGridScaleY = 1.f, lightGridOffsetX = 0.f,
        lightGridOffsetY = 0.f;  // pixel coordinate = numerator / z * scale + offset
  float lightInvDs = 1.f, lightDepthOffset = 0.f;  // depth coordinate = s / ds - offset
  glm::vec3 lightSupport{0.f};                     // T_L grid dims - 0.5

  explicit RayMarchKernel(const RayMarchParams& params) : p(params) {
    const glm::vec3 invSpacing = 1.f / p.volume.spacing;
    gradientToWorld = p.volume.direction * glm::mat3(glm::vec3(invSpacing.x, 0.f, 0.f),
                                                     glm::vec3(0.f, invSpacing.y, 0.f),
                                                     glm::vec3(0.f, 0.f, invSpacing.z));
    lightAtFrustumEye = p.light.eye == p.lightPosition;
    phaseFunction = HenyeyGreenstein(p.hg);
    brdf = NormalisedBlinnPhong(p.kd, p.ks, p.shininess);
    fastMath.shininessInt = rayWholeExponent(p.shininess);
    halfInvSurfaceGradient = 0.5f / p.surfaceGradient;
    lightGridScaleX = 0.5f * float(p.light.dims.x) / p.light.tanX;
    lightGridScaleY = 0.5f * float(p.light.dims.y) / p.light.tanY;
    lightGridOffsetX = 0.5f * float(p.light.dims.x) - 0.5f;
    lightGridOffsetY = 0.5f * float(p.light.dims.y) - 0.5f;
    lightInvDs = 1.f / p.light.ds;
    lightSupport = glm::vec3(p.lightTransmittance.dims) - 0.5f;
    lightDepthOffset = p.light.sNear / p.light.ds + 0.5f;
  }

  VISOPT_HD VISOPT_INLINE float phaseHG(float cosTheta) const {
    return phaseFunction(cosTheta, fastMath);
  }

  // Per-ray linear forms for the light: with x(t) = eye + t dir the world position,
  // x - lightPosition = e + t dir, and the components of x - light.eye along the light
  // frustum's axes, A + t B (used when the frustum's eye is the light).
  struct LightRay {
    glm::vec3 e;                   // camera eye - light position
    float zA, zB, uA, uB, vA, vB;  // x - light.eye along forward, right * scaleX, up * scaleY
  };

  VISOPT_HD VISOPT_INLINE LightRay lightRay(glm::vec3 eye, glm::vec3 dir) const {
    LightRay r;
    r.e = eye - p.lightPosition;
    const glm::vec3 ef = eye - p.light.eye;
    r.zA = glm::dot(ef, p.light.forward);
    r.zB = glm::dot(dir, p.light.forward);
    r.uA = glm::dot(ef, p.light.right) * lightGridScaleX;
    r.uB = glm::dot(dir, p.light.right) * lightGridScaleX;
    r.vA = glm::dot(ef, p.light.up) * lightGridScaleY;
    r.vB = glm::dot(dir, p.light.up) * lightGridScaleY;
    return r;
  }

  // T_L at the sample at distance t along the ray, dist = |x - light.eye|. At surface-like
  // samples (bias = the Blinn-Phong weight) T_L is looked up up to one light-grid cell towards
  // the light: like a shadow map's depth bias, this keeps an opaque surface from shadowing
  // itself through the grid's discretisation (moiré rings where the light grid's cells cut the
  // surface). Homogeneous media (bias 0) keep the exact lookup. Moving x towards the light along
  // the light's own ray keeps its frustum pixel and shortens its distance by bias * ds.
  VISOPT_HD VISOPT_INLINE float lightTransmittanceAt(const LightRay& r, float t, float dist,
                                                     glm::vec3 x, glm::vec3 toLight,
                                                     float bias) const {
    if (!p.lightTransmittance.valid()) return 1.f;
    glm::vec3 y;
    if (lightAtFrustumEye) {
      const float z = r.zA + t * r.zB;
      const float s = dist - bias * p.light.ds;
      if (z <= 0.f || s <= 0.f) return 1.f;  // behind the light: outside the frustum
      const float invZ = rayRcp(z);
      y = glm::vec3((r.uA + t * r.uB) * invZ + lightGridOffsetX,
                    (r.vA + t * r.vB) * invZ + lightGridOffsetY, s * lightInvDs - lightDepthOffset);
    } else {
      y = p.light.toGrid(x + (bias * p.light.ds) * toLight);
    }
    // Outside the cell-centred grid's support [-0.5, dims - 0.5]: unshadowed.
    if (!(y.x >= -0.5f && y.y >= -0.5f && y.z >= -0.5f && y.x <= lightSupport.x &&
          y.y <= lightSupport.y && y.z <= lightSupport.z))
      return 1.f;
    return raySample(p.lightTransmittance, y);
  }

  // Marches the ray of pixel (px, row); T is the storage type of the scalars. Returns the
  // number of volume samples taken.
  template <class T>
  VISOPT_HD int64_t march(int px, int row, int64_t pixel) const {
    const int h = p.camera.dims.y;
    const int py = h - 1 - row;
    const glm::vec3 dir = p.camera.rayDirection(float(px), float(py));
    const glm::vec3 o = p.volume.toIndex(p.camera.eye);
    const glm::vec3 d = p.volume.directionToIndex(dir);  // index units per world unit
    const T* scalars = static_cast<const T*>(p.scalars.data);
    const glm::ivec3 dims = p.scalars.dims;

    const RayInterval box = intersectBox(o, d, glm::vec3(p.volume.dims - 1));
    float t0 = box.t0;
    float t1 = box.t1;
    glm::vec3 radiance(0.f);
    float transmittance = 1.f;
    int64_t samples = 0;
    const RayMethod method = p.surf.method;
    // Context surfaces: the first hit ends the volume march (except for transparency
    // modulation, which blends the surface and marches on).
    SurfaceHit hit;
    if (!p.surf.surfaces.empty() && t1 > t0) {
      hit = traceSurfaces(p.surf.surfaces, o, d, t0, t1, p.surf.minStep);
      if (hit.hit && method == RayMethod::CutAway) {
        // Cut away: a hit inside the cut region does not count; look for one beyond it.
        float from = hit.t;
        for (int tries = 0; tries < 8 && hit.hit &&
                            p.surf.importanceBehind.sample(o + hit.t * d) > p.surf.cutThreshold;
             ++tries) {
          // Leave the surface (and the cut region's interior) before tracing on.
          from = hit.t + p.surf.minStep;
          while (from < t1 && p.surf.surfaces.unionAt(o + from * d) <= 0.f) from += p.surf.minStep;
          hit = traceSurfaces(p.surf.surfaces, o, d, from, t1, p.surf.minStep);
        }
        if (hit.hit && p.surf.importanceBehind.sample(o + hit.t * d) > p.surf.cutThreshold)
          hit = SurfaceHit{};
      }
    }
    // Maximum importance projection (Viola et al. 2004, extended to surfaces): where the ray
    // meets a volume more important than its first surface hit, the ray starts at that volume
    // (the first sample whose g reaches half the ray's maximum, less one step) and everything in
    // front of it is cut away; the surfaces there too. Otherwise the ray is drawn as the base
    // scene. This method's T_L and volume AO see the volume only (computeLightTransmittance,
    // computeVolumeOcclusion): a context dropped for the eye would otherwise shadow what it shows.
    if (method == RayMethod::MaxImportance && t1 > t0) {
      const int count = int(ceilf((t1 - t0) / p.step));
      const float seg = (t1 - t0) / float(count);
      const float offset = p.jitter ? hashToUnit(uint32_t(pixel) * 9781u + p.seed * 6271u) : 0.5f;
      auto importanceAt = [&](int s) {
        return p.surf.importance.sample(o + (t0 + (float(s) + offset) * seg) * d);
      };
      float maxG = 0.f;
      int argMax = 0;
      for (int s = 0; s < count; ++s) {
        const float g = importanceAt(s);
        if (g > maxG) {
          maxG = g;
          argMax = s;
        }
      }
      const float surfaceG = hit.hit ? p.surf.importance.sample(o + hit.t * d) : 0.f;
      if (maxG > kMipMinImportance && maxG > surfaceG) {
        int first = 0;  // at most argMax, where g is the maximum
        while (first < argMax && importanceAt(first) < 0.5f * maxG) ++first;
        const float start = t0 + float(first > 0 ? first - 1 : 0) * seg;
        if (hit.hit && hit.t < start) {
          // Leave the cut surfaces' interior, then look for a surface beyond the start.
          float from = start;
          while (from < t1 && p.surf.surfaces.unionAt(o + from * d) <= 0.f) from += p.surf.minStep;
          hit = traceSurfaces(p.surf.surfaces, o, d, from, t1, p.surf.minStep);
        }
        t0 = start;
      }
    }
    glm::vec3 surfaceColour(0.f);
    float surfaceAlpha = 0.f;
    if (hit.hit) {
      const glm::vec3 hidx = o + hit.t * d;
      const glm::vec3 x = p.camera.eye + hit.t * dir;
      glm::vec3 n = surfaceNormal(p.surf.surfaces.phi[hit.surface], hidx, p.volume);
      if (glm::dot(n, dir) > 0.f) n = -n;  // the side facing the viewer
      const glm::vec3 toLight = glm::normalize(p.lightPosition - x);
      // T_L just outside the surface, along its normal (the field is 0 inside it).
      const float lightT = p.lightTransmittance.valid()
                               ? [&] {
                                   const glm::vec3 y = p.light.toGrid(x + p.light.ds * n);
                                   return (y.x >= -0.5f && y.y >= -0.5f && y.z >= -0.5f &&
                                           y.x <= lightSupport.x && y.y <= lightSupport.y &&
                                           y.z <= lightSupport.z)
                                              ? raySample(p.lightTransmittance, y)
                                              : 1.f;
                                 }()
                               : 1.f;
      // Volume ambient occlusion: transmittance through mu along the normal.
      float volumeOcclusion = 1.f;
      if (p.surf.ambientOcclusion) {
        float depth = 0.f;
        for (int i = 1; i <= 4; ++i) {
          const float dist = p.surf.aoRadius * float(i) / 4.f;
          const glm::vec3 q = p.volume.toIndex(x + dist * n);
          const glm::vec3 hi = glm::vec3(p.volume.dims - 1);
          if (q.x < 0.f || q.y < 0.f || q.z < 0.f || q.x > hi.x || q.y > hi.y || q.z > hi.z) break;
          const float base = p.transfer.extinction(p.transfer.locate(raySample(p.scalars, q)));
          const float mu = p.extinctionChange.valid()
                               ? extinctionWithChange(base, raySample(p.extinctionChange, q))
                               : base;
          depth += mu * 0.25f * p.surf.aoRadius;
        }
        volumeOcclusion = expf(-depth);
      }
      surfaceColour = surfaceRadiance(p.surf, p.volume, hit.surface, hidx, x, n, toLight, -dir,
                                      lightT, p.lightRadiance, p.ambient, volumeOcclusion);
      surfaceAlpha = 1.f;
      if (method == RayMethod::Transparency)
        surfaceAlpha = 1.f - fminf(fmaxf(p.surf.importanceBehind.sample(hidx), 0.f), 1.f);
      else
        t1 = hit.t;
    }
    if (t1 > t0) {
      const int count = int(ceilf((t1 - t0) / p.step));
      const float seg = (t1 - t0) / float(count);
      const float offset = p.jitter ? hashToUnit(uint32_t(pixel) * 9781u + p.seed * 6271u) : 0.5f;
      const glm::vec3 toEye = -dir;
      const bool shade = p.kd > 0.f || p.ks > 0.f;
      const LightRay lr = lightRay(p.camera.eye, dir);
      const glm::vec3 ambient(p.ambient);
      // For leaving an empty block: per axis the face ahead (upper for d > 0) and 1 / d.
      glm::vec3 invD(0.f);
      glm::ivec3 ahead(0);
      for (int a = 0; a < 3; ++a) {
        const bool moves = d[a] > 1e-20f || d[a] < -1e-20f;
        invD[a] = moves ? 1.f / d[a] : 0.f;
        ahead[a] = d[a] > 0.f ? 1 : 0;
      }
      for (int s = 0; s < count && transmittance > p.earlyStop; ++s) {
        const float t = t0 + (float(s) + offset) * seg;
        const glm::vec3 idx = o + t * d;
        if (p.skip.valid()) {
          const glm::ivec3 b = glm::ivec3(glm::max(idx, glm::vec3(0.f))) / kRaySkipBlock;
          const glm::ivec3 bc = glm::min(b, p.skip.dims - 1);
          if (p.skip.empty[(int64_t(bc.z) * p.skip.dims.y + bc.y) * p.skip.dims.x + bc.x]) {
            // Jump to the first sample at or past the block's exit face.
            float tExit = 3.0e38f;
            for (int a = 0; a < 3; ++a) {
              if (invD[a] == 0.f) continue;
              const float face = float((bc[a] + ahead[a]) * kRaySkipBlock);
              const float ta = (face - o[a]) * invD[a];
              tExit = ta < tExit ? ta : tExit;
            }
            const float next = ceilf((tExit - t0) / seg - offset);
            s = next > float(s + 1) ? (next < float(count) ? int(next) : count) - 1 : s;
            continue;
          }
        }
        ++samples;
        RayVoxels<T> voxels(scalars, dims, idx);
        const float value = voxels.value();
        const TransferLookup::Entry entry = p.transfer.locate(value);
        float mu = p.transfer.extinction(entry);
        if (p.extinctionChange.valid())
          mu = extinctionWithChange(mu, raySample(p.extinctionChange, idx));
        const float opticalDepth = mu * seg;
        if (opticalDepth < kRayMinOpticalDepth) continue;
        const float alpha = raySegmentAlpha(opticalDepth);
        const glm::vec3 albedo = overlayAlbedo(p.surf, idx, p.transfer.albedo(entry), true);

        // Direction and distance to the light from x = eye + t dir.
        const glm::vec3 fromLight = lr.e + t * dir;
        const float dist2 = glm::dot(fromLight, fromLight);
        const float invDist = rayRsqrt(dist2);
        const float dist = dist2 * invDist;
        const glm::vec3 toLight = fromLight * -invDist;

        // Phase function: HG blended with Blinn-Phong about the gradient.
        float phase = phaseHG(glm::dot(toLight, dir));
        float surfaceWeight = 0.f;
        // Gradient shading only where the sample can still be seen: below that its effect on
        // the pixel is under 1e-4 of the light's radiance.
        if (shade && transmittance * alpha > 1e-4f) {
          const glm::vec3 g2 = voxels.gradient2();  // twice the per-voxel gradient
          const float g2Length2 = glm::dot(g2, g2);
          // weight = |g| / surfaceGradient, capped at 1 (|g| = |g2| / 2 per voxel).
          const float ratio = g2Length2 * rayRsqrt(g2Length2) * halfInvSurfaceGradient;
          const float weight = g2Length2 > 0.f ? (ratio < 1.f ? ratio : 1.f) : 0.f;
          surfaceWeight = weight;
          if (weight > 0.f) {
            const glm::vec3 gw = gradientToWorld * g2;
            glm::vec3 n = gw * rayRsqrt(glm::dot(gw, gw));
            if (glm::dot(n, toEye) < 0.f) n = -n;  // two-sided
            const float bp = brdf.cosWeighted(n, toLight, toEye, fastMath);
            phase = (1.f - weight) * phase + weight * bp;
          }
        }
        const float lightT =
            lightTransmittanceAt(lr, t, dist, p.camera.eye + t * dir, toLight, surfaceWeight);
        const glm::vec3 occludedAmbient =
            p.volumeOcclusion.valid() ? ambient * raySample(p.volumeOcclusion, idx) : ambient;
        const glm::vec3 scattered = albedo * (phase * lightT * p.lightRadiance + occludedAmbient);
        // Transparency modulation: the surface sits at hit.t; blend it in when passing it.
        if (surfaceAlpha > 0.f && method == RayMethod::Transparency && t > hit.t) {
          radiance += transmittance * surfaceAlpha * surfaceColour;
          transmittance *= 1.f - surfaceAlpha;
          surfaceAlpha = 0.f;
        }
        radiance += transmittance * alpha * scattered;
        transmittance *= 1.f - alpha;
      }
    }
    if (surfaceAlpha > 0.f) {  // the surface ends the ray (or was not passed by a sample)
      radiance += transmittance * surfaceAlpha * surfaceColour;
      transmittance *= 1.f - surfaceAlpha;
    }
    radiance += transmittance * p.background;
    p.pixels[pixel] = radiance;
    return samples;
  }

  // Launch item -> pixel (see rayMarchItems); returns the number of volume samples taken.
  VISOPT_HD int64_t operator()(int64_t item) const {
    const int w = p.camera.dims.x, h = p.camera.dims.y;
    const int tilesX = (w + kRayTile - 1) / kRayTile;
    const int64_t tile = item / (kRayTile * kRayTile);
    const int local = int(item % (kRayTile * kRayTile));
    const int px = int(tile % tilesX) * kRayTile + local % kRayTile;
    const int row = int(tile / tilesX) * kRayTile + local / kRayTile;
    if (px >= w || row >= h) return 0;
    const int64_t pixel = int64_t(row) * w + px;
    return p.scalars.half ? march<Half>(px, row, pixel) : march<float>(px, row, pixel);
  }
};

}  // namespace visopt
