// The per-pixel kernels of moment images (Rapp et al. 2022): generation (§3.2: march the ray,
// accumulate the bounded trigonometric moments of the density and its bounds, rescale by Eq. 5),
// the moment count of §3.5, and emission-absorption rendering from a density source (the
// reconstruction of §3.3, or the volume itself as the reference), with a pre-integrated
// transfer function. Written once for host and device.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "kernels/bounded_mese.h"
#include "kernels/p_square.h"
#include "kernels/ray_box.h"

namespace visopt {

// A pixel's ray in the volume's index space and its interval [t0, t1] (world units along the
// unit direction) inside the box of voxel centres; row 0 is the image's top.
struct MomentRay {
  glm::vec3 o{0.f}, d{0.f};
  float t0 = 0.f, t1 = -1.f;
  VISOPT_HD bool hits() const { return t1 > t0; }
};

VISOPT_HD inline MomentRay momentRay(const FrustumMap& camera, const GridMap& volume,
                                     int64_t pixel) {
  const int w = camera.dims.x, h = camera.dims.y;
  const int px = int(pixel % w), row = int(pixel / w);
  MomentRay r;
  r.o = volume.toIndex(camera.eye);
  r.d = volume.directionToIndex(camera.rayDirection(float(px), float(h - 1 - row)));
  const RayInterval box = intersectBox(r.o, r.d, glm::vec3(volume.dims - 1));
  r.t0 = box.t0;
  r.t1 = box.t1;
  return r;
}

// Samples on [t0, t1] at most `step` apart, at least two.
VISOPT_HD inline int momentSampleCount(const MomentRay& r, float step) {
  const float n = ceilf((r.t1 - r.t0) / step);
  return n < 1.f ? 2 : (n > 1e6f ? 1000001 : int(n) + 1);
}

// The density a ray samples: trilinear in a field of the whole grid, or in a slab of it holding
// slices [first, first + slab's dims.z) (distributed generation). The slab's sample is the whole
// field's (FieldView::sample: clamped to the whole grid, the same weights) wherever the slab
// holds the eight voxels it reads.
struct WholeDensity {
  FieldView field;
  VISOPT_HD VISOPT_INLINE float operator()(glm::vec3 p) const { return field.sample(p); }
};
struct SlabDensity {
  FieldView slab;
  glm::ivec3 dims{0};  // of the whole grid
  int first = 0;
  VISOPT_HD VISOPT_INLINE float operator()(glm::vec3 p) const {
    p = glm::clamp(p, glm::vec3(0.f), glm::vec3(dims - 1));
    const glm::ivec3 i0 = glm::ivec3(p);
    const glm::ivec3 i1 = glm::min(i0 + 1, dims - 1);
    const glm::vec3 f = p - glm::vec3(i0);
    const int z0 = i0.z - first, z1 = i1.z - first;
    const float c000 = slab.at(i0.x, i0.y, z0), c100 = slab.at(i1.x, i0.y, z0);
    const float c010 = slab.at(i0.x, i1.y, z0), c110 = slab.at(i1.x, i1.y, z0);
    const float c001 = slab.at(i0.x, i0.y, z1), c101 = slab.at(i1.x, i0.y, z1);
    const float c011 = slab.at(i0.x, i1.y, z1), c111 = slab.at(i1.x, i1.y, z1);
    const float c00 = c000 + f.x * (c100 - c000), c10 = c010 + f.x * (c110 - c010);
    const float c01 = c001 + f.x * (c101 - c001), c11 = c011 + f.x * (c111 - c011);
    const float c0 = c00 + f.y * (c10 - c00), c1 = c01 + f.y * (c11 - c01);
    return c0 + f.z * (c1 - c0);
  }
};

// Sample k of a ray with n samples: its position in index space and its phase (§3: [t0, t1]
// maps linearly to [-pi, 0]).
VISOPT_HD VISOPT_INLINE glm::vec3 momentSamplePoint(const MomentRay& r, int k, float dt) {
  return r.o + (r.t0 + float(k) * dt) * r.d;
}

// c += the raw bounded trigonometric moments (before Eq. 5) of the ray's piecewise linear density
// over samples first..last (first < last), in pieces of kPiece samples that share their end
// samples (moments of pieces add); lo, hi: the min and max of samples first..ownedLast.
template <class Density>
VISOPT_HD inline void addRayMoments(const MomentRay& r, int n, int first, int last, int ownedLast,
                                    int order, const Density& density, double* c, float& lo,
                                    float& hi) {
  constexpr int kPiece = 64;
  float phi[kPiece + 1], s[kPiece + 1];
  const float dt = (r.t1 - r.t0) / float(n - 1);
  const float dphi = float(kMomentPi) / float(n - 1);
  for (int start = first; start < last; start += kPiece) {
    const int end = start + kPiece < last ? start + kPiece : last;
    for (int k = start; k <= end; ++k) {
      const float v = density(momentSamplePoint(r, k, dt));
      const float sv = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
      phi[k - start] = k == n - 1 ? 0.f : -float(kMomentPi) + float(k) * dphi;
      s[k - start] = sv;
      if (k <= ownedLast) {
        lo = sv < lo ? sv : lo;
        hi = sv > hi ? sv : hi;
      }
    }
    addSegmentMoments(phi, s, end - start + 1, order, c);
  }
}

struct MomentGeneration {
  FrustumMap camera;
  GridMap volume;
  FieldView density;  // normalised to [0, 1]
  int order = 0;      // m
  float step = 1.f;   // world units
  float margin = 0.005f;
  float* moments = nullptr;  // (order + 1) per pixel, rescaled by Eq. 5
  float* lower = nullptr;    // per pixel; lower > upper marks a ray that misses the volume
  float* upper = nullptr;
  int* samples = nullptr;  // per pixel

