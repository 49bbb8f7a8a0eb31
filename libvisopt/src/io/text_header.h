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
// A header number that must be a whole number (a size, a count, an offset): refuses (BadInput
// "PATH: invalid KEY VALUE") a non-finite or fractional value or one outside [lo, hi], instead
// of converting it (a double beyond int64's range converted to it is undefined behaviour).
int64_t headerInteger(const std::string& path, const std::string& key, double value, int64_t lo,
                      int64_t hi);
// Reads at most `maxBytes` from the start of a file (binary-safe).
std::string readFilePrefix(const std::string& path, size_t maxBytes);

}  // namespace visopt::io
