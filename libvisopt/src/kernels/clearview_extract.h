// ClearView's layer extraction (Krüger, Schneider, Westermann 2006, §3.1): per pixel, the first
// hit of the view ray with each context surface, the next one searched from where the one before
// it was hit ("the positions stored in the current texture are used as starting points for the
// ray-caster"), and the nearest hit of the focus surfaces (world position, outward normal from
// the central-difference gradient at the hit, depth along the ray); for each context hit the
// distance to the nearest focus surface along the context's inward normal (the distance-based
// measure, §3.2.2: the paper's extra pass from the position texture along the normal texture);
// and optionally the volume layer: the transfer function's matter in front of the first surface,
// composited front to back.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "core/min_max.h"
#include "kernels/ray_box.h"
#include "kernels/transfer_lookup.h"
#include "visopt/clearview.h"

namespace visopt {

// What counts as no hit: depths and distances are this large.
inline constexpr float kClearViewNoHit = 3.0e38f;

// One surface layer's source: inside where sign * (field - iso) >= 0 (sign +1 for an isosurface
// of a scalar inside-high, -1 for an SDF's zero set, inside negative).
// Isosurfaces may carry empty-space flags: blocks of kClearViewBlock^3 voxels where the field
// stays below the isovalue over the block and its 26 neighbours, so that every trilinear sample
// inside the block (which reads the block's voxels and the next ones) is outside.
inline constexpr int kClearViewBlock = 4;

struct ClearViewSurfaceField {
  FieldView field;
  float iso = 0.f;
  float sign = 1.f;
  const uint8_t* empty = nullptr;  // per block, x fastest; null: no skipping
  glm::ivec3 blocks{0};