  VISOPT_HD void operator()(int64_t pixel) const {
    const int stride = order + 1;
    float* out = moments + pixel * stride;
    const MomentRay r = momentRay(camera, volume, pixel);
    if (!r.hits()) {
      for (int j = 0; j < stride; ++j) out[j] = 0.f;
      lower[pixel] = 1.f;
      upper[pixel] = 0.f;
      samples[pixel] = 0;
      return;
    }
    const int n = momentSampleCount(r, step);
    double c[kMomentCapacity];
    for (int j = 0; j < stride; ++j) c[j] = 0.0;
    float lo = 1e30f, hi = -1e30f;
    addRayMoments(r, n, 0, n - 1, n - 1, order, WholeDensity{density}, c, lo, hi);
    rescaleMoments(c, order, lo, hi, margin, out, lower[pixel], upper[pixel]);
    samples[pixel] = n;
  }

  // Eq. 5: the moments of (s - lower) / (upper - lower), lower = lo - margin, upper = hi + margin.
  VISOPT_HD static void rescaleMoments(const double* c, int order, float lo, float hi, float margin,
                                       float* out, float& lower, float& upper) {
    const double a = double(lo) - double(margin), b = double(hi) + double(margin);
    const double scale = 1.0 / (b - a);
    out[0] = float((c[0] - a) * scale);
    for (int j = 1; j <= order; ++j) out[j] = float(c[j] * scale);
    lower = float(a);
    upper = float(b);
  }
};

// Distributed generation: the part of every pixel's ray that one slab of the grid owns. Sample k
// belongs to the slab whose owned slices [ownedBegin, ownedEnd) hold its z (the first slab's
// range open below, the last's above, so that each sample has exactly one owner; along a
// straight ray a slab's samples are consecutive). The slab adds the raw moments of the piece
// from its first sample to the sample after its last (the next slab's first: pieces sharing end
// samples add up to the whole ray's moments) and the min and max of its own samples; summed over
// the slabs (min and max for the bounds) and rescaled by Eq. 5, that is generateMomentImage's
// result up to the order of the sums. The slab must hold the slices that piece reads: the owned
// ones and momentSlabHalo more on each side.
struct MomentSlabGeneration {
  FrustumMap camera;
  GridMap volume;  // the whole grid
  SlabDensity density;
  float ownedBegin = -1e30f, ownedEnd = 1e30f;  // z in index units
  int order = 0;
  float step = 1.f;           // world units
  double* moments = nullptr;  // (order + 1) per pixel, raw, added to
  float* lower = nullptr;     // per pixel: min and max of the owned samples so far
  float* upper = nullptr;

