// The moment mathematics of Rapp et al. 2022 (kernels/bounded_mese.h) against analytic answers
// and quadrature: moments of known signals, the exponential <-> bounded round trip (the index
// bug of the reference code), Levinson against a dense solve, Eq. 4 (the bounded MESE
// reproduces its moments), its bounds, Eq. 10 (the predicted moments are the MESE's own), and
// the reconstructions of a box, a step and two boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "kernels/bounded_mese.h"
#include "kernels/bounded_mese_batch.h"

namespace visopt {
namespace {

constexpr double kPi = 3.14159265358979323846;

// c_j = 1/pi int_{-pi}^0 s(phi) cos(j phi) dphi by composite Simpson on n intervals per unit
// jump-free piece (the signals below are smooth between their breakpoints, which are passed).
std::vector<double> momentsByQuadrature(const std::function<double(double)>& s, int m,
                                        std::vector<double> breaks, int perPiece = 4000) {
  breaks.insert(breaks.begin(), -kPi);
  breaks.push_back(0.0);
  std::vector<double> c(m + 1, 0.0);
  for (size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double a = breaks[b], e = breaks[b + 1], h = (e - a) / perPiece;
    for (int i = 0; i <= perPiece; ++i) {
      // Each piece's values at its ends are taken from inside it (one-sided limits).
      const double x = a + h * i;
      const double xe = std::clamp(x, a + 1e-12, e - 1e-12);
      const double w = (i == 0 || i == perPiece) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      for (int j = 0; j <= m; ++j) c[j] += w * h / 3.0 * s(xe) * std::cos(j * x) / kPi;
    }
  }
  return c;
}

// The moments of a signal through addSegmentMoments from samples on a uniform grid.
std::vector<double> momentsOfSamples(const std::function<double(double)>& s, int m, int n) {
  std::vector<float> phi(n), v(n);
  for (int k = 0; k < n; ++k) {
    phi[k] = float(-kPi + kPi * k / (n - 1));
    v[k] = float(s(phi[k]));
  }
  std::vector<double> c(m + 1, 0.0);
  addSegmentMoments(phi.data(), v.data(), n, m, c.data());
  return c;
}

// 1/pi int_{-pi}^0 f(phi) cos(j phi) by the trapezoid rule on a fine periodic grid: exact to
// round-off for the smooth periodic f of the bounded MESE.
double momentOf(const std::function<double(double)>& f, int j, int n = 20000) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = -kPi + 2.0 * kPi * (i + 0.5) / n;  // the even extension over [-pi, pi]
    sum += f(x < 0 ? x : -x) * std::cos(j * x);
  }
  return sum / n;  // 1/(2 pi) int_{-pi}^{pi} ... dphi
}

struct Mese {
  std::vector<double> re, im;
  int order = -1;
  double operator()(double phi) const { return meseAt(re.data(), im.data(), order, phi); }
};

Mese meseOf(const std::vector<double>& c) {
  std::vector<MomentComplex> lambda(kMomentCapacity);
  Mese out;
  out.order = boundedMese(c.data(), int(c.size()) - 1, lambda.data());
  for (int l = 0; l <= std::max(out.order, 0); ++l) {
    out.re.push_back(lambda[l].re);
    out.im.push_back(lambda[l].im);
  }
  return out;
}

// A box of height 0.9 on [-2, -1], 0.05 elsewhere (strictly inside (0, 1)).
double box(double phi) {
  return (phi > -2.0 && phi < -1.0) ? 0.9 : 0.05;
}
double step(double phi) {
  return phi > -1.3 ? 0.8 : 0.1;
}
double twoBoxes(double phi) {
  return (phi > -2.8 && phi < -2.3) || (phi > -1.0 && phi < -0.6) ? 0.95 : 0.02;
}

TEST(MomentGeneration, PiecewiseLinearQuadratureIsExactForALinearRamp) {
  // s(phi) = 0.2 + 0.6 (phi + pi) / pi: c_0 = 0.5, c_j = 0.6/pi * (1 - (-1)^j) / (pi j^2) ... by
  // integration by parts: 1/pi int_{-pi}^0 (a phi + b) cos(j phi) = a (1 - (-1)^j) / (pi j^2).
  const double a = 0.6 / kPi;
  auto ramp = [&](double p) { return 0.2 + a * (p + kPi); };
  const std::vector<double> c = momentsOfSamples(ramp, 20, 7);
  EXPECT_NEAR(c[0], 0.5, 1e-7);
  for (int j = 1; j <= 20; ++j)
    EXPECT_NEAR(c[j], a * (1.0 - std::pow(-1.0, j)) / (kPi * j * j), 1e-7) << "j=" << j;
}

