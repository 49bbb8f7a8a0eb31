// LDR-ꟻLIP against the reference tool's numbers and error maps (tests/regression/flip-reference),
// its published properties (0 for identical images, symmetric, in [0, 1], growing with the noise),
// and SSIM against closed forms.
#include <zlib.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "visopt/error.h"
#include "visopt/image.h"
#include "visopt/image_metrics.h"

namespace visopt {
namespace {

const std::string kFlipDir = std::string(VISOPT_REGRESSION_DIR) + "/flip-reference/";

nlohmann::json referenceValues() {
  std::ifstream in(kFlipDir + "values.json");
  return nlohmann::json::parse(in);
}

// The tool's error map: a '#' header line, then one row per line.
std::vector<float> readErrorMap(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return {};
  std::string text;
  char buffer[1 << 16];
  int n;
  while ((n = gzread(f, buffer, sizeof(buffer))) > 0) text.append(buffer, size_t(n));
  gzclose(f);
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::vector<float> values;
  float v;
  while (in >> v) values.push_back(v);
  return values;
}

struct Pair {
  std::string id;
  Image reference, test;
  nlohmann::json values;
};
std::vector<Pair> pairs() {
  std::vector<Pair> out;
  const nlohmann::json values = referenceValues();
  for (const auto& p : values["pairs"]) {
    Pair pair;
    pair.id = p["id"].get<std::string>();
    pair.reference = readPng(kFlipDir + p["reference"].get<std::string>());
    pair.test = readPng(kFlipDir + p["test"].get<std::string>());
    pair.values = p;
    out.push_back(std::move(pair));
  }
  return out;
}

TEST(Flip, DefaultObserverIsTheToolsPixelsPerDegree) {
  // The tool computes it in single precision.
  EXPECT_NEAR(flipDefaultPixelsPerDegree(), referenceValues()["pixels_per_degree"].get<double>(),
              1e-5);
  EXPECT_NEAR(pixelsPerDegree(1.0, 0.5, 1000.0), 2000.0 * M_PI / 180.0, 1e-9);
}

TEST(Flip, MeansAndWeightedMediansMatchTheReferenceTool) {
  const std::vector<Pair> all = pairs();
  ASSERT_EQ(all.size(), 9u);
  const double tolerance = referenceValues()["suggested_tolerance"]["mean_abs"].get<double>();
  for (const Pair& p : all) {
    const FlipResult r = flip(p.reference, p.test);
    EXPECT_NEAR(r.mean, p.values["mean"].get<double>(), tolerance) << p.id;
    // Ours agree to ~2e-6 (float rounding): ten times tighter than the suggestion still holds.
    EXPECT_NEAR(r.mean, p.values["mean"].get<double>(), 0.1 * tolerance) << p.id;
    EXPECT_NEAR(r.weightedMedian, p.values["weighted_median"].get<double>(), 2e-3) << p.id;
    EXPECT_NEAR(r.max, p.values["max"].get<double>(), 2e-3) << p.id;
  }
}

// Pairs 04 (an 8-px checkerboard shifted by one pixel: the filters and both feature detectors at
// every edge and at the borders), 05 (a sharp against a blurred disc), 07 (black against white:
// the colour pipeline's largest distances), 08 (a bright 3x3 dot: the point detector) and 09 (a
// visopt rendering in fp32 against fp16), pixel by pixel. Where two filtered colours differ by
// a few float ulps, the colour term's power q_c = 0.7 (infinite slope at 0) turns the rounding
// into errors up to ~5e-4, so a few pixels differ by more than 1e-4 (about 0.2 % on 04 and 05).
TEST(Flip, ErrorMapsMatchTheReferenceToolPixelByPixel) {
  for (const Pair& p : pairs()) {
    const std::string mapFile = kFlipDir + "errormaps/" + p.id + "-errormap.txt.gz";
    if (!std::ifstream(mapFile)) continue;
    const std::vector<float> expected = readErrorMap(mapFile);
    const FlipResult r = flip(p.reference, p.test);
    ASSERT_EQ(expected.size(), r.error.size()) << p.id;
    double worst = 0.0;
    size_t worstAt = 0, offByMoreThan1e4 = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
      const double d = std::abs(double(expected[i]) - double(r.error[i]));
      if (d > worst) worst = d, worstAt = i;
      offByMoreThan1e4 += d > 1e-4;
    }
    EXPECT_LT(worst, 1e-3) << p.id << " at pixel (" << worstAt % size_t(r.width) << ", "
                           << worstAt / size_t(r.width) << "): " << r.error[worstAt] << " vs "
                           << expected[worstAt];
    EXPECT_LT(double(offByMoreThan1e4), 0.01 * double(expected.size())) << p.id;
  }
}

TEST(Flip, IdenticalImagesAreZeroEverywhere) {
  const Image a = readPng(kFlipDir + "06-colour-vs-gray-reference.png");
  const FlipResult r = flip(a, a);
  for (float e : r.error) ASSERT_EQ(e, 0.f);
  EXPECT_EQ(r.mean, 0.0);
  EXPECT_EQ(r.p95, 0.0);
}

TEST(Flip, IsSymmetricAndBetweenZeroAndOne) {
  for (const Pair& p : pairs()) {
    const FlipResult ab = flip(p.reference, p.test), ba = flip(p.test, p.reference);
    for (size_t i = 0; i < ab.error.size(); ++i) {
      ASSERT_GE(ab.error[i], 0.f) << p.id;
      ASSERT_LE(ab.error[i], 1.f) << p.id;
      ASSERT_NEAR(ab.error[i], ba.error[i], 1e-6f) << p.id << " pixel " << i;
    }
    EXPECT_LE(ab.p95, ab.max);
  }
}

TEST(Flip, GrowsWithTheNoise) {
  const auto all = pairs();
  auto meanOf = [&](const std::string& id) {
    for (const Pair& p : all)
      if (p.id == id) return flip(p.reference, p.test).mean;
    ADD_FAILURE() << id;
    return 0.0;
  };
  EXPECT_LT(meanOf("01-identical"), meanOf("02-noise-sigma2"));
  EXPECT_LT(meanOf("02-noise-sigma2"), meanOf("03-noise-sigma10"));
}

// Uniform images have no features: the error is the colour pipeline's alone, the same at every
// pixel, and grows with the difference in grey.
TEST(Flip, UniformImagesDifferByTheirColourAlone) {
  auto uniform = [](float v) {
    Image im(32, 24);
    for (auto& px : im.pixels) px = glm::vec3(v);
    return im;
  };
  const FlipResult small = flip(uniform(0.2f), uniform(0.25f));
  const FlipResult large = flip(uniform(0.2f), uniform(0.6f));
  for (float e : small.error) ASSERT_FLOAT_EQ(e, small.error[0]);
  EXPECT_GT(small.mean, 0.0);
  EXPECT_GT(large.mean, small.mean);
  EXPECT_NEAR(small.p95, small.mean, 1e-6);
}

TEST(Flip, FinerPixelsHideSmallDetails) {
  // The same one-pixel checkerboard seen from farther away (more pixels per degree) is blurred
  // more by the contrast sensitivity filters, so it differs less from flat grey.
  Image checker(64, 64), grey(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      checker.at(x, y) = glm::vec3(float((x + y) % 2));
      grey.at(x, y) = glm::vec3(0.5f);
    }
  EXPECT_GT(flip(checker, grey, 10.0).mean, flip(checker, grey, 120.0).mean);
}

TEST(Flip, RefusesWhatItCannotCompare) {
  EXPECT_THROW((void)flip(Image(8, 8), Image(8, 9)), Error);
  EXPECT_THROW((void)flip(Image(), Image()), Error);
  EXPECT_THROW((void)flip(Image(8, 8), Image(8, 8), 0.0), Error);
  EXPECT_THROW((void)flip(Image(8, 8), Image(8, 8), std::nan("")), Error);
}

TEST(Flip, NanPixelsCountAsBlack) {
  Image nan(16, 16), black(16, 16);
  for (auto& px : nan.pixels) px = glm::vec3(std::nanf(""));
  const FlipResult r = flip(nan, black);
  EXPECT_EQ(r.mean, 0.0);
}

// SSIM of two uniform images: the variances and the covariance vanish, leaving
// (2 mx my + C1) / (mx^2 + my^2 + C1) with C1 = 0.01^2 on the encoded luma.
TEST(Ssim, UniformImagesFollowTheClosedForm) {
  auto uniform = [](float srgb) {
    const float linear = std::pow((srgb + 0.055f) / 1.055f, 2.4f);
    Image im(20, 16);
    for (auto& px : im.pixels) px = glm::vec3(linear);
    return im;
  };
  const double x = 0.3, y = 0.7, c1 = 1e-4;
  EXPECT_NEAR(ssim(uniform(float(x)), uniform(float(y))), (2 * x * y + c1) / (x * x + y * y + c1),
              1e-5);
  EXPECT_NEAR(ssim(uniform(0.5f), uniform(0.5f)), 1.0, 1e-12);
}

TEST(Ssim, StructureLowersItAndBadSizesAreRefused) {
  const Image a = readPng(kFlipDir + "02-noise-sigma2-reference.png");
  const Image b = readPng(kFlipDir + "02-noise-sigma2-test.png");
  const Image c = readPng(kFlipDir + "03-noise-sigma10-test.png");
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
  EXPECT_GT(ssim(a, b), ssim(a, c));
  EXPECT_LT(ssim(a, c), 1.0);
  EXPECT_FALSE(ssimApplies(Image(10, 40)));
  EXPECT_TRUE(ssimApplies(Image(11, 11)));
  EXPECT_THROW((void)ssim(Image(10, 40), Image(10, 40)), Error);
  EXPECT_THROW((void)ssim(a, Image(20, 20)), Error);
}

}  // namespace
}  // namespace visopt
