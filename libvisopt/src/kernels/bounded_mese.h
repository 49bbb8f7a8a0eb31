// Bounded trigonometric moments and their reconstructions (Rapp, Peters, Dachsbacher 2022, §3.1
// and §3.4, after Peters et al. 2019): a signal s: [-pi, 0] -> [0, 1], mirrored to an even signal
// on [-pi, pi], is stored as c_j = 1/(2 pi) int s(phi) exp(-i j phi) dphi, j = 0..m (real, as the
// signal is even). The bounded MESE turns them into exponential moments (Eq. 1), solves their
// Toeplitz system with Levinson's algorithm (Eqs. 6-8), forms Lagrange multipliers (Eq. 2) and
// evaluates 1/2 + atan(...)/pi (Eq. 3), which never leaves (0, 1) and reproduces the moments it was
// built from (Eq. 4). The truncated Fourier series is the simple alternative.
//
// Written once for host and device: plain arrays of at most kMomentCapacity entries, doubles
// (the Toeplitz systems of 100 moments lose ~8 digits in float), no library types.
#pragma once

#include <cmath>

#include "core/hd.h"

namespace visopt {

// Moments 0..m with m + 1 <= kMomentCapacity (the paper uses m = 100).
inline constexpr int kMomentCapacity = 128;

struct MomentComplex {
  double re = 0.0, im = 0.0;
};

VISOPT_HD inline MomentComplex operator+(MomentComplex a, MomentComplex b) {
  return {a.re + b.re, a.im + b.im};
}
VISOPT_HD inline MomentComplex operator-(MomentComplex a, MomentComplex b) {
  return {a.re - b.re, a.im - b.im};
}
VISOPT_HD inline MomentComplex operator*(MomentComplex a, MomentComplex b) {
  return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
}
VISOPT_HD inline MomentComplex operator*(double s, MomentComplex a) {
  return {s * a.re, s * a.im};
}
VISOPT_HD inline MomentComplex conjugate(MomentComplex a) {
  return {a.re, -a.im};
}
VISOPT_HD inline double norm2(MomentComplex a) {
  return a.re * a.re + a.im * a.im;
}
VISOPT_HD inline MomentComplex divide(MomentComplex a, MomentComplex b) {
  const double d = norm2(b);
  return {(a.re * b.re + a.im * b.im) / d, (a.im * b.re - a.re * b.im) / d};
}

constexpr double kMomentPi = 3.14159265358979323846;

// cos, sin and atan in the argument's precision on host and device.
VISOPT_HD inline float momentCos(float x) {
  return cosf(x);
}
VISOPT_HD inline double momentCos(double x) {
  return cos(x);
}
VISOPT_HD inline float momentSin(float x) {
  return sinf(x);
}
VISOPT_HD inline double momentSin(double x) {
  return sin(x);
}
VISOPT_HD inline float momentAtan(float x) {
  return atanf(x);
}
VISOPT_HD inline double momentAtan(double x) {
  return atan(x);
}

// gamma-check_0 = exp(pi i (c_0 - 1/2)) / (4 pi) (§3.1).
VISOPT_HD inline MomentComplex exponentialSeed(double c0) {
  const double a = kMomentPi * (c0 - 0.5);
  return {cos(a) / (4.0 * kMomentPi), sin(a) / (4.0 * kMomentPi)};
}

// Eq. 1: the exponential moments gamma_0..gamma_m of bounded moments c_0..c_m. (The reference
// code reads gamma_l where the sum needs gamma_j, which puts its round trip 3-17 % off.)
// The convolution sum_{j=1}^{l-1} (l - j) c_{l-j} gamma_j that Eqs. 1 and 9 share.
VISOPT_HD inline MomentComplex weightedConvolution(int l, const double* c,
                                                   const MomentComplex* gamma) {
  MomentComplex sum{0.0, 0.0};
  for (int j = 1; j < l; ++j) sum = sum + (double(l - j) * c[l - j]) * gamma[j];
  return sum;
}

VISOPT_HD inline void exponentialMoments(const double* c, int m, MomentComplex* gamma) {
  const MomentComplex seed = exponentialSeed(c[0]);
  gamma[0] = {2.0 * seed.re, 0.0};
  for (int l = 1; l <= m; ++l) {
    const MomentComplex sum = (double(l) * c[l]) * seed + weightedConvolution(l, c, gamma);
    // (2 pi i / l) * sum
    const double f = 2.0 * kMomentPi / double(l);
    gamma[l] = {-f * sum.im, f * sum.re};
  }
}

// Eq. 9: bounded moment c_l from gamma_1..gamma_l and c_1..c_{l-1} (the inverse of Eq. 1).
VISOPT_HD inline double boundedMomentAt(int l, const MomentComplex* gamma, const double* c,
                                        MomentComplex seed) {
  // gamma_l / (2 pi i seed) - sum_{j<l} (l - j) gamma_j c_{l-j} / (l seed)
  const MomentComplex twoPiISeed = {-2.0 * kMomentPi * seed.im, 2.0 * kMomentPi * seed.re};
  const MomentComplex sum = weightedConvolution(l, c, gamma);
  const MomentComplex v = divide(gamma[l], twoPiISeed) -
                          divide(sum, MomentComplex{double(l) * seed.re, double(l) * seed.im});
  return v.re;  // real up to round-off: the signal is even
}

// Eqs. 6-8, Levinson's algorithm: q = C(gamma)^-1 e_0 = 2 pi q^(m) for the Hermitian Toeplitz
// matrix (gamma_{j-k}). Returns the largest order l <= m whose system is positive definite
// (|u^(l)| < 1 with a margin for round-off); q then holds the solution of that order. m < 0
// never happens; gamma_0 <= 0 returns -1.
VISOPT_HD inline int levinson(const MomentComplex* gamma, int m, MomentComplex* q) {
  if (!(gamma[0].re > 0.0)) return -1;
  MomentComplex prev[kMomentCapacity];
  q[0] = {1.0 / gamma[0].re, 0.0};
  int order = 0;
  for (int l = 1; l <= m; ++l) {
    MomentComplex u{0.0, 0.0};
    for (int k = 0; k < l; ++k) u = u + q[k] * gamma[l - k];  // Eq. 7
    const double d = 1.0 - norm2(u);
    if (!(d > 1e-13)) break;  // not positive definite (or too close to it to trust)
    for (int k = 0; k < l; ++k) prev[k] = q[k];
    const double inv = 1.0 / d;
    for (int k = 0; k <= l; ++k) {  // Eq. 8
      const MomentComplex a = k < l ? prev[k] : MomentComplex{0.0, 0.0};
      const MomentComplex b = k > 0 ? conjugate(prev[l - k]) : MomentComplex{0.0, 0.0};
      q[k] = inv * (a - u * b);
    }
    order = l;
  }
  for (int k = 0; k <= order; ++k) q[k] = (2.0 * kMomentPi) * q[k];
  return order;
}

// Eq. 2: the Lagrange multipliers lambda_0..lambda_m from q and gamma (gamma-check_0 = seed,
// gamma-check_k = gamma_k for k >= 1). With the autocorrelation R_d = sum_j conj(q_{j+d}) q_j the
// double sum is sum_k gamma-check_k R_{k+l}: O(m^2) instead of O(m^3).
VISOPT_HD inline void lagrangeMultipliers(const MomentComplex* q, const MomentComplex* gamma,
                                          MomentComplex seed, int m, MomentComplex* lambda) {
  MomentComplex r[kMomentCapacity];
  for (int d = 0; d <= m; ++d) {
    MomentComplex s{0.0, 0.0};
    for (int j = 0; j + d <= m; ++j) s = s + conjugate(q[j + d]) * q[j];
    r[d] = s;
  }
  // 1 / (pi i q_0), q_0 real and positive
  const double scale = 1.0 / (kMomentPi * q[0].re);
  for (int l = 0; l <= m; ++l) {
    MomentComplex s{0.0, 0.0};
    for (int k = 0; k + l <= m; ++k) s = s + (k == 0 ? seed : gamma[k]) * r[k + l];
    lambda[l] = {scale * s.im, -scale * s.re};  // s / (i) * scale
  }
}

// The Lagrange multipliers of bounded moments c_0..c_m; returns the order used (see levinson:
// fewer moments when the higher ones do not form a valid sequence), -1 when c_0 is outside (0, 1).
VISOPT_HD inline int boundedMese(const double* c, int m, MomentComplex* lambda) {
  if (!(c[0] > 0.0 && c[0] < 1.0)) return -1;
  MomentComplex gamma[kMomentCapacity], q[kMomentCapacity];
  exponentialMoments(c, m, gamma);
  const int order = levinson(gamma, m, q);
  if (order < 0) return -1;
  lagrangeMultipliers(q, gamma, exponentialSeed(c[0]), order, lambda);
  return order;
}

// Eq. 3: the bounded MESE at phi from its multipliers lambda_0..lambda_m, in (0, 1).
template <class Real>
VISOPT_HD inline Real meseAt(const Real* lambdaRe, const Real* lambdaIm, int m, Real phi) {
  // Re(lambda_l exp(-i l phi)) = Re lambda_l cos(l phi) + Im lambda_l sin(l phi), with the
  // rotation exp(-i phi) applied l times.
  const Real cr = momentCos(phi), ci = -momentSin(phi);
  Real zr = 1, zi = 0, sum = 0;
  for (int l = 1; l <= m; ++l) {
    const Real nr = zr * cr - zi * ci, ni = zr * ci + zi * cr;
    zr = nr;
    zi = ni;
    sum += lambdaRe[l] * zr - lambdaIm[l] * zi;
  }
  return Real(1) / Real(kMomentPi) * momentAtan(lambdaRe[0] + Real(2) * sum) + Real(0.5);
}

// Rendering evaluates a ray's samples kMomentLanes at a time: meseAt's rotation by exp(-i phi)
// is a chain of dependent multiplies, m long per sample, so one sample at a time waits on
// latency; independent samples side by side fill the SIMD lanes (and a GPU thread's pipeline).
inline constexpr int kMomentLanes = 16;

// meseAt at kMomentLanes angles phi[0..], the same operations lane by lane.
template <class Real>
VISOPT_HD inline void meseAtLanes(const Real* lambdaRe, const Real* lambdaIm, int m,
                                  const Real* phi, Real* out) {
  Real cr[kMomentLanes], ci[kMomentLanes], zr[kMomentLanes], zi[kMomentLanes], sum[kMomentLanes];
  for (int i = 0; i < kMomentLanes; ++i) {
    cr[i] = momentCos(phi[i]);
    ci[i] = -momentSin(phi[i]);
    zr[i] = 1;
    zi[i] = 0;
    sum[i] = 0;
  }
  for (int l = 1; l <= m; ++l) {
    const Real a = lambdaRe[l], b = lambdaIm[l];
    VISOPT_LANE_LOOP
    for (int i = 0; i < kMomentLanes; ++i) {
      const Real nr = zr[i] * cr[i] - zi[i] * ci[i], ni = zr[i] * ci[i] + zi[i] * cr[i];
      zr[i] = nr;
      zi[i] = ni;
      sum[i] += a * zr[i] - b * zi[i];
    }
  }
  for (int i = 0; i < kMomentLanes; ++i)
    out[i] = Real(1) / Real(kMomentPi) * momentAtan(lambdaRe[0] + Real(2) * sum[i]) + Real(0.5);
}

// The truncated Fourier series c_0 + 2 sum_l c_l cos(l phi) (the signal is even).
template <class Real>
VISOPT_HD inline Real fourierAt(const Real* c, int m, Real phi) {
  // cos(l phi) by the recurrence cos((l+1) phi) = 2 cos(phi) cos(l phi) - cos((l-1) phi).
  const Real c1 = momentCos(phi);
  Real prev = 1, cur = c1, sum = 0;
  for (int l = 1; l <= m; ++l) {
    sum += c[l] * cur;
    const Real next = Real(2) * c1 * cur - prev;
    prev = cur;
    cur = next;
  }
  return c[0] + Real(2) * sum;
}

// fourierAt at kMomentLanes angles phi[0..], the same operations lane by lane.
template <class Real>
VISOPT_HD inline void fourierAtLanes(const Real* c, int m, const Real* phi, Real* out) {
  Real c1[kMomentLanes], prev[kMomentLanes], cur[kMomentLanes], sum[kMomentLanes];
  for (int i = 0; i < kMomentLanes; ++i) {
    c1[i] = momentCos(phi[i]);
    prev[i] = 1;
    cur[i] = c1[i];
    sum[i] = 0;
  }
  for (int l = 1; l <= m; ++l) {
    const Real a = c[l];
    VISOPT_LANE_LOOP
    for (int i = 0; i < kMomentLanes; ++i) {
      sum[i] += a * cur[i];
      const Real next = Real(2) * c1[i] * cur[i] - prev[i];
      prev[i] = cur[i];
      cur[i] = next;
    }
  }
  for (int i = 0; i < kMomentLanes; ++i) out[i] = c[0] + Real(2) * sum[i];
}

// §3.4-3.5: the moments c_{n+1}..c_m of the bounded MESE of c_0..c_n, given their exponential
// moments gamma_0..gamma_n (Eq. 10 extends them with the same q into gamma[n+1..m], Eq. 9 maps
// them back), written into c[n+1..m]. Returns false when c_0..c_n do not form a valid sequence.
VISOPT_HD inline bool extendMomentsFrom(double* c, MomentComplex* gamma, int n, int m) {
  MomentComplex q[kMomentCapacity];
  if (!(c[0] > 0.0 && c[0] < 1.0)) return false;
  const int order = levinson(gamma, n, q);
  if (order < n) return false;
  const MomentComplex seed = exponentialSeed(c[0]);
  for (int l = n + 1; l <= m; ++l) {
    // gamma_l = -(1 / q_0) sum_{j=1}^{n} gamma_{l-n-1+j} q_{n+1-j} (Eq. 10 with k = l - n - 1;
    // its j = 0 term holds q_{n+1} = 0)
    MomentComplex s{0.0, 0.0};
    for (int j = 1; j <= n; ++j) s = s + gamma[l - n - 1 + j] * q[n + 1 - j];
    gamma[l] = (-1.0 / q[0].re) * s;
    c[l] = boundedMomentAt(l, gamma, c, seed);
  }
  return true;
}

// The same from c_0..c_n alone.
VISOPT_HD inline bool extendMoments(double* c, int n, int m) {
  MomentComplex gamma[kMomentCapacity];
  if (!(c[0] > 0.0 && c[0] < 1.0)) return false;
  exponentialMoments(c, n, gamma);
  return extendMomentsFrom(c, gamma, n, m);
}

// §3.5's error of keeping c_0..c_n of c_0..c_m: the rRMSE of the dropped moments against those
// the bounded MESE of the kept ones predicts, relative to c_0, given the exponential moments
// gamma_0..gamma_n of the prefix. Infinite when the prefix is not a valid sequence.
VISOPT_HD inline double truncationErrorFrom(const double* c, const MomentComplex* gamma, int n,
                                            int m) {
  if (n >= m) return 0.0;
  double ext[kMomentCapacity];
  MomentComplex g[kMomentCapacity];
  for (int l = 0; l <= n; ++l) {
    ext[l] = c[l];
    g[l] = gamma[l];
  }
  if (!extendMomentsFrom(ext, g, n, m)) return 1e300;
  double sum = 0.0;
  for (int l = n + 1; l <= m; ++l) sum += (c[l] - ext[l]) * (c[l] - ext[l]);
  return sqrt(sum) / c[0];
}

// The same from c alone (the reference momentCountFor is checked against).
VISOPT_HD inline double truncationError(const double* c, int n, int m) {
  if (n >= m) return 0.0;
  if (!(c[0] > 0.0 && c[0] < 1.0)) return 1e300;
  MomentComplex gamma[kMomentCapacity];
  exponentialMoments(c, n, gamma);
  return truncationErrorFrom(c, gamma, n, m);
}

// The smallest n whose truncation error is at most `threshold`, by bisection over [0, m] (§3.5);
// m when threshold <= 0. Eq. 1 is causal (gamma_l needs c_0..c_l only), so the exponential
// moments of every prefix the bisection tries are those of the whole sequence, computed once.
VISOPT_HD inline int momentCountFor(const double* c, int m, double threshold) {
  if (!(threshold > 0.0)) return m;
  MomentComplex gamma[kMomentCapacity];
  const bool valid = c[0] > 0.0 && c[0] < 1.0;
  if (valid) exponentialMoments(c, m, gamma);
  int lo = 0, hi = m;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    const double e = valid ? truncationErrorFrom(c, gamma, mid, m) : 1e300;  // mid < m
    if (e <= threshold)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

// Adds to c_0..c_m the moments of the piecewise-linear signal through (phi_k, s_k), k = 0..n-1
// (phi increasing, inside [-pi, 0]), §3.2's quadrature [Peters et al. 2019, App. C]. The
// antiderivative of (a phi + b) exp(-i j phi) is F(phi) = (a / j^2 + i s(phi) / j) exp(-i j phi);
// summed over the segments the interior points keep only the jumps of the slope a, so
// c_j += 1/pi [sum_k (a_{k-1} - a_k) cos(j phi_k) / j^2 + (s_last sin(j phi_last) - s_first
// sin(j phi_first)) / j] with a_{-1} = a_{n-1} = 0. Moments of disjoint pieces of a ray add: a
// piece's own end terms make the sum exact.
VISOPT_HD inline void addSegmentMoments(const float* phi, const float* s, int n, int m, double* c) {
  if (n < 2) return;
  double slopePrev = 0.0;
  for (int k = 0; k < n; ++k) {
    double slope = 0.0;
    if (k + 1 < n) {
      const double dphi = double(phi[k + 1]) - double(phi[k]);
      slope = dphi > 0.0 ? (double(s[k + 1]) - double(s[k])) / dphi : 0.0;
      c[0] += dphi * 0.5 * (double(s[k]) + double(s[k + 1])) / kMomentPi;
    }
    const double jump = slopePrev - slope;
    const double end = k == 0 ? -double(s[0]) : (k == n - 1 ? double(s[n - 1]) : 0.0);
    if (jump != 0.0 || end != 0.0) {
      const double p = double(phi[k]);
      const double cr = cos(p), si = sin(p);
      double zr = 1.0, zi = 0.0;  // cos(j p), sin(j p)
      for (int j = 1; j <= m; ++j) {
        const double nr = zr * cr - zi * si, ni = zr * si + zi * cr;
        zr = nr;
        zi = ni;
        const double jj = double(j);
        c[j] += (jump * zr / (jj * jj) + end * zi / jj) / kMomentPi;
      }
    }
    slopePrev = slope;
  }
}

}  // namespace visopt
