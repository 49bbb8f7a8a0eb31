// The bit-packed mask of visopt/bit_mask.h.
#include "visopt/bit_mask.h"

#include <bit>

#include "visopt/field.h"

namespace visopt {

size_t BitMask::voxelCount() const {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) return 0;
  return size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
}

void BitMask::set(size_t i, bool v) {
  const auto bit = static_cast<uint8_t>(1u << (i & 7));
  if (v)
    bits[i >> 3] = static_cast<uint8_t>(bits[i >> 3] | bit);
  else
    bits[i >> 3] = static_cast<uint8_t>(bits[i >> 3] & ~bit);
}

BitMask BitMask::cleared(glm::ivec3 dims) {
  BitMask m;
  m.dims = dims;
  m.bits.assign((m.voxelCount() + 7) / 8, 0);
  return m;
}

size_t BitMask::count() const {
  const size_t n = voxelCount();
  size_t total = 0;
  for (size_t b = 0; b < n / 8; ++b) total += size_t(std::popcount(unsigned(bits[b])));
  for (size_t i = n / 8 * 8; i < n; ++i) total += get(i) ? 1u : 0u;
  return total;
}

BitMask packMask(const Field3D& mask) {
  BitMask m = BitMask::cleared(mask.grid().dims);
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask.get(i) > 0.5f) m.bits[i >> 3] = static_cast<uint8_t>(m.bits[i >> 3] | (1u << (i & 7)));
  return m;
}

}  // namespace visopt
