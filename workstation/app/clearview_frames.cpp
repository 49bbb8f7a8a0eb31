// oneTBB before any Qt header: Qt's `emit` macro breaks TBB's profiling header.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "clearview_frames.h"

namespace visopt::ws {

namespace {

// The library's encoding (io/png_image.cpp), operation for operation: the tables below are
// derived from it, so the fast path gives its bytes exactly.
uint8_t encodeSrgb(float linear) {
  if (!(linear > 0.f)) return 0;  // also NaN
  if (linear >= 1.f) return 255;
  const float e =
      linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(std::clamp(e, 0.f, 1.f) * 255.f));
}

// thresholds[k] is the smallest positive float that encodes to k + 1 or more; the encoding is
// monotonic, so a value's code is the number of thresholds at or below it. Found by bisection on
// the bit patterns of the positive floats, which order like the floats.
const std::array<float, 255>& thresholds() {
  static const std::array<float, 255> table = [] {
    std::array<float, 255> t{};
    for (int k = 1; k <= 255; ++k) {
      uint32_t lo = 0, hi = std::bit_cast<uint32_t>(1.f);  // encode(lo) < k <= encode(hi)
      while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (encodeSrgb(std::bit_cast<float>(mid)) >= k)
          hi = mid;
        else
          lo = mid;
      }
      t[size_t(k - 1)] = std::bit_cast<float>(hi);
    }
    return t;
  }();
  return table;
}

// The code of the smallest float in each bucket of floats in [0, 1) that share their top 17 bits
// (exponent and 8 bits of mantissa). A bucket is narrower than the distance between two
// thresholds wherever they lie, so a value's code is its bucket's or, past a threshold inside
// the bucket, one more.
constexpr int kBucketShift = 15;
struct Encoder {
  std::array<float, 255> thresholds;
  std::vector<uint8_t> bucketCode;
};

const Encoder& encoder() {
  static const Encoder e = [] {
    Encoder out;
    out.thresholds = thresholds();
    const uint32_t buckets = std::bit_cast<uint32_t>(1.f) >> kBucketShift;
    out.bucketCode.resize(buckets);
    for (uint32_t b = 0; b < buckets; ++b) {
      const float lowest = std::bit_cast<float>(b << kBucketShift);
      out.bucketCode[b] = static_cast<uint8_t>(
          std::upper_bound(out.thresholds.begin(), out.thresholds.end(), lowest) -
          out.thresholds.begin());
    }
    return out;
  }();
  return e;
}

inline uint8_t encodeFast(const Encoder& e, float linear) {
  if (!(linear > 0.f)) return 0;  // also NaN
  if (linear >= 1.f) return 255;
  unsigned code = e.bucketCode[std::bit_cast<uint32_t>(linear) >> kBucketShift];
  while (code < 255 && linear >= e.thresholds[code]) ++code;
  return static_cast<uint8_t>(code);
}

}  // namespace

bool sameHotspotSettings(const ClearViewSettings& a, const ClearViewSettings& b) {
  return a.context == b.context && a.focus == b.focus && a.volumeLayer == b.volumeLayer &&
         a.measure == b.measure && a.contextShader == b.contextShader &&
         a.focusShader == b.focusShader && a.size == b.size && a.weight == b.weight &&
         a.distanceScale == b.distanceScale && a.border == b.border && a.ambient == b.ambient &&
         a.headlight == b.headlight && a.contextColor == b.contextColor &&
         a.focusColor == b.focusColor && a.background == b.background;
}

QImage toDisplayImage(const Image& image) {
  QImage out(image.width, image.height, QImage::Format_RGBA8888);
  if (out.isNull() || image.pixels.size() != size_t(image.width) * size_t(image.height)) return {};
  const Encoder& t = encoder();
  uchar* bits = out.bits();  // detached here, once, not per row on the worker threads
  const qsizetype stride = out.bytesPerLine();
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height, 16),
                    [&](const tbb::blocked_range<int>& rows) {
                      for (int y = rows.begin(); y != rows.end(); ++y) {
                        uchar* line = bits + qsizetype(y) * stride;
                        const glm::vec3* in = image.pixels.data() + size_t(y) * size_t(image.width);
                        for (int x = 0; x < image.width; ++x) {
                          line[4 * x + 0] = encodeFast(t, in[x].r);
                          line[4 * x + 1] = encodeFast(t, in[x].g);
                          line[4 * x + 2] = encodeFast(t, in[x].b);
                          line[4 * x + 3] = 255;
                        }
                      }
                    });
  return out;
}

}  // namespace visopt::ws
