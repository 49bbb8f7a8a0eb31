#include "session/mask_codec.h"

#include <zstd.h>

#include "session/base64.h"
#include "visopt/error.h"

namespace visopt::session {

namespace {
constexpr int kLevel = 3;  // zstd's default: a 512^3 mask (16 MiB of bits) in tens of ms
}

std::string encodeMaskBits(const std::vector<uint8_t>& bits) {
  std::vector<uint8_t> packed(ZSTD_compressBound(bits.size()));
  const size_t n = ZSTD_compress(packed.data(), packed.size(), bits.data(), bits.size(), kLevel);
  if (ZSTD_isError(n))
    throw Error(ErrorKind::Failure,
                std::string("cannot compress the world mask: ") + ZSTD_getErrorName(n));
  packed.resize(n);
  return base64Encode(packed);
}

std::vector<uint8_t> decodeMaskBits(const std::string& text, size_t expectedBytes,
                                    const std::string& origin) {
  auto packed = base64Decode(text);
  if (!packed) throwBadInput(origin, "the world mask's data is not base64");
  const unsigned long long size = ZSTD_getFrameContentSize(packed->data(), packed->size());
  if (size == ZSTD_CONTENTSIZE_ERROR)
    throwBadInput(origin, "the world mask's data is not a zstd frame");
  if (size != ZSTD_CONTENTSIZE_UNKNOWN && size != expectedBytes)
    throwBadInput(origin, "the world mask holds " + std::to_string(size) +
                              " bytes, its dims need " + std::to_string(expectedBytes));
  std::vector<uint8_t> bits(expectedBytes);
  const size_t n = ZSTD_decompress(bits.data(), bits.size(), packed->data(), packed->size());
  if (ZSTD_isError(n))
    throwBadInput(origin, std::string("the world mask's data is corrupt (zstd: ") +
                              ZSTD_getErrorName(n) + ")");
  if (n != expectedBytes)
    throwBadInput(origin, "the world mask inflates to " + std::to_string(n) +
                              " bytes, its dims need " + std::to_string(expectedBytes));
  return bits;
}

}  // namespace visopt::session
