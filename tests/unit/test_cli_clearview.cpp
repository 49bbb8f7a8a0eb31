// `visopt render --clearview SPEC` as a script would use it: the ClearView hotspot render
// (Krüger et al. 2006) configured by comma-separated key=value. A malformed SPEC is a usage error
// (exit 1) whose one line on stderr names --clearview and the offending element, and no image is
// written; a good one writes the PNG at --size and, with --json, reports the extraction and
// compositing times.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "visopt/image.h"

namespace fs = std::filesystem;

namespace {

using Result = visopt::testing::CliResult;

Result run(const std::string& args) {
  return visopt::testing::runCli(args, "cli-clearview");
}

std::string tmp(const std::string& name) {
  return (fs::path(VISOPT_TEST_TMP) / "cli-clearview" / name).string();
}

// stderr without the CPU-backend notice, line by line.
std::vector<std::string> errorLines(const std::string& err) {
  std::vector<std::string> lines;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line.find("using the CPU backend") == std::string::npos)
      lines.push_back(line);
  return lines;
}

// The shepp-logan scene carries one context surface (the skull) and an importance.
const std::string kShepp = "render --scene builtin:shepp-logan --resolution 32 --size 64x48 --out ";

// A SPEC the tool must refuse: exit 1, one line naming --clearview and `names`, no image.
void expectRefused(const std::string& command, const std::string& out, const std::string& spec,
                   const std::string& names) {
  fs::remove(out);
  const Result r = run(command + out + " --clearview '" + spec + "'");
  EXPECT_EQ(r.code, 1) << spec << "\n" << r.err;
  const std::vector<std::string> lines = errorLines(r.err);
  ASSERT_EQ(lines.size(), 1u) << spec << "\n" << r.err;
  EXPECT_NE(lines[0].find("--clearview"), std::string::npos) << spec << ": " << lines[0];
  EXPECT_NE(lines[0].find(names), std::string::npos) << spec << ": " << lines[0];
  EXPECT_FALSE(fs::exists(out)) << spec;
}

// A 24^3 float32 ball (150 in the core, 100 in the shell, 0 outside): no context surface, no
// importance.
std::string ballVolume() {
  const std::string raw = tmp("ball.raw");
  std::ofstream f(raw, std::ios::binary);
  for (int k = 0; k < 24; ++k)
    for (int j = 0; j < 24; ++j)
      for (int i = 0; i < 24; ++i) {
        const int r2 = (i - 12) * (i - 12) + (j - 12) * (j - 12) + (k - 12) * (k - 12);
        const float v = r2 < 16 ? 150.f : (r2 < 64 ? 100.f : 0.f);
        f.write(reinterpret_cast<const char*>(&v), 4);
      }
  std::ofstream(raw + ".json") << R"({"dims":[24,24,24],"type":"float32","spacing":[1,1,1]})";
  return raw;
}

}  // namespace

TEST(CliClearView, RendersTheHotspotAndReportsItsTimes) {
  const std::string out = tmp("hotspot.png");
  fs::remove(out);
  const Result r = run(kShepp + out + " --clearview measure=distance,at=10:20,size=20 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);  // exactly one JSON object
  ASSERT_TRUE(j.contains("clearview_extract_ms")) << r.out;
  ASSERT_TRUE(j.contains("clearview_composite_ms")) << r.out;
  EXPECT_GE(j["clearview_extract_ms"].get<double>(), 0.0);
  EXPECT_GE(j["clearview_composite_ms"].get<double>(), 0.0);
  const auto& cv = j["clearview"];
  for (const char* key :
       {"extract_ms", "composite_ms", "context_pixels", "focus_pixels", "focus_point"})
    EXPECT_TRUE(cv.contains(key)) << key;
  EXPECT_EQ(cv["extract_ms"], j["clearview_extract_ms"]);
  EXPECT_EQ(cv["composite_ms"], j["clearview_composite_ms"]);
  EXPECT_GE(cv["context_pixels"].get<long long>(), 0);
  EXPECT_GT(cv["focus_pixels"].get<long long>(), 0);  // the tumours, importance 0.5
  EXPECT_LE(cv["focus_pixels"].get<long long>(), 64 * 48);
  EXPECT_TRUE(cv["focus_point"].is_null() ||
              (cv["focus_point"].is_array() && cv["focus_point"].size() == 3u))
      << cv["focus_point"];
  EXPECT_EQ(cv["context"], "surface:0");     // the scene's context surface by default
  EXPECT_EQ(cv["focus"], "importance:0.5");  // and its importance
  EXPECT_EQ(j["image"]["width"], 64);
  EXPECT_EQ(j["image"]["height"], 48);
  ASSERT_TRUE(fs::exists(out));
  const visopt::Image image = visopt::readPng(out);
  EXPECT_EQ(image.width, 64);
  EXPECT_EQ(image.height, 48);
}

TEST(CliClearView, EveryKeyIsAccepted) {
  const std::string out = tmp("every-key.png");
  fs::remove(out);
  const Result r = run(kShepp + out +
                       " --clearview 'context=iso:0.25,focus=importance,volume=1,"
                       "measure=view-distance,shader=cool-warm,focus-shader=diffuse,at=32.5:-1,"
                       "size=15,weight=2,distance-scale=4,border=0,ambient=0.3,light=scene'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ClearView"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out));
  // An empty SPEC keeps every default; surrounding blanks are ignored.
  ASSERT_EQ(run(kShepp + out + " --clearview ''").code, 0);
  ASSERT_EQ(run(kShepp + out + " --clearview ' size=20 , focus=importance:1 '").code, 0);
}

