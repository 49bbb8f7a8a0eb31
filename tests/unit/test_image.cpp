// PNG image IO and PSNR: sRGB encoding of known linear values, write -> read round trip (exact
// on 8-bit codes), atomic writes, bad files, and PSNR of identical and of known perturbations.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "io/srgb_encode.h"
#include "visopt/error.h"
#include "visopt/image.h"

namespace fs = std::filesystem;
using namespace visopt;

namespace {

std::string tmpDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(VISOPT_TEST_TMP) / "image" / info->name();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// Linear value whose sRGB code is exactly `code` (inverse OETF).
float linearOf(int code) {
  double c = code / 255.0;
  return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

Image gradient(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at(x, y) =
          glm::vec3(linearOf((x * 7 + y) % 256), linearOf((y * 13) % 256), linearOf((x * y) % 256));
  return img;
}

}  // namespace

TEST(Image, Srgb8EncodesKnownValues) {
  Image img(6, 1);
  img.at(0, 0) = glm::vec3(0.f, 1.f, 0.5f);
  img.at(1, 0) =
      glm::vec3(-1.f, 2.f, std::numeric_limits<float>::quiet_NaN());  // clamped; NaN -> 0
  img.at(2, 0) = glm::vec3(0.0031308f * 0.5f, 0.18f, 0.214041f);
  img.at(3, 0) = glm::vec3(linearOf(1), linearOf(128), linearOf(254));
  std::vector<uint8_t> s = img.toSrgb8();
  ASSERT_EQ(s.size(), 6u * 4u);
  // 0.5 linear -> 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5 -> 188.
  EXPECT_EQ(s[0], 0);
  EXPECT_EQ(s[1], 255);
  EXPECT_EQ(s[2], 188);
  EXPECT_EQ(s[3], 255);  // alpha
  EXPECT_EQ(s[4], 0);
  EXPECT_EQ(s[5], 255);
  EXPECT_EQ(s[6], 0);
  // Linear segment: 12.92 * 0.0015654 * 255 = 5.16 -> 5; 0.18 -> 0.4614 -> 117.7 -> 118;
  // 0.214041 -> 0.5 exactly in sRGB -> 127.5 -> 128 (rounding half up, within float error).
  EXPECT_EQ(s[8], 5);
  EXPECT_EQ(s[9], 118);
  EXPECT_NEAR(s[10], 128, 1);
  EXPECT_EQ(s[12], 1);
  EXPECT_EQ(s[13], 128);
  EXPECT_EQ(s[14], 254);
}

// The fast sRGB encoder (the path toSrgb8 takes) gives the formula's code exactly: on the floats
// next to every code's step (found by bisection on the formula), out-of-range values, NaN and
// infinities, denormals and random values; writeSrgb8 into padded rows gives toSrgb8's bytes.
TEST(Image, TheFastSrgbEncoderEqualsTheFormula) {
  const io::SrgbEncoder& fast = io::SrgbEncoder::instance();
  std::vector<float> values = {0.f,
                               -0.f,
                               1.f,
                               2.f,
                               -1.f,
                               std::nanf(""),
                               std::numeric_limits<float>::infinity(),
                               -std::numeric_limits<float>::infinity(),
                               std::numeric_limits<float>::denorm_min(),
                               0.0031308f,
                               std::nextafter(0.0031308f, 1.f)};
  for (int k = 1; k <= 255; ++k) {
    float lo = 0.f, hi = 1.f;
    for (int i = 0; i < 60; ++i) {
      const float mid = 0.5f * (lo + hi);
      (io::encodeSrgbReference(mid) >= k ? hi : lo) = mid;
    }
    float v = std::nextafter(lo, 0.f);
    for (int n = 0; n < 4; ++n, v = std::nextafter(v, 2.f)) values.push_back(v);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-0.1f, 1.1f);
  for (int i = 0; i < 200000; ++i) values.push_back(unit(rng) * unit(rng));
  size_t differing = 0;
  for (float v : values) differing += fast(v) != io::encodeSrgbReference(v);
  EXPECT_EQ(differing, 0u);

  Image img(7, 5);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    img.pixels[i] = {values[i], values[i + 40], values[i + 400]};
  const std::vector<uint8_t> packed = img.toSrgb8();
  std::vector<uint8_t> padded(5 * 40, 0xab);
  img.writeSrgb8(padded.data(), 40);
  for (int y = 0; y < 5; ++y)
    for (int b = 0; b < 40; ++b)
      EXPECT_EQ(padded[size_t(y) * 40 + b], b < 28 ? packed[size_t(y) * 28 + b] : 0xab)
          << y << "," << b;
}

TEST(Image, PngRoundTripIsExactOnCodes) {
  std::string path = tmpDir() + "/grad.png";
  Image img = gradient(37, 23);  // odd sizes: no row padding assumptions
  writePng(img, path);
  Image back = readPng(path);
  ASSERT_EQ(back.width, 37);
  ASSERT_EQ(back.height, 23);
  EXPECT_EQ(back.toSrgb8(), img.toSrgb8());
  EXPECT_TRUE(std::isinf(psnr(img, back)));
  // Row 0 is the top: pixel (5, 0) keeps its value.
  EXPECT_NEAR(back.at(5, 0).r, linearOf(35), 1e-6f);
  EXPECT_NEAR(back.at(0, 22).g, linearOf((22 * 13) % 256), 1e-6f);
  // Atomic: nothing but the file itself in the folder.
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(path).parent_path())) {
    ++files;
    EXPECT_EQ(e.path().filename(), "grad.png");
  }
  EXPECT_EQ(files, 1);
  // Overwriting works and replaces the content.
  Image black(4, 2);
  writePng(black, path);
  EXPECT_EQ(readPng(path).width, 4);
}

