// LDR-ꟻLIP (Andersson et al., "ꟻLIP: A Difference Evaluator for Alternating Images", HPG 2020),
// written from the paper. Two pipelines per pixel, both on the images as a display shows them:
//  - colour: the opponent space YyCxCz, filtered by the contrast sensitivity functions of the
//    achromatic, red-green and blue-yellow channels (a sum of Gaussians each, spread set by the
//    pixels per degree), back to linear RGB clamped to the RGB cube, CIELAB with the Hunt effect
//    (a, b scaled by L/100), the HyAB distance |dL| + ||(da, db)||, raised to q_c = 0.7 and
//    remapped so that p_c = 0.4 of the largest colour distance in the gamut (Hunt-adjusted green
//    against blue) maps to p_t = 0.95;
//  - features: edges (first Gaussian derivative) and points (second derivative) of the
//    normalised luminance, spread 0.5 * 0.082 degrees; the larger of the two magnitude
//    differences, over sqrt(2), raised to q_f = 0.5;
// and the error is colour^(1 - feature). Filters are separable and clamp to the edge.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/glm.hpp>

#include "visopt/error.h"
#include "visopt/image_metrics.h"

namespace visopt {

namespace {

constexpr float kQc = 0.7f, kQf = 0.5f, kPc = 0.4f, kPt = 0.95f;
// Contrast sensitivity: S(x) = sum_i a_i sqrt(pi / b_i) exp(-pi^2 x^2 / b_i), x in degrees, for
// the achromatic, red-green and blue-yellow channels (the first two have one Gaussian).
constexpr float kCsfA1[3] = {1.f, 1.f, 34.1f}, kCsfB1[3] = {0.0047f, 0.0053f, 0.04f};
constexpr float kCsfA2Blue = 13.5f, kCsfB2Blue = 0.025f;
constexpr float kFeatureWidthDegrees = 0.082f;  // peak to trough of the edge detector

// Linear sRGB primaries to CIE XYZ (D65) and back; the white point is the image of (1, 1, 1).
const glm::dmat3& rgbToXyz() {
  // glm is column-major: each glm::dvec3 below is a column.
  static const glm::dmat3 m(
      glm::dvec3(10135552.0 / 24577794, 2613072.0 / 12288897, 1425312.0 / 73733382),
      glm::dvec3(8788810.0 / 24577794, 8788810.0 / 12288897, 8788810.0 / 73733382),
      glm::dvec3(4435075.0 / 24577794, 887015.0 / 12288897, 70074185.0 / 73733382));
  return m;
}

struct ColourSpace {
  glm::mat3 toXyz, toRgb;
  glm::vec3 white;
  ColourSpace()
      : toXyz(rgbToXyz()), toRgb(glm::inverse(rgbToXyz())), white(rgbToXyz() * glm::dvec3(1.0)) {}
};
const ColourSpace& space() {
  static const ColourSpace s;
  return s;
}

// CIELAB of linear RGB, then the Hunt effect: chroma fades with lightness.
glm::vec3 huntLab(const glm::vec3& rgb) {
  const glm::vec3 t = space().toXyz * rgb / space().white;
  constexpr float delta = 6.f / 29.f;
  auto f = [&](float v) {
    return v > delta * delta * delta ? std::cbrt(v) : v / (3.f * delta * delta) + 4.f / 29.f;
  };
  const float fx = f(t.x), fy = f(t.y), fz = f(t.z);
  const float l = 116.f * fy - 16.f;
  return {l, 0.01f * l * 500.f * (fx - fy), 0.01f * l * 200.f * (fy - fz)};
}

float hyab(const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 d = a - b;
  return std::abs(d.x) + std::sqrt(d.y * d.y + d.z * d.z);
}

// 1-D kernel k[t], t in [-radius, radius], stored at k[t + radius].
using Kernel = std::vector<float>;

// out(x, y) = sum_t k(t) in(clamp(x + t), y)
void filterRows(const std::vector<float>& in, std::vector<float>& out, int w, int h,
                const Kernel& k) {
  const int r = int(k.size() / 2);
  out.resize(in.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const float* src = in.data() + size_t(y) * size_t(w);
      float* dst = out.data() + size_t(y) * size_t(w);
      for (int x = 0; x < w; ++x) {
        float s = 0.f;
        for (int t = -r; t <= r; ++t) s += k[size_t(t + r)] * src[std::clamp(x + t, 0, w - 1)];
        dst[x] = s;
      }
    }
  });
}