  VISOPT_HD VISOPT_INLINE float inside(glm::vec3 idx) const {
    return sign * (field.sample(idx) - iso);
  }
  VISOPT_HD glm::ivec3 blockOf(glm::vec3 idx) const {
    return glm::ivec3(floorf(idx.x / float(kClearViewBlock)),
                      floorf(idx.y / float(kClearViewBlock)),
                      floorf(idx.z / float(kClearViewBlock)));
  }
  VISOPT_HD bool emptyAt(glm::vec3 idx) const {
    const glm::ivec3 b = glm::clamp(blockOf(idx), glm::ivec3(0), blocks - 1);
    return empty[(int64_t(b.z) * blocks.y + b.y) * blocks.x + b.x] != 0;
  }
  // Where the ray o + t d (index space) leaves the block that holds o + t d.
  VISOPT_HD float blockExit(glm::vec3 o, glm::vec3 d, float t) const {
    const glm::ivec3 b = blockOf(o + t * d);
    float exit = 3.0e38f;
    for (int a = 0; a < 3; ++a) {
      if (d[a] > 0.f) exit = minOf(exit, (float(kClearViewBlock * (b[a] + 1)) - o[a]) / d[a]);
      if (d[a] < 0.f) exit = minOf(exit, (float(kClearViewBlock * b[a]) - o[a]) / d[a]);
    }
    return exit;
  }
};

// One surface layer, structure of arrays, one entry per pixel (row 0 at the top).
struct ClearViewSurfaceOut {
  glm::vec3* position = nullptr;  // world units
  glm::vec3* normal = nullptr;    // outward, unit; zero where there is no hit
  float* depth = nullptr;         // ray parameter in world units; kClearViewNoHit: no hit
};

struct ClearViewExtractParams {
  FrustumMap camera;  // dims.x, dims.y = image size
  GridMap volume;
  ClearViewSurfaceField contexts[kClearViewMaxLayers], foci[kClearViewMaxLayers];
  int contextCount = 1, focusCount = 1;
  float step = 0.5f;              // world units
  float maxNormalDistance = 0.f;  // how far the distance measure looks, world units
  ClearViewSurfaceOut contextOut[kClearViewMaxLayers], focusOut;
  // Per context layer; kClearViewNoHit where no focus surface is found.
  float* normalDistance[kClearViewMaxLayers] = {};
  // The volume layer (optional): normalised scalars and the baked transfer table.
  bool volumeLayer = false;
  FieldView scalars;
  TransferLookup transfer;
  glm::vec4* volumeOut = nullptr;  // premultiplied rgb (the albedo as emission), alpha
};

// The first t in [t0, t1] where s.inside() >= 0, refined by bisection of the last step to well
// below a voxel (12 halvings); false when none. An isosurface is marched in steps of `step`,
// jumping over its empty blocks (the exit of an empty block is outside too, since the flags
// cover the neighbours); an SDF (sign < 0, values in world units) is sphere traced, in steps of
// 0.9 of its distance, at least a quarter of `step` (a shell thinner than a voxel is not
// stepped over; the renderer's surface march does the same, kernels/surface_march.h) and at
// most 8 steps.
VISOPT_HD inline bool clearViewFirstHit(const ClearViewSurfaceField& s, glm::vec3 o, glm::vec3 d,
                                        float t0, float t1, float step, float& tHit) {
  if (!(t1 >= t0)) return false;
  const bool sdf = s.sign < 0.f;
  const float minStep = sdf ? 0.25f * step : step;
  float lo = t0;  // the last position known to be outside
  float v = s.inside(o + t0 * d);
  if (v >= 0.f) {  // the ray enters the box inside the surface
    tHit = t0;
    return true;
  }
  for (int n = 0; n < (1 << 22) && lo < t1; ++n) {
    if (s.empty && s.emptyAt(o + lo * d)) {
      lo = minOf(maxOf(s.blockExit(o, d, lo), lo + 1e-3f * step), t1);
      continue;
    }
    const float advance = sdf ? minOf(maxOf(-0.9f * v, minStep), 8.f * step) : step;
    const float t = minOf(lo + advance, t1);
    v = s.inside(o + t * d);
    if (v >= 0.f) {
      float a = lo, b = t;  // inside(a) < 0 <= inside(b)
      for (int k = 0; k < 12; ++k) {
        const float mid = 0.5f * (a + b);
        if (s.inside(o + mid * d) >= 0.f)
          b = mid;
        else
          a = mid;
      }
      tHit = 0.5f * (a + b);
      return true;
    }
    lo = t;
  }
  return false;
}

// The outward unit normal at index position p: minus the sign-corrected gradient of the field
// by central differences (one voxel each side), taken to world space.
VISOPT_HD inline glm::vec3 clearViewNormal(const ClearViewSurfaceField& s, const GridMap& g,
                                           glm::vec3 p) {
  const FieldView& f = s.field;
  const glm::vec3 gi(
      f.sample(p + glm::vec3(1.f, 0.f, 0.f)) - f.sample(p - glm::vec3(1.f, 0.f, 0.f)),
      f.sample(p + glm::vec3(0.f, 1.f, 0.f)) - f.sample(p - glm::vec3(0.f, 1.f, 0.f)),
      f.sample(p + glm::vec3(0.f, 0.f, 1.f)) - f.sample(p - glm::vec3(0.f, 0.f, 1.f)));
  // d f / d world = direction * (d f / d index / spacing).
  const glm::vec3 gw = g.direction * (0.5f * gi / g.spacing);
  const float len = glm::length(gw);
  if (!(len > 0.f)) return glm::vec3(0.f);
  return (-s.sign / len) * gw;
}

struct ClearViewExtractKernel {
  ClearViewExtractParams p;

  // A hit on the first context surface counts 1 and a focus hit kFocusHit in the value a pixel
  // returns, so that one sum over the image gives both pixel counts (at most 16384^2 < 2^32
  // pixels); the deeper context layers are counted from their depths afterwards.
  static constexpr int64_t kFocusHit = int64_t(1) << 32;