TEST(CliClearView, MalformedSpecsAreUsageErrorsNamingTheElement) {
  const std::string out = tmp("malformed.png");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"colour=red", "colour=red"},                  // unknown key
      {"size=10,size=20", "size=20"},                // duplicate key
      {"measure", "measure"},                        // missing '='
      {"size=abc", "size=abc"},                      // bad number
      {"at=10:2x", "at=10:2x"},                      // bad number, trailing garbage
      {"weight=nan", "weight=nan"},                  // NaN
      {"size=inf", "size=inf"},                      // infinity
      {"distance-scale=-1", "distance-scale=-1"},    // out of range
      {"size=0", "size=0"},                          // out of range: the size must be > 0
      {"weight=-0.5", "weight=-0.5"},                // out of range
      {"ambient=1.5", "ambient=1.5"},                // out of range
      {"weight=1e60", "weight=1e60"},                // beyond a float
      {"at=64:10", "at=64:10"},                      // outside the 64x48 image
      {"focus=importance:0", "focus=importance:0"},  // importance isovalue not in (0, 1]
      {"context=surface:-1", "context=surface:-1"},
      {"context=importance", "context=importance"},  // only focus has the bare form
      {"context=plane:3", "context=plane:3"},        // unknown layer kind
      {"measure=flatness", "measure=flatness"},      // unknown enum word
      {"shader=toon", "shader=toon"},
      {"focus-shader=metal", "focus-shader=metal"},
      {"light=sun", "light=sun"},
      {"volume=yes", "volume=yes"},
      {"border=2", "border=2"},
      {"size=10,,weight=1", "empty element 2"},  // empty element
      {"size=10,", "empty element 2"},
      // a fifth context layer (at most four), and a bad one among several
      {"context=iso:0.1,context=iso:0.2,context=iso:0.3,context=iso:0.4,context=iso:0.5",
       "context=iso:0.5"},
      {"focus=importance,focus=iso:abc", "focus=iso:abc"},
      {"=3", "=3"},
      {"size=", "size="},
  };
  for (const auto& [spec, names] : cases) expectRefused(kShepp, out, spec, names);
}

// context= and focus= repeat: the further context layers lie behind the first (each is reported
// with its pixels), each pixel shows the nearest focus layer.
TEST(CliClearView, RepeatedLayerKeysAddLayersInOrder) {
  const std::string out = tmp("layers-more.png");
  fs::remove(out);
  const Result r = run(kShepp + out +
                       " --clearview 'context=iso:0.1,context=iso:0.5,focus=importance,"
                       "focus=iso:0.9' --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto cv = nlohmann::json::parse(r.out)["clearview"];
  EXPECT_EQ(cv["context"], "iso:0.1");
  ASSERT_EQ(cv["deeper_contexts"].size(), 1u) << cv;
  EXPECT_EQ(cv["deeper_contexts"][0]["layer"], "iso:0.5");
  EXPECT_GT(cv["deeper_contexts"][0]["pixels"].get<long long>(), 0);
  EXPECT_LE(cv["deeper_contexts"][0]["pixels"].get<long long>(),
            cv["context_pixels"].get<long long>());
  EXPECT_EQ(cv["focus"], "importance:0.5");
  EXPECT_EQ(cv["more_foci"], nlohmann::json::array({"iso:0.9"}));
  EXPECT_TRUE(fs::exists(out));
  // One layer each: no lists.
  const Result one = run(kShepp + out + " --clearview context=iso:0.1 --json");
  ASSERT_EQ(one.code, 0) << one.err;
  const auto cv1 = nlohmann::json::parse(one.out)["clearview"];
  EXPECT_FALSE(cv1.contains("deeper_contexts"));
  EXPECT_FALSE(cv1.contains("more_foci"));
}

TEST(CliClearView, LayersMustExistInTheScene) {
  const std::string out = tmp("layers.png");
  // shepp-logan has one context surface.
  expectRefused(kShepp, out, "context=surface:3", "context=surface:3");
  // wall-and-membrane has no context surface: the default context must be given.
  const std::string blob =
      "render --scene builtin:wall-and-membrane --resolution 24 --size 32x32 --out ";
  expectRefused(blob, out, "size=10", "context=iso:VALUE");
  expectRefused(blob, out, "context=surface:0", "no context surface");
  // A volume file has neither a context surface nor an importance (--json: no load progress).
  const std::string ball = "render --volume " + ballVolume() + " --json --size 32x32 --out ";
  expectRefused(ball, out, "context=iso:50", "focus=iso:VALUE");
  expectRefused(ball, out, "context=iso:50,focus=importance", "no importance");
  fs::remove(out);
  const Result r = run(ball + out + " --clearview context=iso:50,focus=iso:125,size=6");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["clearview"]["context_pixels"].get<long long>(), 0);
  EXPECT_GT(j["clearview"]["focus_pixels"].get<long long>(), 0);
  EXPECT_TRUE(fs::exists(out));
}

