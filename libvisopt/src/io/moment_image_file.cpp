// The .vmi file of a moment image, version 1 (visopt/moment_image.h). Layout, little-endian:
//   "VISOPTMI" (8 bytes), u32 version = 1, u32 block count = 4,
//   then 4 blocks, each: 4-byte tag, u64 payload length, u32 CRC-32 of the payload, payload.
//   "HEAD": i32 width, height, order; f32 camera eye, target, up (9), fov; grid origin (3),
//           spacing (3), direction (9, column-major), i32 dims (3); f64 valueMin, valueMax;
//           f32 boundsMargin, errorThreshold, stepVoxels.
//   "CNTS": u8 per pixel, the moments stored (0..order + 1).
//   "BNDS": f32 lower, upper per pixel.
//   "MOMS": f32 moments, pixel after pixel (as many as the counts add up to).
//   "UNCT" (only when the block count is 5): f32 quantile in (0, 1), then f32 per pixel.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>

#include <zlib.h>

#include "io/file_util.h"
#include "visopt/error.h"
#include "visopt/moment_image.h"

namespace visopt {

namespace {

constexpr char kMagic[8] = {'V', 'I', 'S', 'O', 'P', 'T', 'M', 'I'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kBlocks = 4;  // 5 with the uncertainty block

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &v, sizeof(T));
  }
  void put(const void* data, size_t n) {
    const size_t at = bytes_.size();
    bytes_.resize(at + n);
    if (n) std::memcpy(bytes_.data() + at, data, n);
  }
  std::vector<unsigned char>& bytes() { return bytes_; }

 private:
  std::vector<unsigned char> bytes_;
};

uint32_t crcOf(const unsigned char* p, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (n > 0) {
    const uInt chunk = uInt(std::min<size_t>(n, size_t(1) << 30));
    crc = crc32(crc, p, chunk);
    p += chunk;
    n -= chunk;
  }
  return uint32_t(crc);
}

void putBlock(Writer& file, const char tag[4], std::vector<unsigned char> payload) {
  file.put(tag, 4);
  file.put(uint64_t(payload.size()));
  file.put(crcOf(payload.data(), payload.size()));
  file.put(payload.data(), payload.size());
}

class Reader {
 public:
  Reader(const unsigned char* p, size_t n, const std::string& path) : p_(p), n_(n), path_(path) {}
  template <class T>
  T get(const char* what) {
    T v;
    need(sizeof(T), what);
    std::memcpy(&v, p_ + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  const unsigned char* take(size_t n, const char* what) {
    need(n, what);
    const unsigned char* p = p_ + at_;
    at_ += n;
    return p;
  }
  size_t left() const { return n_ - at_; }

 private:
  void need(size_t n, const char* what) const {
    if (n > n_ - at_) throwBadInput(path_, std::string("truncated: the file ends inside ") + what);
  }
  const unsigned char* p_;
  size_t n_, at_ = 0;
  const std::string& path_;
};

}  // namespace

void writeMomentImage(const MomentImage& image, const std::string& path) {
  if (io::hostIsBigEndian())
    throw Error(ErrorKind::Failure, "writing .vmi files needs a little-endian host");
  const size_t pixels = image.pixelCount();
  if (image.counts.size() != pixels || image.lower.size() != pixels || image.upper.size() != pixels)
    throw Error(ErrorKind::Usage, "moment image: per-pixel arrays do not match its size");
  Writer head;
  head.put(int32_t(image.width));
  head.put(int32_t(image.height));
  head.put(int32_t(image.order));
  for (const glm::vec3& v : {image.camera.eye, image.camera.target, image.camera.up})
    for (int a = 0; a < 3; ++a) head.put(v[a]);
  head.put(image.camera.fovYDegrees);
  for (int a = 0; a < 3; ++a) head.put(image.grid.origin[a]);
  for (int a = 0; a < 3; ++a) head.put(image.grid.spacing[a]);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) head.put(image.grid.direction[c][r]);
  for (int a = 0; a < 3; ++a) head.put(int32_t(image.grid.dims[a]));
  head.put(image.valueMin);
  head.put(image.valueMax);
  head.put(image.boundsMargin);
  head.put(image.errorThreshold);
  head.put(image.stepVoxels);

  Writer bounds;
  for (size_t p = 0; p < pixels; ++p) {
    bounds.put(image.lower[p]);
    bounds.put(image.upper[p]);
  }
  Writer moments;
  moments.put(image.moments.data(), image.moments.size() * sizeof(float));

