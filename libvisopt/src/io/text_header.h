// Helpers for the "key: value" / "key = value" text headers of MetaImage, NRRD and INRIMAGE.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace visopt::io {

std::string trim(const std::string& s);
std::string toLower(std::string s);
// Whitespace-separated numbers; nullopt when any token is not a number.
std::optional<std::vector<double>> parseNumbers(const std::string& text);
// Reads at most `maxBytes` from the start of a file (binary-safe).
std::string readFilePrefix(const std::string& path, size_t maxBytes);

}  // namespace visopt::io