TEST(MomentGeneration, SamplesOfASmoothSignalGiveItsMoments) {
  auto smooth = [](double p) { return 0.5 + 0.3 * std::sin(3.0 * p) * std::exp(0.2 * p); };
  const std::vector<double> ref = momentsByQuadrature(smooth, 30, {});
  const std::vector<double> c = momentsOfSamples(smooth, 30, 2001);
  for (int j = 0; j <= 30; ++j) EXPECT_NEAR(c[j], ref[j], 2e-6) << "j=" << j;
}

TEST(MomentGeneration, MomentsOfDisjointPiecesOfARayAdd) {
  auto smooth = [](double p) { return 0.4 + 0.3 * std::cos(2.0 * p + 0.3); };
  const int n = 301, m = 40, cut = 117;
  std::vector<float> phi(n), v(n);
  for (int k = 0; k < n; ++k) {
    phi[k] = float(-kPi + kPi * k / (n - 1));
    v[k] = float(smooth(phi[k]));
  }
  std::vector<double> whole(m + 1, 0.0), parts(m + 1, 0.0);
  addSegmentMoments(phi.data(), v.data(), n, m, whole.data());
  // Two pieces sharing the sample at `cut`, as two bricks of a distributed march would.
  addSegmentMoments(phi.data(), v.data(), cut + 1, m, parts.data());
  addSegmentMoments(phi.data() + cut, v.data() + cut, n - cut, m, parts.data());
  for (int j = 0; j <= m; ++j) EXPECT_NEAR(parts[j], whole[j], 1e-12) << "j=" << j;
}

TEST(BoundedMese, ExponentialAndBoundedMomentsRoundTripAtEveryIndex) {
  const std::vector<double> c = momentsByQuadrature(twoBoxes, 100, {-2.8, -2.3, -1.0, -0.6});
  std::vector<MomentComplex> gamma(101);
  exponentialMoments(c.data(), 100, gamma.data());
  std::vector<double> back(101, 0.0);
  back[0] = c[0];
  const MomentComplex seed = exponentialSeed(c[0]);
  for (int l = 1; l <= 100; ++l) {
    back[l] = boundedMomentAt(l, gamma.data(), back.data(), seed);
    EXPECT_NEAR(back[l], c[l], 1e-6) << "l=" << l;
  }
}

TEST(BoundedMese, LevinsonSolvesTheToeplitzSystem) {
  const int m = 24;
  const std::vector<double> c = momentsByQuadrature(box, m, {-2.0, -1.0});
  std::vector<MomentComplex> gamma(m + 1), q(m + 1);
  exponentialMoments(c.data(), m, gamma.data());
  ASSERT_EQ(levinson(gamma.data(), m, q.data()), m);
  // C(gamma) q = e_0 with C = (gamma_{j-k}) / (2 pi), gamma_{-j} = conj(gamma_j).
  for (int j = 0; j <= m; ++j) {
    MomentComplex row{0.0, 0.0};
    for (int k = 0; k <= m; ++k) {
      const MomentComplex g = j >= k ? gamma[j - k] : conjugate(gamma[k - j]);
      row = row + (1.0 / (2.0 * kPi)) * (g * q[k]);
    }
    EXPECT_NEAR(row.re, j == 0 ? 1.0 : 0.0, 1e-9) << "row " << j;
    EXPECT_NEAR(row.im, 0.0, 1e-9) << "row " << j;
  }
}

TEST(BoundedMese, AConstantIsReconstructedExactly) {
  for (double v : {0.02, 0.25, 0.5, 0.75, 0.97}) {
    std::vector<double> c(11, 0.0);
    c[0] = v;
    const Mese s = meseOf(c);
    ASSERT_EQ(s.order, 10);
    for (double p : {-3.0, -1.5, -0.1}) EXPECT_NEAR(s(p), v, 1e-12) << v << " at " << p;
  }
}