  VISOPT_HD void operator()(int64_t pixel) const {
    const MomentRay r = momentRay(camera, volume, pixel);
    if (!r.hits()) return;
    const int n = momentSampleCount(r, step);
    const float dt = (r.t1 - r.t0) / float(n - 1);
    int first = -1, last = -1;
    for (int k = 0; k < n; ++k) {
      const float z = momentSamplePoint(r, k, dt).z;
      if (z >= ownedBegin && z < ownedEnd) {
        if (first < 0) first = k;
        last = k;
      } else if (first >= 0) {
        break;
      }
    }
    if (first < 0) return;
    float lo = lower[pixel], hi = upper[pixel];
    double* c = moments + pixel * (order + 1);
    const int pieceEnd = last + 1 < n ? last + 1 : last;
    if (pieceEnd > first) {
      addRayMoments(r, n, first, pieceEnd, last, order, density, c, lo, hi);
    } else {  // the ray's last sample alone: no segment, only the bounds
      const float v = density(momentSamplePoint(r, first, dt));
      const float sv = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
      lo = sv < lo ? sv : lo;
      hi = sv > hi ? sv : hi;
    }
    lower[pixel] = lo;
    upper[pixel] = hi;
  }
};

// §3.5: how many moments each pixel keeps (0 for a ray that misses the volume), from the
// moments as they are stored (floats), capped where the sequence stops being valid.
struct MomentCount {
  const float* moments = nullptr;
  const float* lower = nullptr;
  const float* upper = nullptr;
  int order = 0;
  double threshold = 0.01;
  uint8_t* counts = nullptr;

  VISOPT_HD void operator()(int64_t pixel) const {
    if (!(lower[pixel] < upper[pixel])) {
      counts[pixel] = 0;
      return;
    }
    double c[kMomentCapacity];
    for (int j = 0; j <= order; ++j) c[j] = double(moments[pixel * (order + 1) + j]);
    MomentComplex gamma[kMomentCapacity], q[kMomentCapacity];
    exponentialMoments(c, order, gamma);
    const int valid = levinson(gamma, order, q);
    int n = momentCountFor(c, order, threshold);
    n = n < valid ? n : valid;
    counts[pixel] = uint8_t((n < 0 ? 0 : n) + 1);
  }
};

// Pre-integration tables of a baked transfer function (rgb albedo, extinction per entry):
// cumulative integrals over the table's index of the extinction and of albedo x extinction.
struct MomentTransfer {
  const glm::vec4* table = nullptr;       // albedo rgb, extinction
  const glm::vec4* cumulative = nullptr;  // integral of albedo x extinction, of extinction
  int size = 0;
  bool preintegrate = true;

  VISOPT_HD glm::vec4 lerp(const glm::vec4* t, float x) const {
    const int i0 = int(x);
    const int i1 = i0 + 1 < size ? i0 + 1 : size - 1;
    const float f = x - float(i0);
    return t[i0] + f * (t[i1] - t[i0]);
  }

  // Emitted colour (rgb) and opacity (w) of a segment of `length` world units over which the
  // normalised density runs linearly from sf to sb.
  VISOPT_HD glm::vec4 segment(float sf, float sb, float length) const {
    const float hiX = float(size - 1);
    const float xf = (sf < 0.f ? 0.f : (sf > 1.f ? 1.f : sf)) * hiX;
    const float xb = (sb < 0.f ? 0.f : (sb > 1.f ? 1.f : sb)) * hiX;
    glm::vec3 emitted;  // integral of albedo x extinction over the segment
    float tau;          // optical depth
    if (preintegrate && fabsf(xb - xf) > 1e-3f) {
      const glm::vec4 d = (lerp(cumulative, xb) - lerp(cumulative, xf)) * (length / (xb - xf));
      emitted = glm::vec3(d);
      tau = d.w;
    } else {
      const glm::vec4 e = lerp(table, preintegrate ? xf : 0.5f * (xf + xb));
      tau = e.w * length;
      emitted = glm::vec3(e) * tau;
    }
    if (!(tau > 1e-12f)) return glm::vec4(0.f);
    const float alpha = 1.f - expf(-tau);
    return glm::vec4(emitted * (alpha / tau), alpha);
  }
};

// The density of a pixel's ray from its stored moments (bounded MESE or Fourier), per sample.
struct MomentDensity {
  const float* moments = nullptr;  // the pixel's rescaled moments or Lagrange multipliers
  const float* imag = nullptr;     // the multipliers' imaginary parts (MESE), else null
  int order = -1;                  // highest index stored
  float lower = 0.f, upper = 1.f;