TEST(Image, PsnrOfKnownPerturbations) {
  Image a = gradient(16, 16);
  EXPECT_TRUE(std::isinf(psnr(a, a)));
  EXPECT_GT(psnr(a, a), 0.0);
  // Every R, G and B code off by exactly 1 (codes kept inside [1, 254]): MSE = 1 ->
  // 10 log10(255^2) = 48.1308 dB.
  Image b(16, 16), c(16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      int code = 1 + (x * 16 + y) % 253;
      b.at(x, y) = glm::vec3(linearOf(code));
      c.at(x, y) = glm::vec3(linearOf(code + 1));
    }
  EXPECT_NEAR(psnr(b, c), 20.0 * std::log10(255.0), 1e-9);
  // One channel of one pixel off by 255 in a 4x4 image: MSE = 255^2 / 48 -> 10 log10(48).
  Image d(4, 4), e(4, 4);
  e.at(2, 1).g = 1.f;
  EXPECT_NEAR(psnr(d, e), 10.0 * std::log10(48.0), 1e-9);
  EXPECT_DOUBLE_EQ(psnr(d, e), psnr(e, d));
  // Different sizes cannot be compared.
  EXPECT_THROW((void)psnr(Image(4, 4), Image(4, 5)), Error);
}

TEST(Image, BadFilesAreReported) {
  std::string dir = tmpDir();
  auto expectBad = [&](const std::string& path, const std::string& word) {
    try {
      (void)readPng(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::BadInput);
      std::string msg = e.what();
      EXPECT_NE(msg.find(fs::path(path).filename().string()), std::string::npos) << msg;
      EXPECT_NE(msg.find(word), std::string::npos) << msg;
    }
  };
  expectBad(dir + "/missing.png", "not found");
  std::ofstream(dir + "/empty.png").close();
  expectBad(dir + "/empty.png", "empty");
  std::ofstream(dir + "/junk.png") << "this is not a png file at all";
  expectBad(dir + "/junk.png", "PNG");
  // A valid PNG cut in half.
  writePng(gradient(64, 64), dir + "/full.png");
  {
    std::ifstream in(dir + "/full.png", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir + "/cut.png", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  expectBad(dir + "/cut.png", "PNG");
  // Writing into a missing folder fails with the path in the message.
  try {
    writePng(gradient(2, 2), dir + "/no/such/dir/out.png");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out.png"), std::string::npos);
  }
  EXPECT_THROW(writePng(Image(), dir + "/empty_image.png"), Error);
  EXPECT_FALSE(fs::exists(dir + "/empty_image.png"));
}

// A write killed between creating its temporary and renaming it leaves "out.png.tmp-XXXXXX.png"
// behind (issue 13: 25 after 40 kills); the next write to the same path removes such leftovers,
// whose lock no process holds, once they are a few seconds old.
TEST(Image, TheNextWriteRemovesAKilledWritesTemporary) {
  const std::string dir = tmpDir() + "/leftovers";
  fs::create_directories(dir);
  const std::string out = dir + "/out.png";
  const std::string stale = out + ".tmp-AbC123.png", other = dir + "/other.png.tmp-AbC123.png";
  for (const std::string& p : {stale, other}) {
    std::ofstream(p) << "half a png";
    fs::last_write_time(p, fs::file_time_type::clock::now() - std::chrono::minutes(1));
  }
  const std::string fresh = out + ".tmp-NeW456.png";  // a write starting right now: kept
  std::ofstream(fresh) << "";
  writePng(gradient(4, 4), out);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(other)) << "another target's temporaries are not this write's business";
  EXPECT_TRUE(fs::exists(fresh));
  EXPECT_EQ(readPng(out).width, 4);
}