TEST(BoundedMese, ReproducesTheMomentsItWasBuiltFromAndStaysInItsBounds) {
  struct Case {
    const char* name;
    double (*s)(double);
    std::vector<double> breaks;
  };
  const Case cases[] = {{"box", box, {-2.0, -1.0}},
                        {"step", step, {-1.3}},
                        {"two boxes", twoBoxes, {-2.8, -2.3, -1.0, -0.6}}};
  for (const Case& k : cases)
    for (int m : {4, 16, 60}) {
      const std::vector<double> c = momentsByQuadrature(k.s, m, k.breaks);
      const Mese s = meseOf(c);
      ASSERT_EQ(s.order, m) << k.name;
      // Eq. 4: the MESE's own moments are the given ones.
      for (int j = 0; j <= m; ++j)
        EXPECT_NEAR(momentOf(s, j), c[j], 1e-9) << k.name << " m=" << m << " j=" << j;
      for (int i = 0; i <= 2000; ++i) {
        const double v = s(-kPi + kPi * i / 2000.0);
        EXPECT_GT(v, 0.0);
        EXPECT_LT(v, 1.0);
      }
    }
}

TEST(BoundedMese, PredictedMomentsAreThoseOfTheMeseOfThePrefix) {
  const int m = 40;
  const std::vector<double> c = momentsByQuadrature(twoBoxes, m, {-2.8, -2.3, -1.0, -0.6});
  for (int n : {3, 10, 25}) {
    std::vector<double> ext(c.begin(), c.begin() + n + 1);
    ext.resize(m + 1, 0.0);
    ASSERT_TRUE(extendMoments(ext.data(), n, m));
    const Mese s = meseOf(std::vector<double>(c.begin(), c.begin() + n + 1));
    for (int l = n + 1; l <= m; ++l)
      EXPECT_NEAR(ext[l], momentOf(s, l), 1e-8) << "n=" << n << " l=" << l;
  }
}

// Mean absolute error of a reconstruction against the signal over [-pi, 0], away from its jumps
// (within 0.15 of a breakpoint both ring or blur).
double meanError(const std::function<double(double)>& r, double (*s)(double),
                 const std::vector<double>& breaks) {
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i <= 3000; ++i) {
    const double p = -kPi + kPi * i / 3000.0;
    bool near = false;
    for (double b : breaks) near |= std::abs(p - b) < 0.15;
    if (near) continue;
    sum += std::abs(r(p) - s(p));
    ++count;
  }
  return sum / count;
}

TEST(BoundedMese, ReconstructsABoxAStepAndTwoBoxesBetterThanTheFourierSeries) {
  struct Case {
    const char* name;
    double (*s)(double);
    std::vector<double> breaks;
    double meseBound, fourierBound;  // mean absolute error away from the jumps, measured
  };
  // With 30 moments (m = 30). The Fourier series rings; the MESE stays close to the plateaus.
  const Case cases[] = {{"box", box, {-2.0, -1.0}, 0.01, 0.04},
                        {"step", step, {-1.3}, 0.01, 0.04},
                        {"two boxes", twoBoxes, {-2.8, -2.3, -1.0, -0.6}, 0.02, 0.06}};
  for (const Case& k : cases) {
    const std::vector<double> c = momentsByQuadrature(k.s, 30, k.breaks);
    const Mese mese = meseOf(c);
    auto fourier = [&](double p) { return fourierAt(c.data(), 30, p); };
    const double em = meanError(mese, k.s, k.breaks), ef = meanError(fourier, k.s, k.breaks);
    EXPECT_LT(em, k.meseBound) << k.name;
    EXPECT_LT(ef, k.fourierBound) << k.name;
    EXPECT_LT(em, ef) << k.name;
    // Gibbs: the Fourier series over- and undershoots the plateaus by ~9 % of the jump; the MESE
    // rings too, but less (2-6 % measured).
    double lo = 1.0, hi = 0.0, fMin = 1.0, fMax = 0.0, mMin = 1.0, mMax = 0.0;
    for (int i = 0; i <= 3000; ++i) {
      const double p = -kPi + kPi * i / 3000.0;
      lo = std::min(lo, k.s(p));
      hi = std::max(hi, k.s(p));
      fMin = std::min(fMin, fourier(p));
      fMax = std::max(fMax, fourier(p));
      mMin = std::min(mMin, mese(p));
      mMax = std::max(mMax, mese(p));
    }
    const double jump = hi - lo;
    const double fourierOvershoot = std::max(lo - fMin, fMax - hi);
    EXPECT_GT(fourierOvershoot, 0.06 * jump) << k.name;
    EXPECT_LT(std::max(lo - mMin, mMax - hi), 0.7 * fourierOvershoot) << k.name;
  }
}

