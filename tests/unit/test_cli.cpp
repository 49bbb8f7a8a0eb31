// The visopt command-line tool as a script would use it: exit codes (0 ok, 1 usage, 2 bad input,
// 3 other), one JSON object on stdout with --json, one-line errors naming the file.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "visopt/image.h"
#include "visopt/level_set.h"
#include "visopt/optimization.h"
#include "visopt/render_settings.h"

namespace fs = std::filesystem;

namespace {

using Result = visopt::testing::CliResult;

Result run(const std::string& args) {
  return visopt::testing::runCli(args, "cli");
}

std::string tmp(const std::string& name) {
  return (fs::path(VISOPT_TEST_TMP) / "cli" / name).string();
}

// The last line of stderr (the CPU-backend notice may come first).
std::string lastLine(const std::string& text) {
  std::string t = text;
  while (!t.empty() && t.back() == '\n') t.pop_back();
  const auto pos = t.rfind('\n');
  return pos == std::string::npos ? t : t.substr(pos + 1);
}

// A 24^3 float32 raw volume (unit spacing, with its JSON sidecar) whose voxel at distance r from
// the centre voxel holds valueAt(r).
template <class ValueAt>
void writeBallRaw(const std::string& raw, ValueAt valueAt) {
  std::ofstream f(raw, std::ios::binary);
  for (int k = 0; k < 24; ++k)
    for (int j = 0; j < 24; ++j)
      for (int i = 0; i < 24; ++i) {
        const float r =
            std::sqrt(float((i - 12) * (i - 12) + (j - 12) * (j - 12) + (k - 12) * (k - 12)));
        const float v = valueAt(r);
        f.write(reinterpret_cast<const char*>(&v), 4);
      }
  std::ofstream(raw + ".json") << R"({"dims":[24,24,24],"type":"float32","spacing":[1,1,1]})";
}

}  // namespace