  // One pixel; returns its hits as above.
  VISOPT_HD int64_t operator()(int64_t pixel) const {
    const int w = p.camera.dims.x, h = p.camera.dims.y;
    const int px = int(pixel % w), row = int(pixel / w);
    const int py = h - 1 - row;
    const glm::vec3 dirWorld = p.camera.rayDirection(float(px), float(py));
    const glm::vec3 o = p.volume.toIndex(p.camera.eye);
    const glm::vec3 d = p.volume.directionToIndex(dirWorld);
    const RayInterval box = intersectBox(o, d, glm::vec3(p.volume.dims - 1));
    const bool inBox = !box.empty();
    int64_t hits = 0;
    // The nearest focus hit: each further focus surface is searched only up to it.
    float tf = kClearViewNoHit;
    int nearest = -1;
    for (int k = 0; k < p.focusCount && inBox; ++k) {
      float t;
      if (clearViewFirstHit(p.foci[k], o, d, box.t0, minOf(box.t1, tf), p.step, t) && t < tf) {
        tf = t;
        nearest = k;
      }
    }
    if (nearest >= 0) {
      const glm::vec3 idx = o + tf * d;
      p.focusOut.position[pixel] = p.volume.toWorld(idx);
      glm::vec3 n = clearViewNormal(p.foci[nearest], p.volume, idx);
      if (n == glm::vec3(0.f)) n = -dirWorld;  // a flat field: face the viewer
      p.focusOut.normal[pixel] = n;
      hits += kFocusHit;
    } else {
      p.focusOut.position[pixel] = glm::vec3(0.f);
      p.focusOut.normal[pixel] = glm::vec3(0.f);
    }
    p.focusOut.depth[pixel] = tf;
    float start = box.t0, tFirst = kClearViewNoHit;
    for (int k = 0; k < p.contextCount; ++k) {
      const ClearViewSurfaceOut& out = p.contextOut[k];
      float tc = kClearViewNoHit;
      if (inBox && clearViewFirstHit(p.contexts[k], o, d, start, box.t1, p.step, tc)) {
        const glm::vec3 idx = o + tc * d;
        out.position[pixel] = p.volume.toWorld(idx);
        glm::vec3 n = clearViewNormal(p.contexts[k], p.volume, idx);
        if (n == glm::vec3(0.f)) n = -dirWorld;
        out.normal[pixel] = n;
        if (k == 0) {
          ++hits;
          tFirst = tc;
        }
        p.normalDistance[k][pixel] = distanceToFocus(idx, n);
        start = tc;  // the next context layer is searched from here
      } else {
        tc = kClearViewNoHit;
        out.position[pixel] = glm::vec3(0.f);
        out.normal[pixel] = glm::vec3(0.f);
        p.normalDistance[k][pixel] = kClearViewNoHit;
      }
      out.depth[pixel] = tc;
    }
    if (p.volumeLayer) p.volumeOut[pixel] = volumeInFront(o, d, box, minOf(tFirst, tf));
    return hits;
  }

  // §3.2.2: from a context hit (index position idx, outward world normal n) along the inward
  // normal to the nearest focus surface, as far as maxNormalDistance.
  VISOPT_HD float distanceToFocus(glm::vec3 idx, glm::vec3 n) const {
    float dist = kClearViewNoHit;
    if (!(p.maxNormalDistance > 0.f)) return dist;
    const glm::vec3 dn = p.volume.directionToIndex(-n);
    const RayInterval nbox = intersectBox(idx, dn, glm::vec3(p.volume.dims - 1));
    if (nbox.empty()) return dist;
    for (int k = 0; k < p.focusCount; ++k) {
      const float end = minOf(minOf(nbox.t1, p.maxNormalDistance), dist);
      float tn;
      if (clearViewFirstHit(p.foci[k], idx, dn, 0.f, end, p.step, tn) && tn < dist) dist = tn;
    }
    return dist;
  }

  // Emission-absorption of the transfer function's matter over [t0, min(tEnd, t1)]: each step
  // of length h adds T (1 - exp(-mu h)) albedo and multiplies T by exp(-mu h).
  VISOPT_HD glm::vec4 volumeInFront(glm::vec3 o, glm::vec3 d, RayInterval box, float tEnd) const {
    glm::vec3 c(0.f);
    float T = 1.f;
    if (box.empty()) return glm::vec4(0.f);
    const float end = minOf(box.t1, tEnd);
    for (float t = box.t0 + 0.5f * p.step; t < end && T > 1e-3f; t += p.step) {
      const float s = p.scalars.sample(o + t * d);
      const glm::vec4 ae = p.transfer.at(s);
      const float a = 1.f - expf(-ae.w * p.step);
      c += T * a * glm::vec3(ae);
      T *= 1.f - a;
    }
    return glm::vec4(c, 1.f - T);
  }
};

}  // namespace visopt