  VISOPT_HD float at(float phi) const {
    if (order < 0) return 0.f;
    const float st = imag ? meseAt(moments, imag, order, phi) : fourierAt(moments, order, phi);
    return lower + st * (upper - lower);  // Eq. 5 inverted
  }
  // at() at kMomentLanes angles.
  VISOPT_HD void atLanes(const float* phi, float* out) const {
    if (order < 0) {
      for (int i = 0; i < kMomentLanes; ++i) out[i] = 0.f;
      return;
    }
    if (imag)
      meseAtLanes(moments, imag, order, phi, out);
    else
      fourierAtLanes(moments, order, phi, out);
    for (int i = 0; i < kMomentLanes; ++i) out[i] = lower + out[i] * (upper - lower);
  }
};

// The front-to-back sum of a ray's segments; the ray counts as opaque once its transmittance
// falls to 1e-4.
struct FrontToBack {
  glm::vec3 radiance{0.f};
  float transmittance = 1.f;
  VISOPT_HD bool open() const { return transmittance > 1e-4f; }
  VISOPT_HD void add(const MomentTransfer& tf, float front, float back, float dt) {
    const glm::vec4 seg = tf.segment(front, back, dt);
    radiance += transmittance * glm::vec3(seg);
    transmittance *= 1.f - seg.w;
  }
};

// Front-to-back emission-absorption along one ray, `n` samples from t0 to t1, density(k, t,
// phi) giving the normalised density at sample k.
template <class Density>
VISOPT_HD inline glm::vec3 compositeRay(const MomentRay& r, int n, const MomentTransfer& tf,
                                        Density density) {
  const float dt = (r.t1 - r.t0) / float(n - 1);
  const float dphi = float(kMomentPi) / float(n - 1);
  FrontToBack sum;
  float front = density(r.t0, -float(kMomentPi));
  for (int k = 1; k < n && sum.open(); ++k) {
    const float back = density(r.t0 + float(k) * dt, -float(kMomentPi) + float(k) * dphi);
    sum.add(tf, front, back, dt);
    front = back;
  }
  return sum.radiance;
}

// compositeRay with the density taken kMomentLanes samples at a time, density(phi, out) giving
// the normalised density at the angles phi[0..kMomentLanes) (past the last sample they repeat
// it). The samples, their angles and the compositing are compositeRay's; a ray that turns
// opaque wastes at most one block's evaluations.
template <class LaneDensity>
VISOPT_HD inline glm::vec3 compositeRayLanes(const MomentRay& r, int n, const MomentTransfer& tf,
                                             LaneDensity density) {
  const float dt = (r.t1 - r.t0) / float(n - 1);
  const float dphi = float(kMomentPi) / float(n - 1);
  FrontToBack sum;
  float front = 0.f;
  float phi[kMomentLanes], value[kMomentLanes];
  for (int k0 = 0; k0 < n && sum.open(); k0 += kMomentLanes) {
    for (int i = 0; i < kMomentLanes; ++i) {
      const int k = k0 + i < n ? k0 + i : n - 1;
      phi[i] = -float(kMomentPi) + float(k) * dphi;
    }
    density(phi, value);
    for (int i = 0; i < kMomentLanes && k0 + i < n; ++i) {
      if (k0 + i == 0) {
        front = value[0];
        continue;
      }
      if (!sum.open()) break;
      sum.add(tf, front, value[i], dt);
      front = value[i];
    }
  }
  return sum.radiance;
}

// Renders pixels from a moment image: per pixel the stored moments (Fourier) or the Lagrange
// multipliers computed from them (MESE, `imag` set). perSample evaluates one sample after the
// other (compositeRay), the reference the lanes path is tested against.
struct MomentRender {
  FrustumMap camera;
  GridMap volume;
  MomentTransfer tf;
  float step = 1.f;
  const uint64_t* offsets = nullptr;
  const float* values = nullptr;  // moments or multipliers' real parts, at offsets
  const float* imag = nullptr;    // multipliers' imaginary parts, or null (Fourier)
  const float* lower = nullptr;
  const float* upper = nullptr;
  glm::vec3* out = nullptr;
  bool perSample = false;

