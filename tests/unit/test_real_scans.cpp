// The real CT with the README's command: skin at -400 HU as the context surface, bone (the
// ct-skin-bone preset's importance) as what must show. Needs data/Cranium.raw from
// datasets-scripts/fetch_datasets.sh; skips with a message otherwise.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

struct CliResult {
  int code = -1;
  std::string out, err;
};

CliResult runCli(const std::string& args) {
  const std::filesystem::path dir = std::filesystem::path(VISOPT_TEST_TMP) / "real-scans";
  std::filesystem::create_directories(dir);
  const std::string errFile = (dir / ("stderr-" + std::to_string(getpid()) + ".txt")).string();
  const std::string cmd = std::string(VISOPT_CLI) + " " + args + " 2>" + errFile;
  CliResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(errFile);
  r.err.assign(std::istreambuf_iterator<char>(err), {});
  return r;
}

}  // namespace

TEST(RealScans, TheCraniumSkullShowsThroughTheSkinWithTheReadmeCommand) {
  const std::string ct = std::string(VISOPT_DATA_DIR) + "/Cranium.raw";
  if (!std::filesystem::exists(ct))
    GTEST_SKIP() << ct << " absent; run datasets-scripts/fetch_datasets.sh to fetch it";
  const std::filesystem::path out = std::filesystem::path(VISOPT_TEST_TMP) / "real-scans";
  std::filesystem::create_directories(out);
  // README, "Context surfaces that give way".
  const CliResult r = runCli("optimize --volume " + ct +
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
