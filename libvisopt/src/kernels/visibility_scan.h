// Grid updates of the extinction optimisation (Himmler & Günther 2026, Eqs. 10-13; docs/methods.md
// §1) along the rays of a view- or light-space frustum grid.
//
// The discrete energy (the ground truth the gradient is checked against) is
//   E = rho/2 sum_v (mu_v - mubar_v)^2 dV  -  q sum_c g_c mu_c T_c dV_c  -  r (same on the light
//   grid)
// over object voxels v and frustum cells c, with mu_c, g_c trilinear samples at the cell centres
// (zero outside the volume's cells), exclusive transmittance T_c = exp(-sum_{j<k} mu_j ds) along
// the cell's ray, and the cell volume dV_c = Omega_ij s_k^2 ds (Omega_ij: the pixel's solid angle).
//
// dE/dmu at a cell, per unit volume, is -q d_c with
//   d_c = g_c T_c - G_c,   G_c = (1 / s_k^2) sum_{j>k} g_j mu_j T_j s_j^2 ds,
// where the s_j^2 / s_k^2 factor is the ray bundle's spread (cells are equal-solid-angle, not
// equal-volume). One front-to-back pass gives T; one back-to-front pass gives G and d. The pass
// re-samples mu and g rather than buffering the ray, so it needs no per-ray scratch memory on
// either backend. Each ray also returns its contributions to the energy and to the
// importance-weighted visibility V = sum g mu T dV / sum g mu dV.
//
// Context surfaces (Himmler & Günther 2026, §III) are opaque: from the first cell inside their
// union (phi < 0) on, T = 0, so the volume behind a surface is neither seen nor lit and gets no
// derivative. View rays may carry screen-space weights (lens, windowing masks: Fig. 8) that
// multiply g. When `behindMax` is given, the backward pass also stores the running maximum of g
// strictly behind each cell — half of ghat in Eq. 19.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/field_view.h"
#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/scan_skip.h"
#include "kernels/screen_weights.h"
#include "kernels/surface_set.h"

namespace visopt {

struct ScanSums {
  double gMuT = 0.0;  // sum g mu T dV  (the visibility integral; energy term = -weight * this)
  double gMu = 0.0;   // sum g mu dV
  // How much the occluders (unimportant matter and context surfaces), not the important
  // structure itself, hide it: V_occ = importantSeen / importantSeenAlone, with
  //   importantSeen      = sum (g mu) T dV        over cells not behind a surface,
  //   importantSeenAlone = sum (g mu) T_imp dV    over all cells,
  // T_imp = exp(-integral (g mu)) the transmittance through important matter alone. V_occ = 1
  // when nothing unimportant is in the way, whatever the structure hides of itself (the back of
  // a skull behind its front weighs ~0 in both sums). (g mu) is the trilinear interpolation of
  // the per-voxel products g_v mu_v, so a cell between a bone voxel and a soft-tissue voxel does
  // not count the bone's extinction as unimportant: interpolating g and mu separately made the
  // partial-volume rim of every important structure an occluder (T_occ ~ 0.6 through one rim of
  // a 64^3 skull).
  double importantSeen = 0.0;
  double importantSeenAlone = 0.0;
  VISOPT_HD ScanSums operator+(const ScanSums& o) const {
    return {gMuT + o.gMuT, gMu + o.gMu, importantSeen + o.importantSeen,
            importantSeenAlone + o.importantSeenAlone};
  }
  double visibilityThroughOccluders() const {
    return importantSeenAlone > 0.0 ? importantSeen / importantSeenAlone : 0.0;
  }
};

struct VisibilityScan {
  FrustumMap frustum;
  GridMap volume;
  FieldView mu;                // extinction on the object grid
  FieldView importance;        // g on the object grid
  FrustumFieldView out;        // d on the frustum grid; T is kept there between the two passes
  SurfaceSet surfaces;         // opaque context surfaces on the object grid (may be empty)
  ScreenWeights weights;       // view rays only
  FrustumFieldView behindMax;  // optional: max of g behind each cell, on the frustum grid
  ScanSkipGrid skip;           // optional: empty space for the fast scans (this one ignores it)

  // Pixel solid angle (for cell volumes): the tan-plane area over (1 + u^2 + v^2)^(3/2).
  VISOPT_HD float solidAngle(int i, int j) const {
    const float du = 2.f * frustum.tanX / float(frustum.dims.x);
    const float dv = 2.f * frustum.tanY / float(frustum.dims.y);
    const float u = (float(i) + 0.5f) * du - frustum.tanX;
    const float v = (float(j) + 0.5f) * dv - frustum.tanY;
    const float r2 = 1.f + u * u + v * v;
    return du * dv / (r2 * sqrtf(r2));
  }

