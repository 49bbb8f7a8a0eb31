// The world mask inside a session: bit-packed voxels (x fastest, LSB first), zstd-compressed,
// base64 text. Masks are binary and mostly large uniform regions, so this is small.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace visopt::session {

std::string encodeMaskBits(const std::vector<uint8_t>& bits);
// Throws BadInput naming `origin` when the text is not base64, not a zstd frame, or does not
// inflate to exactly `expectedBytes`.
std::vector<uint8_t> decodeMaskBits(const std::string& text, size_t expectedBytes,
                                    const std::string& origin);

}  // namespace visopt::session
