// Base64 (RFC 4648 §4, with padding): binary blobs inside session JSON.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace visopt::session {

std::string base64Encode(const std::vector<uint8_t>& bytes);
// nullopt for text that is not canonical padded base64 (whitespace is not allowed).
std::optional<std::vector<uint8_t>> base64Decode(const std::string& text);

}  // namespace visopt::session