TEST(BoundedMese, MomentCountMeetsTheThresholdAndBisectionFindsTheSmallest) {
  const int m = 60;
  const std::vector<double> smoothC =
      momentsByQuadrature([](double p) { return 0.5 + 0.2 * std::cos(p); }, m, {});
  const std::vector<double> boxC = momentsByQuadrature(box, m, {-2.0, -1.0});
  for (const auto* c : {&smoothC, &boxC})
    for (double threshold : {0.1, 0.01, 0.001}) {
      const int n = momentCountFor(c->data(), m, threshold);
      EXPECT_LE(truncationError(c->data(), n, m), threshold);
      if (n > 0) {
        EXPECT_GT(truncationError(c->data(), n - 1, m), threshold);
      }
    }
  // A smooth signal needs few moments (3 here: the MESE of c_0, c_1 is not itself a cosine), a
  // box many.
  EXPECT_LE(momentCountFor(smoothC.data(), m, 0.001), 3);
  EXPECT_GT(momentCountFor(boxC.data(), m, 0.001), 10);
  EXPECT_EQ(momentCountFor(boxC.data(), m, 0.0), m);
}

// momentCountFor computes Eq. 1 once for all bisection steps; the reference bisection below
// recomputes it per step through truncationError. Same counts on signals of 1 to 6 random
// raised-cosine bumps of random widths over a ramp (density within (0, 1)), and for the invalid
// c_0 of an empty ray.
TEST(BoundedMese, MomentCountEqualsTheBisectionOverTruncationError) {
  const int m = 48;
  uint32_t state = 12345u;
  auto uniform = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  auto reference = [m](const double* c, double threshold) {
    int lo = 0, hi = m;
    while (lo < hi) {
      const int mid = (lo + hi) / 2;
      if (truncationError(c, mid, m) <= threshold)
        hi = mid;
      else
        lo = mid + 1;
    }
    return lo;
  };
  int distinct = 0, previous = -1;
  for (int trial = 0; trial < 40; ++trial) {
    const int bumps = 1 + trial % 6;
    std::vector<double> centre, width, height;
    for (int b = 0; b < bumps; ++b) {
      centre.push_back(-kPi * uniform());
      width.push_back(0.05 + 1.2 * uniform());
      height.push_back((0.1 + 0.8 * uniform()) * 0.85 / bumps);
    }
    auto signal = [&](double phi) {
      double v = 0.1 + 0.02 * phi;  // a ramp under the bumps, 0.037 at phi = -pi
      for (int b = 0; b < bumps; ++b) {
        const double u = (phi - centre[b]) / width[b];
        if (std::abs(u) < 1.0) v += height[b] * 0.5 * (1.0 + std::cos(kPi * u));
      }
      return v;
    };
    const std::vector<double> c = momentsOfSamples(signal, m, 2000);
    for (double threshold : {0.05, 0.01, 0.002}) {
      const int n = momentCountFor(c.data(), m, threshold);
      EXPECT_EQ(n, reference(c.data(), threshold)) << "trial " << trial << " at " << threshold;
      distinct += n != previous;
      previous = n;
    }
  }
  EXPECT_GT(distinct, 20);  // the signals span many counts, not one answer repeated
  std::vector<double> empty(m + 1, 0.0);
  EXPECT_EQ(momentCountFor(empty.data(), m, 0.01), reference(empty.data(), 0.01));
}

