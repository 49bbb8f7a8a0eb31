#include "io/text_header.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "visopt/error.h"

namespace visopt::io {

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

std::string toLower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::optional<std::vector<double>> parseNumbers(const std::string& text) {
  std::vector<double> out;
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    char* end = nullptr;
    double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') return std::nullopt;
    out.push_back(v);
  }
  return out;
}

int64_t headerInteger(const std::string& path, const std::string& key, double value, int64_t lo,
                      int64_t hi) {
  if (!(value >= double(lo) && value <= double(hi)) || value != std::floor(value)) {
    std::ostringstream text;
    text.precision(17);
    text << "invalid " << key << " " << value << " (need a whole number from " << lo << " to " << hi
         << ")";
    throwBadInput(path, text.str());
  }
  return static_cast<int64_t>(value);
}

std::string readFilePrefix(const std::string& path, size_t maxBytes) {
  std::ifstream in(path, std::ios::binary);
  // No larger than the file: a 1 MiB header window was zero-filled for every small file.
  std::error_code ec;
  const uintmax_t fileSize = std::filesystem::file_size(path, ec);
  if (!ec) maxBytes = static_cast<size_t>(std::min<uintmax_t>(maxBytes, fileSize));
  std::string data(maxBytes, '\0');
  in.read(data.data(), static_cast<std::streamsize>(maxBytes));
  data.resize(static_cast<size_t>(in.gcount()));
  return data;
}

}  // namespace visopt::io
