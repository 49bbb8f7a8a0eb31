// The real CT with the README's command: skin at -400 HU as the context surface, bone (the
// ct-skin-bone preset's importance) as what must show. Needs data/Cranium.raw from
// datasets-scripts/fetch_datasets.sh; skips with a message otherwise.
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace {
visopt::testing::CliResult runCli(const std::string& args) {
  return visopt::testing::runCli(args, "real-scans");
}
}  // namespace

TEST(RealScans, TheCraniumSkullShowsThroughTheSkinWithTheReadmeCommand) {
  const std::string ct = std::string(VISOPT_DATA_DIR) + "/Cranium.raw";
  if (!std::filesystem::exists(ct))
    GTEST_SKIP() << ct << " absent; run datasets-scripts/fetch_datasets.sh to fetch it";
  const std::filesystem::path out = std::filesystem::path(VISOPT_TEST_TMP) / "real-scans";
  std::filesystem::create_directories(out);
  // README, "Context surfaces that give way".
  const visopt::testing::CliResult r =
      runCli("optimize --volume " + ct +
             " --tf preset:ct-skin-bone --context iso:-400 --camera 0,10,2.4 "
             "--out " +
             (out / "ct-skin.png").string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const double v0 = j["initial"]["visibility_view_occluders"].get<double>();
  const double v1 = j["final"]["visibility_view_occluders"].get<double>();
  std::printf("Cranium CT, skin as context: visibility through occluders %.3f -> %.3f\n", v0, v1);
  EXPECT_LT(v0, 0.2) << "the skin hides the skull at first";
  EXPECT_GE(v1, 0.8);
}