TEST(CliClearView, RayCasterOptionsAreRefused) {
  const std::string out = tmp("conflict.png");
  for (const char* option : {"--deviation-view", "--preview"}) {
    fs::remove(out);
    const Result r = run(kShepp + out + " --clearview size=10 " + option);
    EXPECT_EQ(r.code, 1) << option << "\n" << r.err;
    const std::vector<std::string> lines = errorLines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_NE(lines[0].find("--clearview"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find(option), std::string::npos) << lines[0];
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(CliClearView, TheNormalRenderIsUnchanged) {
  const std::string out = tmp("normal.png");
  const Result r = run(kShepp + out + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j.contains("clearview"));
  EXPECT_FALSE(j.contains("clearview_extract_ms"));
  EXPECT_GT(j["samples"].get<double>(), 0.0);
}

// `visopt compare` shows ClearView as a fifth panel beside the four methods of Fig. 10.
TEST(CliClearView, CompareShowsClearViewAsTheFifthPanel) {
  const std::string out = tmp("compare.png");
  fs::remove(out);
  const Result r =
      run("compare --scene builtin:shepp-logan --resolution 48 --size 40x32 "
          "--iterations 2 --levels 1 --clearview measure=distance --out " +
          out + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["panels"].size(), 5u);
  EXPECT_EQ(j["panels"][4], "clearview");
  const visopt::Image img = visopt::readPng(out);
  EXPECT_EQ(img.width, 5 * 40 + 4 * 4);
  EXPECT_EQ(img.height, 32);
  // A malformed SPEC fails before the optimisation, naming the option.
  const Result bad =
      run("compare --scene builtin:shepp-logan --resolution 32 --size 32x32 "
          "--clearview measure=bogus --out " +
          tmp("compare-bad.png"));
  EXPECT_EQ(bad.code, 1);
  const std::vector<std::string> lines = errorLines(bad.err);
  ASSERT_EQ(lines.size(), 1u) << bad.err;
  EXPECT_NE(lines[0].find("--clearview"), std::string::npos) << lines[0];
  EXPECT_FALSE(fs::exists(tmp("compare-bad.png")));
}

// `visopt optimize --importance hotspot:X,Y,Z,R`: the hotspot as paper 000's importance.
TEST(CliClearView, OptimizeTakesTheHotspotAsItsImportance) {
  const Result r =
      run("optimize --scene builtin:shepp-logan --resolution 48 "
          "--importance hotspot:10,20,5,30 --iterations 5 --levels 1 --out " +
          tmp("hotspot.png") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["final"]["visibility_view"].get<double>(),
            j["initial"]["visibility_view"].get<double>());
  for (const char* bad : {"hotspot:10,20,5", "hotspot:10,20,nan,3", "hotspot:1,2,3,0",
                          "hotspot:1,2,3,-4", "hotspot:"}) {
    const Result b = run(std::string("optimize --scene builtin:shepp-logan --resolution 32 ") +
                         "--importance " + bad + " --out " + tmp("hotspot-bad.png"));
    EXPECT_EQ(b.code, 1) << bad << ": " << b.err;
    const std::vector<std::string> lines = errorLines(b.err);
    ASSERT_EQ(lines.size(), 1u) << b.err;
    EXPECT_NE(lines[0].find("--importance"), std::string::npos) << lines[0];
  }
}

// A session's hotspot settings (saved by the workstation's Hotspot panel) are the defaults of
// `render --session S --clearview SPEC`; SPEC's keys override them.
TEST(CliClearView, ASessionsHotspotSettingsAreTheDefaults) {
  const std::string session = tmp("hotspot.visopt-session");
  {
    std::ofstream f(session);
    f << R"({"format": "visopt-session", "version": 4,
             "data": {"builtin": "shepp-logan", "resolution": 32},
             "clearView": {"context": {"kind": "iso", "isovalue": 0.37},
                           "focus": {"kind": "importance", "isovalue": 0.5},
                           "measure": "view-distance", "weight": 0.3}})";
  }
  Result r = run("render --session " + session + " --size 48x40 --clearview '' --out " +
                 tmp("session-cv.png") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["clearview"]["measure"], "view-distance");
  EXPECT_EQ(j["clearview"]["context"], "iso:0.37");
  r = run("render --session " + session + " --size 48x40 --clearview measure=distance --out " +
          tmp("session-cv.png") + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["clearview"]["measure"], "distance");
  EXPECT_EQ(j["clearview"]["context"], "iso:0.37");
  // session-info says what the hotspot will show.
  r = run("session-info " + session);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("hotspot:     iso:0.37 over importance:0.5, view-distance"),
            std::string::npos)
      << r.out;
}
