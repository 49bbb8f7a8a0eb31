// SSIM on sRGB luma (visopt/image_metrics.h): separable Gaussian window over the valid positions.
#include "visopt/error.h"
#include "visopt/image_metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace visopt {

namespace {

constexpr int kRadius = 5;  // 11x11 window
constexpr double kSigma = 1.5;

float encodeSrgb(float linear) {
  const float c = linear > 0.f ? std::min(linear, 1.f) : 0.f;  // NaN -> 0, as writePng
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
}

std::array<double, 2 * kRadius + 1> gaussianWeights() {
  std::array<double, 2 * kRadius + 1> w{};
  double sum = 0.0;
  for (int i = -kRadius; i <= kRadius; ++i) {
    w[static_cast<size_t>(i + kRadius)] = std::exp(-0.5 * i * i / (kSigma * kSigma));
    sum += w[static_cast<size_t>(i + kRadius)];
  }
  for (double& v : w) v /= sum;
  return w;
}

// Separable Gaussian filter over the "valid" window positions: the output is
// (width - 2 r) x (height - 2 r), entry (x, y) centred on input pixel (x + r, y + r).
std::vector<double> filterValid(const std::vector<double>& in, int width, int height) {
  static const auto w = gaussianWeights();
  const int ow = width - 2 * kRadius, oh = height - 2 * kRadius;
  std::vector<double> rows(static_cast<size_t>(ow) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < ow; ++x) {
      double s = 0.0;
      for (int k = 0; k <= 2 * kRadius; ++k)
        s += w[static_cast<size_t>(k)] * in[static_cast<size_t>(y) * width + (x + k)];
      rows[static_cast<size_t>(y) * ow + x] = s;
    }
  std::vector<double> out(static_cast<size_t>(ow) * oh);
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      double s = 0.0;
      for (int k = 0; k <= 2 * kRadius; ++k)
        s += w[static_cast<size_t>(k)] * rows[static_cast<size_t>(y + k) * ow + x];
      out[static_cast<size_t>(y) * ow + x] = s;
    }
  return out;
}

// Luma of the sRGB-encoded image (Rec. 709 weights on the encoded channels, each clamped to
// [0, 1] first), row-major: the values a display shows, as PSNR uses them.
std::vector<float> srgbLuma(const Image& image) {
  std::vector<float> y(image.pixels.size());
  for (size_t i = 0; i < y.size(); ++i) {
    const glm::vec3& p = image.pixels[i];
    y[i] = 0.2126f * encodeSrgb(p.r) + 0.7152f * encodeSrgb(p.g) + 0.0722f * encodeSrgb(p.b);
  }
  return y;
}

}  // namespace

bool ssimApplies(const Image& a) {
  return a.width > 2 * kRadius && a.height > 2 * kRadius;
}

double ssim(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size())
    throw Error(ErrorKind::Usage, "ssim: the images differ in size");
  if (!ssimApplies(a))
    throw Error(ErrorKind::Usage, "ssim: the images are smaller than the 11x11 window");
  const std::vector<float> la = srgbLuma(a), lb = srgbLuma(b);
  const size_t n = la.size();
  std::vector<double> x(n), y(n), xx(n), yy(n), xy(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = la[i];
    y[i] = lb[i];
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const int w = a.width, h = a.height;
  const std::vector<double> mx = filterValid(x, w, h), my = filterValid(y, w, h);
  const std::vector<double> mxx = filterValid(xx, w, h), myy = filterValid(yy, w, h);
  const std::vector<double> mxy = filterValid(xy, w, h);
  constexpr double c1 = (0.01 * 1.0) * (0.01 * 1.0), c2 = (0.03 * 1.0) * (0.03 * 1.0);
  double sum = 0.0;
  for (size_t i = 0; i < mx.size(); ++i) {
    const double vx = mxx[i] - mx[i] * mx[i], vy = myy[i] - my[i] * my[i];
    const double cov = mxy[i] - mx[i] * my[i];
    sum += ((2.0 * mx[i] * my[i] + c1) * (2.0 * cov + c2)) /
           ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
  }
  return sum / static_cast<double>(mx.size());
}

}  // namespace visopt