  VISOPT_HD void operator()(int64_t pixel) const {
    const MomentRay r = momentRay(camera, volume, pixel);
    const uint64_t begin = offsets[pixel], count = offsets[pixel + 1] - begin;
    if (!r.hits() || count == 0) {
      out[pixel] = glm::vec3(0.f);
      return;
    }
    MomentDensity d;
    d.moments = values + begin;
    d.imag = imag ? imag + begin : nullptr;
    d.order = int(count) - 1;
    d.lower = lower[pixel];
    d.upper = upper[pixel];
    const int n = momentSampleCount(r, step);
    if (perSample)
      out[pixel] = compositeRay(r, n, tf, [&](float, float phi) { return d.at(phi); });
    else
      out[pixel] =
          compositeRayLanes(r, n, tf, [&](const float* phi, float* v) { d.atLanes(phi, v); });
  }
};

// The same rendering from the volume (the reference).
struct VolumeEmissionAbsorption {
  FrustumMap camera;
  GridMap volume;
  FieldView density;
  MomentTransfer tf;
  float step = 1.f;
  glm::vec3* out = nullptr;

  VISOPT_HD void operator()(int64_t pixel) const {
    const MomentRay r = momentRay(camera, volume, pixel);
    if (!r.hits()) {
      out[pixel] = glm::vec3(0.f);
      return;
    }
    out[pixel] = compositeRay(r, momentSampleCount(r, step), tf, [&](float t, float) {
      const float v = density.sample(r.o + t * r.d);
      return v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
    });
  }
};

// The bounded MESE's multipliers lambda_0..lambda_{count-1} of one pixel's `count` moments, as
// floats (zero past the order used); returns that order. c_0 outside (0, 1) cannot be (Eq. 5
// puts the mean strictly inside the bounds); should it happen, the constant with that mean
// (lambda_0 = tan(pi (c_0 - 1/2)), order 0) is what remains.
VISOPT_HD inline float constantMultiplier(double c0) {
  return float(tan(kMomentPi * (fmin(fmax(c0, 1e-6), 1.0 - 1e-6) - 0.5)));
}

VISOPT_HD inline int pixelMultipliers(const float* moments, int count, float* re, float* im) {
  double c[kMomentCapacity] = {};
  for (int j = 0; j < count; ++j) c[j] = double(moments[j]);
  MomentComplex lambda[kMomentCapacity];
  const int order = boundedMese(c, count - 1, lambda);
  for (int j = 0; j < count; ++j) {
    re[j] = j <= order ? float(lambda[j].re) : 0.f;
    im[j] = j <= order ? float(lambda[j].im) : 0.f;
  }
  if (order >= 0) return order;
  re[0] = constantMultiplier(c[0]);
  return 0;
}

// §4.1: per pixel, the p-quantile of |reconstructed - volume| density along the ray (bounded
// MESE of the stored moments against the volume's samples at the generation's step), estimated
// online by P-square so that a pixel needs no storage of its samples.
struct MomentUncertainty {
  FrustumMap camera;
  GridMap volume;
  FieldView density;
  float step = 1.f;
  float quantile = 0.95f;
  const uint64_t* offsets = nullptr;
  const float* moments = nullptr;
  const float* lower = nullptr;
  const float* upper = nullptr;
  float* out = nullptr;

  VISOPT_HD void operator()(int64_t pixel) const {
    const MomentRay r = momentRay(camera, volume, pixel);
    const uint64_t begin = offsets[pixel];
    const int count = int(offsets[pixel + 1] - begin);
    if (!r.hits() || count == 0) {
      out[pixel] = 0.f;
      return;
    }
    float re[kMomentCapacity], im[kMomentCapacity];
    const int order = pixelMultipliers(moments + begin, count, re, im);
    const MomentDensity d{re, im, order, lower[pixel], upper[pixel]};
    const int n = momentSampleCount(r, step);
    const float dt = (r.t1 - r.t0) / float(n - 1);
    const float dphi = float(kMomentPi) / float(n - 1);
    PSquare q(quantile);
    for (int k = 0; k < n; ++k) {
      const float v = density.sample(r.o + (r.t0 + float(k) * dt) * r.d);
      const float truth = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
      q.add(fabsf(d.at(-float(kMomentPi) + float(k) * dphi) - truth));
    }
    out[pixel] = q.value();
  }
};

}  // namespace visopt
