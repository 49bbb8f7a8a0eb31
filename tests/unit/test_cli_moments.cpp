// `visopt moments generate | render | info` as a user runs them: a moment image of a built-in
// scene, rendered with a transfer function it was not made with, close to the direct rendering;
// a broken .vmi gives exit 2 and one line naming the file; bad options exit 1.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace fs = std::filesystem;

namespace {

visopt::testing::CliResult run(const std::string& args) {
  return visopt::testing::runCli(args, "cli_moments");
}

std::string tmp(const std::string& name) {
  fs::create_directories(fs::path(VISOPT_TEST_TMP) / "cli_moments");
  return (fs::path(VISOPT_TEST_TMP) / "cli_moments" / name).string();
}

TEST(CliMoments, GenerateInfoAndRenderAgainstTheDirectRendering) {
  const std::string vmi = tmp("ml.vmi");
  auto r =
      run("moments generate --scene builtin:marschner-lobb --resolution 32 --size 48x40 "
          "--moments 60 --out " +
          vmi + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto g = nlohmann::json::parse(r.out);
  EXPECT_EQ(g["size"], nlohmann::json({48, 40}));
  EXPECT_EQ(g["order"], 60);
  EXPECT_GT(g["pixels_hit"].get<int>(), 0);
  EXPECT_LE(g["moments_per_hit_pixel"].get<double>(), 61.0);

  r = run("moments info " + vmi + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["moments_stored"], g["moments_stored"]);

  for (const char* rec : {"mese", "fourier"}) {
    const std::string png = tmp(std::string("ml-") + rec + ".png");
    r = run("moments render " + vmi + " --tf preset:generic --reconstruction " + rec +
            " --scene builtin:marschner-lobb --resolution 32 --reference-out " + tmp("direct.png") +
            " --out " + png + " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["psnr_against_direct_db"].get<double>(), 30.0) << rec;
    EXPECT_TRUE(fs::exists(png));
  }
  // Without an uncertainty block, --uncertainty is a usage error; with one it draws the heat map.
  r = run("moments render " + vmi + " --uncertainty --out " + tmp("u.png"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("holds no uncertainty"), std::string::npos) << r.err;
  const std::string withU = tmp("ml-u.vmi");
  ASSERT_EQ(run("moments generate --scene builtin:marschner-lobb --resolution 32 --size 24x20 "
                "--moments 30 --uncertainty 0.9 --out " +
                withU)
                .code,
            0);
  r = run("moments render " + withU + " --uncertainty --out " + tmp("u.png"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(tmp("u.png")));
  // The direct rendering needs the same grid: another resolution is refused.
  r = run("moments render " + vmi + " --scene builtin:marschner-lobb --resolution 40 --out " +
          tmp("x.png"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("grid"), std::string::npos) << r.err;
}

TEST(CliMoments, ABrokenFileExitsTwoNamingIt) {
  const std::string bad = tmp("broken.vmi");
  {
    std::ofstream out(bad, std::ios::binary);
    out.write("VISOPTMI\x01\0\0\0", 12);  // magic and version, then nothing
  }
  for (const char* cmd : {"info", "render"}) {
    const auto r = run(std::string("moments ") + cmd + " " + bad +
                       (std::string(cmd) == "render" ? " --out " + tmp("b.png") : ""));
    EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp("b.png")));
  }
}

TEST(CliMoments, BadOptionsExitOne) {
  EXPECT_EQ(
      run("moments generate --scene builtin:marschner-lobb --moments 500 --out " + tmp("x.vmi"))
          .code,
      1);
  EXPECT_EQ(
      run("moments generate --scene builtin:marschner-lobb --error -1 --out " + tmp("x.vmi")).code,
      1);
  EXPECT_EQ(
      run("moments render " + tmp("x.vmi") + " --reconstruction spline --out " + tmp("x.png")).code,
      1);
  EXPECT_EQ(run("moments").code, 1);
}

}  // namespace
