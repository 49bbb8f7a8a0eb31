// `visopt image-diff A.png B.png` as a script would use it: PSNR, SSIM and ꟻLIP of two images,
// one JSON object with --json, the ꟻLIP error map as a PNG, and clear errors (exit 2 naming the
// file for a missing, corrupt or differently sized image; exit 1 for a bad option).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "visopt/image.h"

namespace fs = std::filesystem;

namespace {

const std::string kFlipDir = std::string(VISOPT_REGRESSION_DIR) + "/flip-reference/";

visopt::testing::CliResult run(const std::string& args) {
  return visopt::testing::runCli(args, "cli_image_diff");
}

std::string tmp(const std::string& name) {
  return (fs::path(VISOPT_TEST_TMP) / "cli_image_diff" / name).string();
}

std::string pair(const std::string& id) {
  return kFlipDir + id + "-reference.png " + kFlipDir + id + "-test.png";
}

nlohmann::json referencePair(const std::string& id) {
  std::ifstream in(kFlipDir + "values.json");
  const nlohmann::json values = nlohmann::json::parse(in);
  for (const auto& p : values["pairs"])
    if (p["id"] == id) return p;
  return {};
}

TEST(CliImageDiff, JsonReportsTheThreeMetrics) {
  const auto r = run("image-diff " + pair("03-noise-sigma10") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["size"], nlohmann::json({256, 256}));
  EXPECT_NEAR(j["flip"]["mean"].get<double>(), referencePair("03-noise-sigma10")["mean"], 1e-4);
  EXPECT_GT(j["flip"]["p95"].get<double>(), j["flip"]["mean"].get<double>());
  EXPECT_LE(j["flip"]["p95"].get<double>(), j["flip"]["max"].get<double>());
  // Gaussian noise of sigma 10/255 on the 8-bit codes, clipped at the ends: PSNR near
  // 20 log10(255 / 10) = 28.1 dB.
  EXPECT_NEAR(j["psnr_db"].get<double>(), 20.0 * std::log10(25.5), 1.0);
  EXPECT_GT(j["ssim"].get<double>(), 0.0);
  EXPECT_LT(j["ssim"].get<double>(), 1.0);
  EXPECT_FALSE(j["identical"].get<bool>());
}

TEST(CliImageDiff, IdenticalImagesHaveNoFinitePsnrAndZeroFlip) {
  const std::string a = kFlipDir + "06-colour-vs-gray-reference.png";
  const auto r = run("image-diff " + a + " " + a + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["psnr_db"].is_null());
  EXPECT_TRUE(j["identical"].get<bool>());
  EXPECT_EQ(j["ssim"].get<double>(), 1.0);
  EXPECT_EQ(j["flip"]["mean"].get<double>(), 0.0);
  const auto text = run("image-diff " + a + " " + a);
  EXPECT_NE(text.out.find("PSNR  inf (identical)"), std::string::npos) << text.out;
}

TEST(CliImageDiff, WritesTheErrorMapAtTheImagesSize) {
  const std::string out = tmp("map.png");
  fs::remove(out);
  const auto r =
      run("image-diff " + pair("09-visopt-shepp-logan-fp32-vs-fp16") + " --error-map " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const visopt::Image map = visopt::readPng(out);
  EXPECT_EQ(map.width, 128);
  EXPECT_EQ(map.height, 128);
  EXPECT_NE(r.out.find("FLIP  mean 0.0009"), std::string::npos) << r.out;
}

TEST(CliImageDiff, ObserverFartherAwaySeesLess) {
  // More pixels per degree: the one-pixel shift of the checkerboard is harder to see.
  auto meanAt = [](const std::string& ppd) {
    const auto r = run("image-diff " + pair("04-checker-shift1") + " --json --ppd " + ppd);
    EXPECT_EQ(r.code, 0) << r.err;
    return nlohmann::json::parse(r.out)["flip"]["mean"].get<double>();
  };
  EXPECT_GT(meanAt("20"), meanAt("200"));
}

TEST(CliImageDiff, BadInputIsNamedAndNothingIsWritten) {
  const std::string out = tmp("never.png");
  fs::remove(out);
  const std::string small = kFlipDir + "09-visopt-shepp-logan-fp32-vs-fp16-test.png";
  const std::string large = kFlipDir + "04-checker-shift1-test.png";
  auto sizes = run("image-diff " + large + " " + small + " --error-map " + out);
  EXPECT_EQ(sizes.code, 2);
  EXPECT_NE(sizes.err.find(small + ": 128x128, but " + large + " is 256x256"), std::string::npos)
      << sizes.err;
  EXPECT_FALSE(fs::exists(out));

  const auto missing = run("image-diff " + large + " " + tmp("absent.png"));
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("absent.png"), std::string::npos) << missing.err;

  const std::string truncated = tmp("truncated.png");
  {
    std::ifstream in(large, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  const auto corrupt = run("image-diff " + truncated + " " + large);
  EXPECT_EQ(corrupt.code, 2);
  EXPECT_NE(corrupt.err.find("truncated.png"), std::string::npos) << corrupt.err;

  EXPECT_EQ(run("image-diff " + pair("02-noise-sigma2") + " --ppd 0").code, 1);
  EXPECT_EQ(run("image-diff " + pair("02-noise-sigma2") + " --ppd nan").code, 1);
  EXPECT_EQ(run("image-diff " + large).code, 1);
  EXPECT_EQ(run("image-diff " + pair("02-noise-sigma2") + " --error-map " +
                fs::path(VISOPT_TEST_TMP).string())
                .code,
            1);
}

}  // namespace