  // Trilinear interpolation of the per-voxel product g_v mu_v at p (index space).
  VISOPT_HD VISOPT_INLINE float importantExtinction(glm::vec3 p) const {
    const glm::ivec3 dims = mu.dims;
    p = glm::clamp(p, glm::vec3(0.f), glm::vec3(dims - 1));
    const glm::ivec3 i0 = glm::ivec3(p);
    const glm::ivec3 i1 = glm::min(i0 + 1, dims - 1);
    const glm::vec3 f = p - glm::vec3(i0);
    float acc = 0.f;
    for (int c = 0; c < 8; ++c) {
      const int x = (c & 1) ? i1.x : i0.x, y = (c & 2) ? i1.y : i0.y, z = (c & 4) ? i1.z : i0.z;
      const float w =
          ((c & 1) ? f.x : 1.f - f.x) * ((c & 2) ? f.y : 1.f - f.y) * ((c & 4) ? f.z : 1.f - f.z);
      acc += w * mu.at(x, y, z) * importance.at(x, y, z);
    }
    return acc;
  }

  // mu and g at the cell centre o + s d (o, d: the ray in index space, s: depth); zero outside
  // the volume's cells. opaque: the cell centre lies inside a context surface.
  VISOPT_HD VISOPT_INLINE bool sampleAt(glm::vec3 o, glm::vec3 d, float depth, float& m, float& g,
                                        bool& opaque) const {
    const glm::vec3 idx = o + depth * d;
    // The volume occupies its voxels' cells, [-0.5, dims - 0.5] in index space (sampling clamps
    // beyond the outer voxel centres), so every voxel, boundary voxels included, is covered by
    // frustum cells in proportion to its volume, as the gather in extinction_step.h assumes.
    const glm::vec3 lo(-0.5f), hi = glm::vec3(volume.dims) - 0.5f;
    if (idx.x < lo.x || idx.y < lo.y || idx.z < lo.z || idx.x > hi.x || idx.y > hi.y ||
        idx.z > hi.z) {
      m = g = 0.f;
      opaque = false;
      return false;
    }
    m = mu.sample(idx);
    g = importance.sample(idx);
    opaque = !surfaces.empty() && surfaces.unionAt(idx) < 0.f;
    return true;
  }

  VISOPT_HD ScanSums operator()(int64_t ray) const {
    const int i = int(ray % frustum.dims.x), j = int(ray / frustum.dims.x);
    const int nz = frustum.dims.z;
    const float ds = frustum.ds;
    // The ray in index space, computed once: cell k's centre is o + depth(k) d.
    const glm::vec3 o = volume.toIndex(frustum.eye);
    const glm::vec3 d = volume.directionToIndex(frustum.rayDirection(float(i), float(j)));
    const float w = weights.active() ? weights.at(i, j, frustum.dims.x, frustum.dims.y) : 1.f;
    // Front to back: exclusive transmittance; a surface blocks everything from its first cell.
    const float omega = solidAngle(i, j);
    ScanSums sums;
    float opticalDepth = 0.f, importantDepth = 0.f;
    bool blocked = false;
    for (int k = 0; k < nz; ++k) {
      float m, g;
      bool opaque;
      const float depth = frustum.depthOf(float(k));
      const bool in = sampleAt(o, d, depth, m, g, opaque);
      blocked = blocked || opaque;
      const float t = blocked ? 0.f : expf(-opticalDepth);
      out.store(out.index(i, j, k), t);
      opticalDepth += m * ds;
      if (in && g > 0.f) {
        // The statistic V_occ (ScanSums): screen weights scale importance as in the energy.
        const float gm = fminf(w, 1.f / fmaxf(g, 1e-30f)) * importantExtinction(o + depth * d);
        const double dV = double(omega) * double(depth) * double(depth) * double(ds);
        sums.importantSeen += double(gm * t) * dV;
        sums.importantSeenAlone += double(gm * expf(-importantDepth)) * dV;
        importantDepth += gm * ds;
      }
    }
    // Back to front: G (behind, weighted by s^2) and d = g T - G.
    float behind = 0.f;      // sum_{j>k} g mu T s^2 ds
    float runningMax = 0.f;  // max_{j>k} g
    for (int k = nz - 1; k >= 0; --k) {
      float m, g;
      bool opaque;
      sampleAt(o, d, frustum.depthOf(float(k)), m, g, opaque);
      g = fminf(g * w, 1.f);
      if (behindMax.valid()) {
        behindMax.store(behindMax.index(i, j, k), runningMax);
        runningMax = fmaxf(runningMax, g);
      }
      const size_t c = out.index(i, j, k);
      const float t = out.load(c);
      const float s = frustum.depthOf(float(k));
      const float s2 = s * s;
      out.store(c, g * t - behind / s2);
      const float gmt = g * m * t;
      behind += gmt * s2 * ds;
      const double dV = double(omega) * double(s2) * double(ds);
      sums.gMuT += double(gmt) * dV;
      sums.gMu += double(g * m) * dV;
    }
    return sums;
  }
};

}  // namespace visopt
