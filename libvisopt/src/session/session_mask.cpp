// The bit-packed world mask of a session.
#include "visopt/field.h"
#include "visopt/session.h"

namespace visopt {

size_t SessionMask::voxelCount() const {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) return 0;
  return size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
}

void SessionMask::set(size_t i, bool v) {
  const auto bit = static_cast<uint8_t>(1u << (i & 7));
  if (v)
    bits[i >> 3] = static_cast<uint8_t>(bits[i >> 3] | bit);
  else
    bits[i >> 3] = static_cast<uint8_t>(bits[i >> 3] & ~bit);
}

SessionMask packMask(const Field3D& mask) {
  SessionMask m;
  m.dims = mask.grid().dims;
  m.bits.assign((m.voxelCount() + 7) / 8, 0);
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask.get(i) > 0.5f) m.bits[i >> 3] = static_cast<uint8_t>(m.bits[i >> 3] | (1u << (i & 7)));
  return m;
}

}  // namespace visopt
