// Image <-> 8-bit sRGB PNG through libpng's simplified API, and PSNR.
//  - toSrgb8: the sRGB OETF (IEC 61966-2-1) of each clamped linear channel, rounded; NaN -> 0;
//    alpha 255 (io/srgb_encode.h: the fast encoder, equal code for code to the formula).
//  - writePng: RGBA8 written to a temporary sibling, then renamed (Error(Failure) on any problem,
//    Error(Usage) for an empty image).
//  - readPng: any PNG libpng can convert to 8-bit RGB, decoded to linear with the inverse OETF
//    (Error(BadInput) "PATH: problem" for a missing or corrupt file).
//  - psnr: over the 8-bit sRGB codes of R, G and B: 10 log10(255^2 / MSE). Identical images give
//    +infinity (std::numeric_limits<double>::infinity()); differently sized images Error(Usage).
#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "io/file_util.h"
#include "io/srgb_encode.h"
#include "visopt/error.h"
#include "visopt/image.h"

namespace visopt {

namespace {

const std::array<float, 256>& decodeTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[size_t(i)] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

}  // namespace

std::vector<uint8_t> Image::toSrgb8() const {
  std::vector<uint8_t> out(pixels.size() * 4);
  writeSrgb8(out.data(), size_t(width) * 4);
  return out;
}

void Image::writeSrgb8(uint8_t* rgba, size_t bytesPerRow) const {
  if (pixels.size() != size_t(width) * size_t(height)) return;
  const io::SrgbEncoder& encode = io::SrgbEncoder::instance();
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      uint8_t* line = rgba + size_t(y) * bytesPerRow;
      const glm::vec3* in = pixels.data() + size_t(y) * size_t(width);
      for (int x = 0; x < width; ++x) {
        line[4 * x + 0] = encode(in[x].r);
        line[4 * x + 1] = encode(in[x].g);
        line[4 * x + 2] = encode(in[x].b);
        line[4 * x + 3] = 255;
      }
    }
  });
}

void checkPngOutput(const std::string& path) {
  io::checkOutputTarget(path);
}

void writePng(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != size_t(image.width) * size_t(image.height))
    throw Error(ErrorKind::Usage, path + ": cannot write an empty or inconsistent image");
  const std::vector<uint8_t> rgba = image.toSrgb8();
  const std::string tmp = io::makeTemporarySibling(path, ".png");
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGBA;
  if (!png_image_write_to_file(&png, tmp.c_str(), 0, rgba.data(), 0, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    io::discardTemporary(tmp);
    throw Error(ErrorKind::Failure, path + ": cannot write PNG (" + message + ")");
  }
  io::commitTemporary(tmp, path);
}

Image readPng(const std::string& path) {
  io::checkedFileSize(path);
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    std::string message = png.message;
    png_image_free(&png);
    throwBadInput(path, "not a readable PNG (" + message + ")");
  }
  png.format = PNG_FORMAT_RGB;
  if (png.width == 0 || png.height == 0 || png.width > 1u << 16 || png.height > 1u << 16) {
    png_image_free(&png);
    throwBadInput(path, "unsupported PNG size");
  }
  std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, rgb.data(), 0, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    throwBadInput(path, "corrupt PNG (" + message + ")");
  }
  Image image(int(png.width), int(png.height));
  const auto& table = decodeTable();
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = glm::vec3(table[rgb[3 * i]], table[rgb[3 * i + 1]], table[rgb[3 * i + 2]]);
  return image;
}

double psnr(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size())
    throw Error(ErrorKind::Usage, "psnr: images differ in size (" + std::to_string(a.width) + "x" +
                                      std::to_string(a.height) + " vs " + std::to_string(b.width) +
                                      "x" + std::to_string(b.height) + ")");
  if (a.pixels.empty()) throw Error(ErrorKind::Usage, "psnr: empty images");
  const std::vector<uint8_t> sa = a.toSrgb8(), sb = b.toSrgb8();
  double sum = 0.0;
  for (size_t i = 0; i < sa.size(); ++i) {
    if (i % 4 == 3) continue;  // alpha
    const double d = double(sa[i]) - double(sb[i]);
    sum += d * d;
  }
  const double mse = sum / (double(a.pixels.size()) * 3.0);
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

}  // namespace visopt
