#include "io/srgb_encode.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace visopt::io {

namespace {

// Floats in [0, 1) that share their top 17 bits (exponent and 8 bits of mantissa) form a bucket;
// a bucket is narrower than the distance between two thresholds wherever they lie, so a value's
// code is its bucket's or, past a threshold inside the bucket, one more.
constexpr int kBucketShift = 15;

}  // namespace

uint8_t encodeSrgbReference(float linear) {
  if (!(linear > 0.f)) return 0;  // also NaN
  if (linear >= 1.f) return 255;
  const float e =
      linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(std::clamp(e, 0.f, 1.f) * 255.f));
}

SrgbEncoder::SrgbEncoder() {
  // Bisection on the bit patterns of the positive floats, which order like the floats; the
  // reference is monotonic, so a value's code is the number of thresholds at or below it.
  for (int k = 1; k <= 255; ++k) {
    uint32_t lo = 0, hi = std::bit_cast<uint32_t>(1.f);  // reference(lo) < k <= reference(hi)
    while (hi - lo > 1) {
      const uint32_t mid = lo + (hi - lo) / 2;
      if (encodeSrgbReference(std::bit_cast<float>(mid)) >= k)
        hi = mid;
      else
        lo = mid;
    }
    thresholds_[size_t(k - 1)] = std::bit_cast<float>(hi);
  }
  const uint32_t buckets = std::bit_cast<uint32_t>(1.f) >> kBucketShift;
  bucketCode_.resize(buckets);
  for (uint32_t b = 0; b < buckets; ++b) {
    const float lowest = std::bit_cast<float>(b << kBucketShift);
    bucketCode_[b] = static_cast<uint8_t>(
        std::upper_bound(thresholds_.begin(), thresholds_.end(), lowest) - thresholds_.begin());
  }
}

const SrgbEncoder& SrgbEncoder::instance() {
  static const SrgbEncoder encoder;
  return encoder;
}

uint8_t SrgbEncoder::operator()(float linear) const {
  if (!(linear > 0.f)) return 0;  // also NaN
  if (linear >= 1.f) return 255;
  unsigned code = bucketCode_[std::bit_cast<uint32_t>(linear) >> kBucketShift];
  while (code < 255 && linear >= thresholds_[code]) ++code;
  return static_cast<uint8_t>(code);
}

}  // namespace visopt::io