// out(x, y) = sum_t k(t) in(x, clamp(y + t))
void filterColumns(const std::vector<float>& in, std::vector<float>& out, int w, int h,
                   const Kernel& k) {
  const int r = int(k.size() / 2);
  out.resize(in.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      float* dst = out.data() + size_t(y) * size_t(w);
      std::fill(dst, dst + w, 0.f);
      for (int t = -r; t <= r; ++t) {
        const float* src = in.data() + size_t(std::clamp(y + t, 0, h - 1)) * size_t(w);
        const float kt = k[size_t(t + r)];
        for (int x = 0; x < w; ++x) dst[x] += kt * src[x];
      }
    }
  });
}

std::vector<float> separable(const std::vector<float>& in, int w, int h, const Kernel& kx,
                             const Kernel& ky) {
  std::vector<float> tmp, out;
  filterRows(in, tmp, w, h, kx);
  filterColumns(tmp, out, w, h, ky);
  return out;
}

// The colour pipeline's spatial filters. One radius for all channels, from the widest Gaussian.
struct CsfKernels {
  Kernel achromatic, redGreen, blue1, blue2;   // each sums to 1
  float blueWeight1 = 0.f, blueWeight2 = 0.f;  // blue = w1 * (blue1 x blue1) + w2 * (blue2 x blue2)
};
CsfKernels csfKernels(double ppd) {
  const float widest = std::max(kCsfB1[2], kCsfB2Blue);
  const int r =
      int(std::ceil(3.0 * std::sqrt(widest / (2.0 * std::numbers::pi * std::numbers::pi)) * ppd));
  const float dx = float(1.0 / ppd), pi2 = float(std::numbers::pi * std::numbers::pi);
  auto gaussian = [&](float b, float& sum) {
    Kernel k(size_t(2 * r + 1));
    sum = 0.f;
    for (int t = -r; t <= r; ++t) {
      const float x = float(t) * dx;
      k[size_t(t + r)] = std::exp(-pi2 * x * x / b);
      sum += k[size_t(t + r)];
    }
    for (float& v : k) v /= sum;
    return k;
  };
  CsfKernels c;
  float s0, s1, s2, s3;
  c.achromatic = gaussian(kCsfB1[0], s0);
  c.redGreen = gaussian(kCsfB1[1], s1);
  c.blue1 = gaussian(kCsfB1[2], s2);
  c.blue2 = gaussian(kCsfB2Blue, s3);
  // The 2-D blue-yellow filter a1 sqrt(pi/b1) g1(x) g1(y) + a2 sqrt(pi/b2) g2(x) g2(y),
  // normalised to sum 1: each separable part sums to s^2 before the per-kernel normalisation.
  const float amp1 = kCsfA1[2] * std::sqrt(float(std::numbers::pi) / kCsfB1[2]) * s2 * s2;
  const float amp2 = kCsfA2Blue * std::sqrt(float(std::numbers::pi) / kCsfB2Blue) * s3 * s3;
  c.blueWeight1 = amp1 / (amp1 + amp2);
  c.blueWeight2 = amp2 / (amp1 + amp2);
  return c;
}