// The renderer evaluates Eq. 3 and the Fourier series kMomentLanes angles at a time; each lane
// must be the scalar evaluation at its angle (the same operations: equal to float round-off) for
// the multipliers of real moment sequences of orders 0 to 100.
TEST(BoundedMese, LaneEvaluationIsTheScalarOneAtEachAngle) {
  uint32_t state = 777u;
  auto uniform = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  int compared = 0;
  for (int m : {0, 1, 2, 7, 16, 35, 64, 100}) {
    const double centre = -kPi * uniform(), width = 0.2 + uniform();
    const std::vector<double> c = momentsOfSamples(
        [&](double p) {
          const double u = (p - centre) / width;
          return 0.1 + (std::abs(u) < 1.0 ? 0.7 * 0.5 * (1.0 + std::cos(kPi * u)) : 0.0);
        },
        m, 1500);
    MomentComplex lambda[kMomentCapacity];
    const int order = boundedMese(c.data(), m, lambda);
    ASSERT_GE(order, 0) << m;
    std::vector<float> re(order + 1), im(order + 1), cf(m + 1);
    for (int l = 0; l <= order; ++l) {
      re[l] = float(lambda[l].re);
      im[l] = float(lambda[l].im);
    }
    for (int l = 0; l <= m; ++l) cf[l] = float(c[l]);
    for (int block = 0; block < 8; ++block) {
      float phi[kMomentLanes], mese[kMomentLanes], fourier[kMomentLanes];
      for (int i = 0; i < kMomentLanes; ++i) phi[i] = float(-kPi * uniform());
      meseAtLanes(re.data(), im.data(), order, phi, mese);
      fourierAtLanes(cf.data(), m, phi, fourier);
      for (int i = 0; i < kMomentLanes; ++i) {
        EXPECT_NEAR(mese[i], meseAt(re.data(), im.data(), order, phi[i]), 2e-6f)
            << "order " << order << " phi " << phi[i];
        EXPECT_NEAR(fourier[i], fourierAt(cf.data(), m, phi[i]), 2e-6f)
            << "m " << m << " phi " << phi[i];
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 8 * 8 * kMomentLanes);
}

// boundedMeseBatch computes kMeseBatch pixels' multipliers side by side; each lane must be
// boundedMese of that pixel: the same order (also where Levinson stops early on moments that are
// no valid sequence, and -1 for an invalid c_0 or an empty lane) and the same multipliers to
// double round-off.
TEST(BoundedMese, TheBatchIsBoundedMesePerPixel) {
  uint32_t state = 4242u;
  auto uniform = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  int earlyStops = 0, invalid = 0, checked = 0;
  for (int round = 0; round < 6; ++round) {
    MeseBatch batch;
    std::vector<std::vector<double>> seqs(kMeseBatch);
    for (int b = 0; b < kMeseBatch; ++b) {
      const int kind = (round * kMeseBatch + b) % 11;
      int m = int(uniform() * 100.0);
      if (kind == 0) m = 0;
      if (kind == 1) m = -1;  // an empty lane
      batch.m[b] = m;
      if (m < 0) continue;
      const double centre = -kPi * uniform(), width = 0.1 + uniform();
      seqs[b] = momentsOfSamples(
          [&](double p) {
            const double u = (p - centre) / width;
            return 0.05 + (std::abs(u) < 1.0 ? 0.8 * 0.5 * (1.0 + std::cos(kPi * u)) : 0.0);
          },
          m, 1200);
      if (kind == 2 && m > 4) seqs[b][m / 2] += 0.6;  // no longer a valid sequence past m / 2
      if (kind == 3) seqs[b][0] = 0.0;                // c_0 outside (0, 1)
    }
    for (int b = 0; b < kMeseBatch; ++b)
      for (int l = 0; l < kMomentCapacity; ++l)
        batch.c[l * kMeseBatch + b] = l <= batch.m[b] ? seqs[b][l] : 0.0;
    boundedMeseBatch(batch);
    for (int b = 0; b < kMeseBatch; ++b) {
      if (batch.m[b] < 0) {
        EXPECT_EQ(batch.order[b], -1);
        continue;
      }
      MomentComplex lambda[kMomentCapacity];
      const int order = boundedMese(seqs[b].data(), batch.m[b], lambda);
      ASSERT_EQ(batch.order[b], order) << "round " << round << " lane " << b;
      earlyStops += order >= 0 && order < batch.m[b];
      invalid += order < 0;
      for (int l = 0; l <= order; ++l) {
        const double re = batch.lambdaRe[l * kMeseBatch + b],
                     im = batch.lambdaIm[l * kMeseBatch + b];
        EXPECT_NEAR(re, lambda[l].re, 1e-9 * (1.0 + std::abs(lambda[l].re))) << b << " " << l;
        EXPECT_NEAR(im, lambda[l].im, 1e-9 * (1.0 + std::abs(lambda[l].im))) << b << " " << l;
        ++checked;
      }
    }
  }
  EXPECT_GT(earlyStops, 0);
  EXPECT_GT(invalid, 0);
  EXPECT_GT(checked, 500);
}

TEST(BoundedMese, InvalidMomentsAreRefusedNotReconstructed) {
  std::vector<double> c(5, 0.0);
  c[0] = 1.2;  // the mean of a signal in [0, 1] cannot exceed 1
  std::vector<MomentComplex> lambda(kMomentCapacity);
  EXPECT_EQ(boundedMese(c.data(), 4, lambda.data()), -1);
  // |c_1| too large for the mean: the sequence is invalid from order 1 on.
  c = {0.5, 0.45, 0.0, 0.0, 0.0};
  EXPECT_EQ(boundedMese(c.data(), 4, lambda.data()), 0);
}

}  // namespace
}  // namespace visopt