TEST(Cli, ScenesListsTheDefault) {
  Result r = run("scenes --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  bool hasDefault = false;
  for (const auto& s : j["scenes"]) hasDefault |= s["default"].get<bool>();
  EXPECT_TRUE(hasDefault);
  EXPECT_GE(j["scenes"].size(), 4u);
}

TEST(Cli, RenderWritesPngAndReportsStagesAndLedger) {
  const std::string out = tmp("render.png");
  fs::remove(out);
  Result r = run(
      "render --scene builtin:marschner-lobb --resolution 32 --size 48x40 --precision fp16 --out " +
      out + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);  // exactly one JSON object
  EXPECT_EQ(j["image"]["width"], 48);
  EXPECT_GT(j["samples"].get<double>(), 0.0);
  bool hasRender = false;
  for (const auto& s : j["stages"]) hasRender |= s["name"] == "render";
  EXPECT_TRUE(hasRender);
  bool volumeFp16 = false;
  for (const auto& f : j["memory"]["fields"])
    if (f["name"] == "volume")
      volumeFp16 = f["precision"] == "fp16" && f["bytes"] == 32 * 32 * 32 * 2;
  EXPECT_TRUE(volumeFp16);
  EXPECT_TRUE(fs::exists(out));
}

TEST(Cli, UsageErrorsExitOne) {
  EXPECT_EQ(run("").code, 1);
  EXPECT_EQ(run("render --out x.png").code, 1);  // neither --volume nor --scene
  EXPECT_EQ(run("render --scene builtin:nope --out " + tmp("x.png")).code, 1);
  EXPECT_EQ(run("render --scene builtin:shepp-logan --size 0x5 --out " + tmp("x.png")).code, 1);
  EXPECT_EQ(run("render --scene builtin:shepp-logan --precision fp8 --out " + tmp("x.png")).code,
            1);
  EXPECT_EQ(run("optimize --scene builtin:shepp-logan --optimizer sgd").code, 1);
}

TEST(Cli, DeviationColormapIsChosenByName) {
  const std::string a = tmp("dev-viridis.png"), b = tmp("dev-magma.png");
  const std::string common =
      "render --scene builtin:shepp-logan --resolution 48 --size 64x64 "
      "--deviation-view --out ";
  ASSERT_EQ(run(common + a).code, 0);
  ASSERT_EQ(run(common + b + " --deviation-colormap magma").code, 0);
  // The surfaces are on their base shape: colormap(0), viridis' dark purple against magma's
  // near black, so the two images differ.
  const visopt::Image ia = visopt::readPng(a), ib = visopt::readPng(b);
  ASSERT_EQ(ia.pixels.size(), ib.pixels.size());
  float diff = 0.f;
  for (size_t i = 0; i < ia.pixels.size(); ++i) {
    const glm::vec3 d = glm::abs(ia.pixels[i] - ib.pixels[i]);
    diff += d.x + d.y + d.z;
  }
  EXPECT_GT(diff, 0.5f) << "--deviation-colormap had no effect";
  const Result bad = run(common + tmp("dev-bad.png") + " --deviation-colormap jet");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(lastLine(bad.err).find("viridis, magma, inferno, coolwarm, grey"), std::string::npos)
      << bad.err;
  EXPECT_EQ(run("optimize --scene builtin:shepp-logan --deviation-colormap jet").code, 1);
}

TEST(Cli, BadInputExitsTwoWithOneLineNamingTheFile) {
  const std::string bad = tmp("truncated.raw");
  {
    std::ofstream(bad, std::ios::binary) << "abc";
    std::ofstream(bad + ".json") << R"({"dims":[4,4,4],"type":"float32","spacing":[1,1,1]})";
  }
  Result r = run("info " + bad);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(lastLine(r.err).find("truncated.raw"), std::string::npos) << r.err;
  r = run("render --volume " + tmp("missing.nii") + " --out " + tmp("x.png"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(lastLine(r.err).find("missing.nii"), std::string::npos);
  const std::string tf = tmp("broken-tf.json");
  std::ofstream(tf) << "{ not json";
  const std::string never = tmp("never-written.png");
  r = run("render --scene builtin:shepp-logan --resolution 16 --tf " + tf + " --out " + never);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(lastLine(r.err).find("broken-tf.json"), std::string::npos);
  EXPECT_FALSE(fs::exists(never)) << "no output for a failed run";
}

TEST(Cli, OptimizeReportsFallingEnergyAndRisingVisibility) {
  const std::string out = tmp("opt.png");
  Result r =
      run("optimize --scene builtin:shepp-logan --resolution 48 --size 64x64 --levels 2 "
          "--iterations 30 --out " +
          out + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_GT(j["iterations"].size(), 10u);
  EXPECT_LT(j["final"]["energy"].get<double>(), j["initial"]["energy"].get<double>());
  EXPECT_GT(j["final"]["visibility_view"].get<double>(),
            j["initial"]["visibility_view"].get<double>());
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(fs::exists(tmp("opt-before.png")));
}

TEST(Cli, OptimizeWithContextSurfacesMasksLensAndDeviationView) {
  // A small raw volume: a ball of value 100 in 0; the ball is the context surface (iso 50).
  const std::string raw = tmp("ball.raw");
  writeBallRaw(raw, [](float r) { return r < 4.f ? 150.f : (r < 8.f ? 100.f : 0.f); });
  std::ofstream(tmp("g.json")) << R"({"points":[[0,0],[120,0],[140,1]]})";
  const std::string out = tmp("ctx.png");
  Result r = run("optimize --volume " + raw + " --importance " + tmp("g.json") +
                 " --context iso:50:inside-high --shell 1 --lambda 0.5 --redist-iterations 16"
                 " --lens 10,10,5,1.5 --deviation-view --view-from 90,0,3 --size 48x48"
                 " --levels 1 --iterations 5 --out " +
                 out + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["iterations"].size(), 5u);
  EXPECT_TRUE(j["final"].contains("sdf_step_ms"));
  EXPECT_TRUE(j["final"].contains("max_deviation_voxels"));
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(fs::exists(tmp("ctx-view.png")));
  // Malformed context and lens specifications are usage errors; a missing mesh is bad input.
  EXPECT_EQ(
      run("optimize --volume " + raw + " --importance " + tmp("g.json") + " --context iso:abc")
          .code,
      1);
  EXPECT_EQ(run("optimize --volume " + raw + " --importance " + tmp("g.json") + " --lens 1,2").code,
            1);
  EXPECT_EQ(run("optimize --volume " + raw + " --importance " + tmp("g.json") +
                " --context mesh:" + tmp("nope.obj"))
                .code,
            2);
}

// `compare` takes the importance a --tf preset carries, as `optimize` does: a CT-like ball (skin
// -400 HU around bone 700 HU) with preset:ct-skin-bone and no --importance runs; a preset with no
// importance named in --importance is a usage error naming it, and no image is written.
TEST(Cli, CompareTakesThePresetImportanceAsOptimizeDoes) {
  const std::string raw = tmp("ct-ball.raw");
  writeBallRaw(raw, [](float r) { return r < 4.f ? 700.f : (r < 9.f ? 0.f : -1000.f); });
  const std::string out = tmp("ct-compare.png");
  fs::remove(out);
  Result r = run("compare --volume " + raw +
                 " --tf preset:ct-skin-bone --context iso:-400 --size 24x24 --levels 1"
                 " --iterations 1 --out " +
                 out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
  fs::remove(out);
  r = run("compare --volume " + raw +
          " --tf preset:ct-skin-bone --importance preset:generic"
          " --size 24x24 --levels 1 --iterations 1 --out " +
          out);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(lastLine(r.err).find("preset:generic"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// Every number a user types is checked before anything runs (issue 13): NaN and infinite values,
// cameras and lights on the volume's centre or 1e30 radii away, ray-march steps that would run
// for hours, level-set and optimiser settings the kernels would turn into NaN fields. Each is a
// usage error (exit 1) whose one line names the option or the setting, and no image is written.
// Before, a NaN camera or a 1e30 distance ended in a segmentation fault, --step 1e-6 ran for
// hours and --lambda nan was accepted.
TEST(Cli, EveryNumberAUserTypesIsChecked) {
  const std::string out = tmp("checked.png");
  const std::string render = "render --scene builtin:shepp-logan --resolution 16 --size 16x16 ";
  const std::string optimize =
      "optimize --scene builtin:shepp-logan --resolution 16 --size 16x16 --levels 1 "
      "--iterations 1 ";
  const struct {
    std::string args, says;
  } cases[] = {
      {render + "--camera nan,0,2", "--camera: 'nan,0,2' is not a list of finite numbers"},
      {render + "--camera 0,inf,2", "is not a list of finite numbers"},
      {render + "--camera 0,0,1e30", "--camera: the distance must be"},
      {render + "--camera 0,0,1e-30", "--camera: the distance must be"},
      {render + "--camera 0,0,0", "--camera: the distance must be"},
      {render + "--step 1e-6", "the ray-march step must be 0.05..16"},
      {render + "--step inf", "the ray-march step must be"},
      {render + "--step nan", "the ray-march step must be"},
      {optimize + "--camera nan,0,2", "is not a list of finite numbers"},
      {optimize + "--light 0,0,1e30", "--light: the distance must be"},
      {optimize + "--view-from 0,0,1e30", "--view-from: the distance must be"},
      {optimize + "--lambda nan", "lambda must be finite"},
      {optimize + "--lambda -1", "lambda must be finite, >= 0"},
      {optimize + "--level-set-reach inf", "the level-set reach must be"},
      {optimize + "--level-set-band nan", "the narrow band must be"},
      {optimize + "--redist-iterations -5", "redistancing iterations must be"},
      {optimize + "--tolerance nan", "the energy tolerance must be finite"},
      {optimize + "--lens 8,8,4,1e30", "the lens needs"},
  };
  for (const auto& c : cases) {
    std::filesystem::remove(out);
    const Result r = run(c.args + " --out " + out);
    EXPECT_EQ(r.code, 1) << c.args << "\n" << r.err;
    EXPECT_NE(lastLine(r.err).find(c.says), std::string::npos) << c.args << ": " << lastLine(r.err);
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
  // Inside the volume, at an elevation of 90 degrees and at the finest step: fine.
  for (const std::string args :
       {"--camera 0,0,0.5", "--camera 30,90,2", "--step 0.05", "--camera 1e6,0,2"}) {
    const Result r = run(render + args + " --out " + out);
    EXPECT_EQ(r.code, 0) << args << "\n" << r.err;
  }
}

// Paths that name a device, a FIFO or a folder are refused, for input (a transfer function
// /dev/zero was read without end, a FIFO blocked) and for output (the written file was renamed
// over the target: as root, --out /dev/full replaced the device with a PNG). The output check
// comes before the work: optimize refuses a FIFO as --out before it optimises.
TEST(Cli, DevicesPipesAndFoldersAreRefused) {
  const std::string fifo = tmp("a-fifo");
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string render = "render --scene builtin:shepp-logan --resolution 16 --size 16x16 ";
  Result r = run(render + "--tf /dev/zero --out " + tmp("dev.png"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(lastLine(r.err).find("/dev/zero: is a device, pipe or socket"), std::string::npos)
      << r.err;
  r = run(render + "--tf " + fifo + " --out " + tmp("dev.png"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(lastLine(r.err).find(fifo + ": is a device, pipe or socket"), std::string::npos)
      << r.err;
  r = run(render + "--out " + fifo);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(lastLine(r.err).find("visopt writes only regular files"), std::string::npos) << r.err;
  EXPECT_TRUE(std::filesystem::is_fifo(fifo)) << "the FIFO is still a FIFO";
  r = run(render + "--out " + tmp(""));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(lastLine(r.err).find("is a folder"), std::string::npos) << r.err;
  r = run("optimize --scene builtin:shepp-logan --resolution 16 --size 16x16 --out " + fifo);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.find("level 0"), std::string::npos) << "refused before optimising";
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  std::filesystem::remove(fifo);
}

// The help of each option shows its default, and for the optimisation's settings that default is
// the library's own (the CLI once said "default 6" for a band of 8).
TEST(Cli, HelpShowsTheLibrarysDefaults) {
  const Result r = run("optimize --help");
  ASSERT_EQ(r.code, 0) << r.err;
  // "  --lambda FLOAT=0.3   How strongly ..." -> 0.3
  auto shown = [&](const std::string& option) -> double {
    const size_t at = r.out.find("  " + option + " ");
    if (at == std::string::npos) return std::nan("");
    const size_t eq = r.out.find('=', at);
    const size_t eol = r.out.find('\n', at);
    if (eq == std::string::npos || eq > eol) return std::nan("");
    return std::strtod(r.out.c_str() + eq + 1, nullptr);
  };
  const visopt::ExtinctionSettings e;
  const visopt::LevelSetSettings ls;
  const std::pair<const char*, double> expected[] = {
      {"--lambda", ls.lambda},
      {"--level-set-reach", ls.reach},
      {"--level-set-band", ls.band},
      {"--redist-iterations", ls.redistanceIterations},
      {"--rho", e.rho},
      {"--q", e.q},
      {"--r", e.r},
      {"--lr", e.learningRate},
      {"--mu-max", e.muMax},
      {"--levels", e.levels},
      {"--iterations", e.maxIterationsPerLevel},
      {"--tolerance", e.tolerance},
      {"--frustum-scale", e.frustumScale}};
  for (const auto& [option, value] : expected)
    EXPECT_NEAR(shown(option), value, 1e-6 * std::max(1.0, std::abs(value))) << option << "\n"
                                                                             << r.out;
  EXPECT_NE(r.out.find("--size TEXT=512x512"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--camera TEXT=the scene's view"), std::string::npos) << r.out;

  const Result render = run("render --help");
  ASSERT_EQ(render.code, 0);
  const size_t step = render.out.find("--step FLOAT=");
  ASSERT_NE(step, std::string::npos) << render.out;
  EXPECT_FLOAT_EQ(std::strtof(render.out.c_str() + step + 13, nullptr),
                  visopt::RenderSettings{}.stepFactor);
}