// The feature pipeline's kernels: the Gaussian and its first and second derivatives, each
// derivative's positive weights scaled to sum 1 and its negative ones to sum -1.
struct FeatureKernels {
  Kernel g, dg, ddg;
};
FeatureKernels featureKernels(double ppd) {
  const float sd = float(0.5 * kFeatureWidthDegrees * ppd);
  const int r = int(std::ceil(3.f * sd));
  FeatureKernels f;
  f.g.resize(size_t(2 * r + 1));
  f.dg.resize(f.g.size());
  f.ddg.resize(f.g.size());
  float gSum = 0.f, dgPos = 0.f, dgNeg = 0.f, ddgPos = 0.f, ddgNeg = 0.f;
  for (int t = -r; t <= r; ++t) {
    const float x = float(t), g = std::exp(-x * x / (2.f * sd * sd));
    const float dg = -x * g, ddg = (x * x / (sd * sd) - 1.f) * g;
    f.g[size_t(t + r)] = g;
    f.dg[size_t(t + r)] = dg;
    f.ddg[size_t(t + r)] = ddg;
    gSum += g;
    (dg > 0.f ? dgPos : dgNeg) += std::abs(dg);
    (ddg > 0.f ? ddgPos : ddgNeg) += std::abs(ddg);
  }
  for (size_t i = 0; i < f.g.size(); ++i) {
    f.g[i] /= gSum;
    f.dg[i] /= f.dg[i] > 0.f ? dgPos : dgNeg;
    f.ddg[i] /= f.ddg[i] > 0.f ? ddgPos : ddgNeg;
  }
  return f;
}

// One image in the opponent space, planar, and its normalised luminance for the features.
struct Opponent {
  std::vector<float> y, cx, cz;  // YyCxCz: Yy = 116 Y/Yn - 16, Cx = 500 (X/Xn - Y/Yn), ...
  std::vector<float> luminance;  // Y / Yn = (Yy + 16) / 116
};
Opponent toOpponent(const Image& image) {
  const size_t n = image.pixels.size();
  Opponent o;
  o.y.resize(n);
  o.cx.resize(n);
  o.cz.resize(n);
  o.luminance.resize(n);
  const ColourSpace& cs = space();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        glm::vec3 c = image.pixels[i];
                        for (int k = 0; k < 3; ++k)
                          c[k] = c[k] > 0.f ? std::min(c[k], 1.f) : 0.f;  // NaN -> 0
                        const glm::vec3 t = cs.toXyz * c / cs.white;
                        o.y[i] = 116.f * t.y - 16.f;
                        o.cx[i] = 500.f * (t.x - t.y);
                        o.cz[i] = 200.f * (t.y - t.z);
                        o.luminance[i] = (o.y[i] + 16.f) / 116.f;
                      }
                    });
  return o;
}

// The colour pipeline's per-pixel Hunt-adjusted CIELAB of the CSF-filtered image.
std::vector<glm::vec3> filteredLab(const Opponent& o, int w, int h, const CsfKernels& k) {
  const std::vector<float> y = separable(o.y, w, h, k.achromatic, k.achromatic);
  const std::vector<float> cx = separable(o.cx, w, h, k.redGreen, k.redGreen);
  const std::vector<float> cz1 = separable(o.cz, w, h, k.blue1, k.blue1);
  const std::vector<float> cz2 = separable(o.cz, w, h, k.blue2, k.blue2);
  std::vector<glm::vec3> lab(y.size());
  const ColourSpace& cs = space();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, lab.size(), 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        const float cz = k.blueWeight1 * cz1[i] + k.blueWeight2 * cz2[i];
                        const float ty = (y[i] + 16.f) / 116.f;
                        const glm::vec3 t(cx[i] / 500.f + ty, ty, ty - cz / 200.f);
                        glm::vec3 rgb = cs.toRgb * (t * cs.white);
                        rgb = glm::clamp(rgb, glm::vec3(0.f), glm::vec3(1.f));
                        lab[i] = huntLab(rgb);
                      }
                    });
  return lab;
}

