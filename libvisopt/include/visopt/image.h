#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace visopt {

// A linear-light RGB image, row 0 at the top.
struct Image {
  int width = 0, height = 0;
  std::vector<glm::vec3> pixels;

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(static_cast<size_t>(w) * h, glm::vec3(0.f)) {}
  glm::vec3& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
  const glm::vec3& at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
  // 8-bit sRGB, RGBA interleaved.
  std::vector<uint8_t> toSrgb8() const;
  // The same into rows of `bytesPerRow` bytes (>= 4 * width) at `rgba` (e.g. a GUI's image).
  void writeSrgb8(uint8_t* rgba, size_t bytesPerRow) const;
};

// Writes an 8-bit sRGB PNG atomically (temporary file, then rename). Throws Error(Failure).
void writePng(const Image& image, const std::string& path);
// Throws Error(Usage) unless writePng may write `path` (a regular file, a link or a new path;
// not a folder, device, pipe or socket): check before the work whose result it will hold.
void checkPngOutput(const std::string& path);
// Reads an 8-bit PNG back into linear RGB (for tests and comparisons).
Image readPng(const std::string& path);
// Peak signal-to-noise ratio in dB of two equally sized images over sRGB-encoded values.
double psnr(const Image& a, const Image& b);

}  // namespace visopt
