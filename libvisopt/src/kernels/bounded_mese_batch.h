// boundedMese (kernels/bounded_mese.h: Eq. 1, Levinson's Eqs. 6-8 and Eq. 2) for kMeseBatch
// pixels at once, one pixel per SIMD lane. Per pixel the recursions are chains of dependent
// complex multiplies (O(m^2) each), which one pixel at a time leaves waiting on latency; side by
// side, pixel b's arithmetic is boundedMese's own, in the same order, with lanes of lower order
// masked. Levinson's early stop (a system that is not positive definite) is a per-lane flag.
// Host code: the renderer's CPU path (a GPU thread computes one pixel with boundedMese).
#pragma once

#include <cmath>

#include "core/hd.h"
#include "kernels/bounded_mese.h"

namespace visopt {

inline constexpr int kMeseBatch = 8;

// Lane-major arrays: element [l * kMeseBatch + b] is index l of pixel b.
struct MeseBatch {
  double c[kMomentCapacity * kMeseBatch];  // bounded moments; past a pixel's m, anything
  int m[kMeseBatch];                       // highest moment per pixel; -1: no pixel in the lane
  // Output: multipliers lambda_0..lambda_order (zero past it) and the order, -1 where
  // boundedMese returns -1.
  double lambdaRe[kMomentCapacity * kMeseBatch], lambdaIm[kMomentCapacity * kMeseBatch];
  int order[kMeseBatch];
};

inline void boundedMeseBatch(MeseBatch& p) {
  constexpr int B = kMeseBatch;
  double gRe[kMomentCapacity * B], gIm[kMomentCapacity * B];
  double qRe[kMomentCapacity * B], qIm[kMomentCapacity * B];
  double pRe[kMomentCapacity * B], pIm[kMomentCapacity * B];
  double seedRe[B], seedIm[B];
  bool live[B];
  int top = -1;
  for (int b = 0; b < B; ++b) {
    const double c0 = p.c[b];
    const bool valid = p.m[b] >= 0 && c0 > 0.0 && c0 < 1.0;
    const MomentComplex seed = exponentialSeed(valid ? c0 : 0.5);
    seedRe[b] = seed.re;
    seedIm[b] = seed.im;
    live[b] = valid;
    p.order[b] = valid ? 0 : -1;
    if (valid) top = p.m[b] > top ? p.m[b] : top;
  }
  for (int i = 0; i < kMomentCapacity * B; ++i) p.lambdaRe[i] = p.lambdaIm[i] = 0.0;
  if (top < 0) return;

  // Eq. 1 (exponentialMoments): gamma_l = (2 pi i / l) (l c_l seed + sum_j (l - j) c_{l-j}
  // gamma_j).
  for (int b = 0; b < B; ++b) {
    gRe[b] = 2.0 * seedRe[b];
    gIm[b] = 0.0;
  }
  for (int l = 1; l <= top; ++l) {
    double sRe[B], sIm[B];
    VISOPT_LANE_LOOP
    for (int b = 0; b < B; ++b) sRe[b] = sIm[b] = 0.0;
    for (int j = 1; j < l; ++j) {
      VISOPT_LANE_LOOP
      for (int b = 0; b < B; ++b) {
        const double w = double(l - j) * p.c[(l - j) * B + b];
        sRe[b] = sRe[b] + w * gRe[j * B + b];
        sIm[b] = sIm[b] + w * gIm[j * B + b];
      }
    }
    const double f = 2.0 * kMomentPi / double(l);
    VISOPT_LANE_LOOP
    for (int b = 0; b < B; ++b) {
      const double w = double(l) * p.c[l * B + b];
      const double re = w * seedRe[b] + sRe[b], im = w * seedIm[b] + sIm[b];
      gRe[l * B + b] = -f * im;
      gIm[l * B + b] = f * re;
    }
  }

  // Levinson (levinson): q^(l) from q^(l-1), while the system stays positive definite.
  for (int b = 0; b < B; ++b) {
    live[b] = live[b] && gRe[b] > 0.0;
    if (!live[b]) p.order[b] = -1;
    qRe[b] = live[b] ? 1.0 / gRe[b] : 0.0;
    qIm[b] = 0.0;
  }
  for (int l = 1; l <= top; ++l) {
    double uRe[B], uIm[B], inv[B];
    double step[B];  // 1 where the lane takes this order (a double: the select vectorises)
    VISOPT_LANE_LOOP
    for (int b = 0; b < B; ++b) uRe[b] = uIm[b] = 0.0;
    for (int k = 0; k < l; ++k) {
      VISOPT_LANE_LOOP
      for (int b = 0; b < B; ++b) {
        const double ar = qRe[k * B + b], ai = qIm[k * B + b];
        const double br = gRe[(l - k) * B + b], bi = gIm[(l - k) * B + b];
        uRe[b] = uRe[b] + (ar * br - ai * bi);
        uIm[b] = uIm[b] + (ar * bi + ai * br);
      }
    }
    bool any = false;
    for (int b = 0; b < B; ++b) {
      const double d = 1.0 - (uRe[b] * uRe[b] + uIm[b] * uIm[b]);
      if (live[b] && (l > p.m[b] || !(d > 1e-13))) live[b] = false;
      step[b] = live[b] ? 1.0 : 0.0;
      inv[b] = live[b] ? 1.0 / d : 0.0;
      if (live[b]) p.order[b] = l;
      any = any || live[b];
    }
    if (!any) break;
    for (int k = 0; k < l; ++k)
      for (int b = 0; b < B; ++b) {
        pRe[k * B + b] = qRe[k * B + b];
        pIm[k * B + b] = qIm[k * B + b];
      }
    for (int k = 0; k <= l; ++k) {
      VISOPT_LANE_LOOP
      for (int b = 0; b < B; ++b) {
        // q_k = inv (prev_k - u conj(prev_{l-k})), prev_l = 0 and the conj term 0 at k = 0
        const double ar = k < l ? pRe[k * B + b] : 0.0, ai = k < l ? pIm[k * B + b] : 0.0;
        const double br = k > 0 ? pRe[(l - k) * B + b] : 0.0;
        const double bi = k > 0 ? -pIm[(l - k) * B + b] : 0.0;
        const double re = inv[b] * (ar - (uRe[b] * br - uIm[b] * bi));
        const double im = inv[b] * (ai - (uRe[b] * bi + uIm[b] * br));
        qRe[k * B + b] = step[b] != 0.0 ? re : qRe[k * B + b];
        qIm[k * B + b] = step[b] != 0.0 ? im : qIm[k * B + b];
      }
    }
  }
  int topOrder = -1;
  for (int b = 0; b < B; ++b) topOrder = p.order[b] > topOrder ? p.order[b] : topOrder;
  for (int k = 0; k <= topOrder; ++k)
    for (int b = 0; b < B; ++b) {
      qRe[k * B + b] = (2.0 * kMomentPi) * qRe[k * B + b];
      qIm[k * B + b] = (2.0 * kMomentPi) * qIm[k * B + b];
    }

  // Eq. 2 (lagrangeMultipliers): R_d = sum_j conj(q_{j+d}) q_j, lambda_l = sum_k gamma-check_k
  // R_{k+l} / (pi i q_0), each lane to its own order.
  double rRe[kMomentCapacity * B], rIm[kMomentCapacity * B];
  for (int d = 0; d <= topOrder; ++d) {
    double sRe[B], sIm[B];
    VISOPT_LANE_LOOP
    for (int b = 0; b < B; ++b) sRe[b] = sIm[b] = 0.0;
    for (int j = 0; j + d <= topOrder; ++j) {
      VISOPT_LANE_LOOP
      for (int b = 0; b < B; ++b) {
        const bool in = j + d <= p.order[b];
        const double ar = qRe[(j + d) * B + b], ai = -qIm[(j + d) * B + b];
        const double br = qRe[j * B + b], bi = qIm[j * B + b];
        sRe[b] = in ? sRe[b] + (ar * br - ai * bi) : sRe[b];
        sIm[b] = in ? sIm[b] + (ar * bi + ai * br) : sIm[b];
      }
    }
    for (int b = 0; b < B; ++b) {
      rRe[d * B + b] = sRe[b];
      rIm[d * B + b] = sIm[b];
    }
  }
  for (int l = 0; l <= topOrder; ++l) {
    double sRe[B], sIm[B];
    VISOPT_LANE_LOOP
    for (int b = 0; b < B; ++b) sRe[b] = sIm[b] = 0.0;
    for (int k = 0; k + l <= topOrder; ++k) {
      VISOPT_LANE_LOOP
      for (int b = 0; b < B; ++b) {
        const bool in = k + l <= p.order[b];
        const double ar = k == 0 ? seedRe[b] : gRe[k * B + b];
        const double ai = k == 0 ? seedIm[b] : gIm[k * B + b];
        const double br = rRe[(k + l) * B + b], bi = rIm[(k + l) * B + b];
        sRe[b] = in ? sRe[b] + (ar * br - ai * bi) : sRe[b];
        sIm[b] = in ? sIm[b] + (ar * bi + ai * br) : sIm[b];
      }
    }
    for (int b = 0; b < B; ++b) {
      if (l > p.order[b]) continue;
      const double scale = 1.0 / (kMomentPi * qRe[b]);
      p.lambdaRe[l * B + b] = scale * sIm[b];
      p.lambdaIm[l * B + b] = -scale * sRe[b];
    }
  }
}

}  // namespace visopt