// Edge and point magnitudes of the normalised luminance.
struct Features {
  std::vector<float> edge, point;
};
Features features(const std::vector<float>& lum, int w, int h, const FeatureKernels& k) {
  std::vector<float> rg, rdg, rddg;
  filterRows(lum, rg, w, h, k.g);
  filterRows(lum, rdg, w, h, k.dg);
  filterRows(lum, rddg, w, h, k.ddg);
  std::vector<float> ex, ey, px, py;
  filterColumns(rdg, ex, w, h, k.g);
  filterColumns(rg, ey, w, h, k.dg);
  filterColumns(rddg, px, w, h, k.g);
  filterColumns(rg, py, w, h, k.ddg);
  Features f;
  f.edge.resize(lum.size());
  f.point.resize(lum.size());
  for (size_t i = 0; i < lum.size(); ++i) {
    f.edge[i] = std::sqrt(ex[i] * ex[i] + ey[i] * ey[i]);
    f.point[i] = std::sqrt(px[i] * px[i] + py[i] * py[i]);
  }
  return f;
}

void summarise(FlipResult& r) {
  double sum = 0.0;
  for (float e : r.error) sum += e;
  r.mean = sum / double(r.error.size());
  std::vector<float> sorted = r.error;
  std::sort(sorted.begin(), sorted.end());
  const size_t n = sorted.size();
  r.max = sorted.back();
  r.p95 = sorted[size_t(std::ceil(0.95 * double(n))) - 1];
  double running = 0.0;
  r.weightedMedian = 0.0;
  for (float e : sorted) {
    running += e;
    if (running > 0.5 * sum) {
      r.weightedMedian = e;
      break;
    }
  }
}

}  // namespace

double pixelsPerDegree(double distanceM, double widthM, double columns) {
  return distanceM * columns / widthM * std::numbers::pi / 180.0;
}

double flipDefaultPixelsPerDegree() {
  return pixelsPerDegree(0.7, 0.7, 3840.0);
}

FlipResult flip(const Image& reference, const Image& test, double ppd) {
  if (reference.width != test.width || reference.height != test.height ||
      reference.pixels.size() != test.pixels.size())
    throw Error(ErrorKind::Usage,
                "flip: the images differ in size (" + std::to_string(reference.width) + "x" +
                    std::to_string(reference.height) + " vs " + std::to_string(test.width) + "x" +
                    std::to_string(test.height) + ")");
  if (reference.pixels.empty() ||
      reference.pixels.size() != size_t(reference.width) * size_t(reference.height))
    throw Error(ErrorKind::Usage, "flip: empty or inconsistent images");
  if (!(ppd > 0.0) || !std::isfinite(ppd))
    throw Error(ErrorKind::Usage, "flip: pixels per degree must be positive and finite");
  const int w = reference.width, h = reference.height;
  const Opponent oa = toOpponent(reference), ob = toOpponent(test);

  const CsfKernels csf = csfKernels(ppd);
  const std::vector<glm::vec3> la = filteredLab(oa, w, h, csf), lb = filteredLab(ob, w, h, csf);
  const float cmax = std::pow(hyab(huntLab({0.f, 1.f, 0.f}), huntLab({0.f, 0.f, 1.f})), kQc);
  const float knee = kPc * cmax;

  const FeatureKernels fk = featureKernels(ppd);
  const Features fa = features(oa.luminance, w, h, fk), fb = features(ob.luminance, w, h, fk);

  FlipResult r;
  r.width = w;
  r.height = h;
  r.error.resize(reference.pixels.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, r.error.size(), 4096),
      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
          float colour = std::pow(hyab(la[i], lb[i]), kQc);
          colour = colour < knee ? colour * kPt / knee
                                 : kPt + (colour - knee) / (cmax - knee) * (1.f - kPt);
          const float feature = std::pow(
              std::max(std::abs(fa.edge[i] - fb.edge[i]), std::abs(fa.point[i] - fb.point[i])) /
                  float(std::numbers::sqrt2),
              kQf);
          r.error[i] = std::pow(colour, 1.f - feature);
        }
      });
  summarise(r);
  return r;
}

}  // namespace visopt