  const bool uncertain = !image.uncertainty.empty();
  if (uncertain && image.uncertainty.size() != pixels)
    throw Error(ErrorKind::Usage, "moment image: the uncertainty does not match its size");
  Writer file;
  file.put(kMagic, 8);
  file.put(kVersion);
  file.put(kBlocks + (uncertain ? 1u : 0u));
  putBlock(file, "HEAD", std::move(head.bytes()));
  putBlock(file, "CNTS", std::vector<unsigned char>(image.counts.begin(), image.counts.end()));
  putBlock(file, "BNDS", std::move(bounds.bytes()));
  putBlock(file, "MOMS", std::move(moments.bytes()));
  if (uncertain) {
    Writer u;
    u.put(image.uncertaintyQuantile);
    u.put(image.uncertainty.data(), pixels * sizeof(float));
    putBlock(file, "UNCT", std::move(u.bytes()));
  }

  const std::string tmp = io::makeTemporarySibling(path, ".vmi");
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(file.bytes().data()),
              std::streamsize(file.bytes().size()));
    out.close();
    if (!out) throw Error(ErrorKind::Failure, path + ": cannot write the moment image");
    io::commitTemporary(tmp, path);
  } catch (...) {
    io::discardTemporary(tmp);
    throw;
  }
}

MomentImage readMomentImage(const std::string& path) {
  if (io::hostIsBigEndian())
    throw Error(ErrorKind::Failure, "reading .vmi files needs a little-endian host");
  const uint64_t size = io::checkedFileSize(path);
  std::vector<unsigned char> bytes(size);
  {
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
    if (!in) throwBadInput(path, "cannot be read");
  }
  Reader file(bytes.data(), bytes.size(), path);
  const unsigned char* magic = file.take(8, "the magic number");
  if (std::memcmp(magic, kMagic, 8) != 0)
    throwBadInput(path, "not a visopt moment image (.vmi): wrong magic number");
  const uint32_t version = file.get<uint32_t>("the version");
  if (version != kVersion)
    throwBadInput(path, "moment image version " + std::to_string(version) +
                            " is not supported (this visopt reads version 1)");
  const uint32_t blocks = file.get<uint32_t>("the block count");
  if (blocks != kBlocks && blocks != kBlocks + 1)
    throwBadInput(path, "wrong block count (a version 1 file has 4 or 5 blocks)");
  auto block = [&](const char* tag) {
    const unsigned char* t = file.take(4, "a block tag");
    if (std::memcmp(t, tag, 4) != 0)
      throwBadInput(path, std::string("expected block ") + std::string(tag, 4) + ", found '" +
                              std::string(reinterpret_cast<const char*>(t), 4) + "'");
    const uint64_t length = file.get<uint64_t>("a block header");
    const uint32_t crc = file.get<uint32_t>("a block header");
    if (length > file.left())
      throwBadInput(path, std::string("truncated: block ") + std::string(tag, 4) + " claims " +
                              std::to_string(length) + " bytes, " + std::to_string(file.left()) +
                              " remain");
    const unsigned char* payload = file.take(size_t(length), "a block");
    if (crcOf(payload, size_t(length)) != crc)
      throwBadInput(path, std::string("block ") + std::string(tag, 4) +
                              " is corrupt (its CRC-32 does not match)");
    return Reader(payload, size_t(length), path);
  };

  MomentImage image;
  {
    Reader head = block("HEAD");
    image.width = head.get<int32_t>("the header");
    image.height = head.get<int32_t>("the header");
    image.order = head.get<int32_t>("the header");
    for (glm::vec3* v : {&image.camera.eye, &image.camera.target, &image.camera.up})
      for (int a = 0; a < 3; ++a) (*v)[a] = head.get<float>("the header");
    image.camera.fovYDegrees = head.get<float>("the header");
    for (int a = 0; a < 3; ++a) image.grid.origin[a] = head.get<float>("the header");
    for (int a = 0; a < 3; ++a) image.grid.spacing[a] = head.get<float>("the header");
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) image.grid.direction[c][r] = head.get<float>("the header");
    for (int a = 0; a < 3; ++a) image.grid.dims[a] = head.get<int32_t>("the header");
    image.valueMin = head.get<double>("the header");
    image.valueMax = head.get<double>("the header");
    image.boundsMargin = head.get<float>("the header");
    image.errorThreshold = head.get<float>("the header");
    image.stepVoxels = head.get<float>("the header");
  }
  if (image.width < 1 || image.height < 1 || image.width > 16384 || image.height > 16384)
    throwBadInput(path, "absurd image size " + std::to_string(image.width) + "x" +
                            std::to_string(image.height));
  if (image.order < 0 || image.order > kMaxMomentOrder)
    throwBadInput(path, "moment order " + std::to_string(image.order) + " is outside 0.." +
                            std::to_string(kMaxMomentOrder));
  bool finite = std::isfinite(image.valueMin) && std::isfinite(image.valueMax) &&
                std::isfinite(image.camera.fovYDegrees);
  for (int a = 0; a < 3; ++a)
    finite = finite && std::isfinite(image.camera.eye[a]) &&
             std::isfinite(image.camera.target[a]) && std::isfinite(image.camera.up[a]) &&
             std::isfinite(image.grid.origin[a]) && image.grid.spacing[a] > 0.f &&
             std::isfinite(image.grid.spacing[a]) && image.grid.dims[a] >= 1 &&
             image.grid.dims[a] <= (1 << 16);
  if (!finite) throwBadInput(path, "the header's camera or volume geometry is not valid");
  const size_t pixels = image.pixelCount();
  {
    Reader counts = block("CNTS");
    if (counts.left() != pixels)
      throwBadInput(path, "the counts block holds " + std::to_string(counts.left()) +
                              " pixels, the header says " + std::to_string(pixels));
    const unsigned char* c = counts.take(pixels, "the counts");
    image.counts.assign(c, c + pixels);
  }
  uint64_t stored = 0;
  for (size_t p = 0; p < pixels; ++p) {
    if (image.counts[p] > image.order + 1)
      throwBadInput(path, "pixel " + std::to_string(p) + " claims " +
                              std::to_string(image.counts[p]) + " moments, above the order " +
                              std::to_string(image.order) + " + 1");
    stored += image.counts[p];
  }
  {
    Reader bounds = block("BNDS");
    if (bounds.left() != pixels * 8)
      throwBadInput(path, "the bounds block does not hold two floats per pixel");
    image.lower.resize(pixels);
    image.upper.resize(pixels);
    for (size_t p = 0; p < pixels; ++p) {
      image.lower[p] = bounds.get<float>("the bounds");
      image.upper[p] = bounds.get<float>("the bounds");
      const bool ok = image.counts[p] == 0
                          ? std::isfinite(image.lower[p])
                          : std::isfinite(image.lower[p]) && std::isfinite(image.upper[p]) &&
                                image.lower[p] < image.upper[p];
      if (!ok)
        throwBadInput(path, "pixel " + std::to_string(p) +
                                " has bounds that are not finite or not increasing");
    }
  }
  {
    Reader moments = block("MOMS");
    if (moments.left() != stored * sizeof(float))
      throwBadInput(path, "the moments block holds " + std::to_string(moments.left() / 4) +
                              " moments, the counts add up to " + std::to_string(stored));
    image.moments.resize(stored);
    if (stored)
      std::memcpy(image.moments.data(), moments.take(stored * 4, "the moments"), stored * 4);
    for (size_t i = 0; i < stored; ++i)
      if (!std::isfinite(image.moments[i]))
        throwBadInput(path, "moment " + std::to_string(i) + " is not finite");
  }
  if (blocks == kBlocks + 1) {
    Reader u = block("UNCT");
    if (u.left() != 4 + pixels * 4)
      throwBadInput(path, "the uncertainty block does not hold one float per pixel");
    image.uncertaintyQuantile = u.get<float>("the uncertainty");
    if (!(image.uncertaintyQuantile > 0.f && image.uncertaintyQuantile < 1.f))
      throwBadInput(path, "the uncertainty quantile is outside (0, 1)");
    image.uncertainty.resize(pixels);
    for (size_t p = 0; p < pixels; ++p) {
      image.uncertainty[p] = u.get<float>("the uncertainty");
      if (!(image.uncertainty[p] >= 0.f && image.uncertainty[p] <= 1.f))
        throwBadInput(path, "pixel " + std::to_string(p) + "'s uncertainty is outside [0, 1]");
    }
  }
  if (file.left() != 0) throwBadInput(path, "unexpected bytes after the last block");
  return image;
}

}  // namespace visopt
