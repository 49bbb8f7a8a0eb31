// Transfer functions: piecewise-linear lookups, the ParaView unit-distance extinction, baking,
// the JSON formats (visopt and ParaView's exported colour maps), malformed input and presets.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tf/presets.h"
#include "visopt/error.h"
#include "visopt/transfer_function.h"

namespace fs = std::filesystem;
using visopt::Error;
using visopt::ErrorKind;
using visopt::TransferFunction;

namespace {

TransferFunction threePoint() {
  TransferFunction tf;
  tf.name = "three";
  // Deliberately unsorted: validate() sorts.
  tf.opacity = {{20.0, 0.5f}, {0.0, 0.f}, {10.0, 1.f}};
  tf.color = {{10.0, {1.f, 0.5f, 0.f}}, {0.0, {0.f, 0.f, 0.f}}};
  tf.validate();
  return tf;
}

std::string tmpDir(const std::string& name) {
  fs::path dir = fs::path(VISOPT_TEST_TMP) / ("tf-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Runs f, expects Error(BadInput) whose one-line message starts with "ORIGIN: ".
template <class F>
void expectBadInput(F f, const std::string& origin, const std::string& fragment = "") {
  try {
    f();
    FAIL() << "no error for " << origin;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput) << e.what();
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(origin + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    if (!fragment.empty()) {
      EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
    }
  }
}

const std::string kResources = VISOPT_RESOURCE_DIR;

}  // namespace

TEST(TransferFunction, InterpolatesPiecewiseLinearAndClampsOutside) {
  const TransferFunction tf = threePoint();
  ASSERT_EQ(tf.opacity.size(), 3u);
  EXPECT_EQ(tf.opacity[0].value, 0.0);  // sorted
  EXPECT_FLOAT_EQ(tf.opacityAt(-5.0), 0.f);
  EXPECT_FLOAT_EQ(tf.opacityAt(0.0), 0.f);
  EXPECT_FLOAT_EQ(tf.opacityAt(5.0), 0.5f);
  EXPECT_FLOAT_EQ(tf.opacityAt(2.5), 0.25f);
  EXPECT_FLOAT_EQ(tf.opacityAt(10.0), 1.f);
  EXPECT_FLOAT_EQ(tf.opacityAt(15.0), 0.75f);
  EXPECT_FLOAT_EQ(tf.opacityAt(20.0), 0.5f);
  EXPECT_FLOAT_EQ(tf.opacityAt(1e6), 0.5f);
  const glm::vec3 c = tf.colorAt(2.5);
  EXPECT_FLOAT_EQ(c.r, 0.25f);
  EXPECT_FLOAT_EQ(c.g, 0.125f);
  EXPECT_FLOAT_EQ(c.b, 0.f);
  EXPECT_EQ(tf.colorAt(-1.0), glm::vec3(0.f));
  EXPECT_EQ(tf.colorAt(100.0), glm::vec3(1.f, 0.5f, 0.f));
}

TEST(TransferFunction, StepAtRepeatedValue) {
  TransferFunction tf;
  tf.opacity = {{0.0, 0.f}, {5.0, 0.f}, {5.0, 1.f}, {10.0, 1.f}};
  tf.color = {{0.0, glm::vec3(1.f)}};
  tf.validate();
  EXPECT_FLOAT_EQ(tf.opacityAt(4.999), 0.f);
  EXPECT_FLOAT_EQ(tf.opacityAt(5.0), 1.f);  // right-continuous
  EXPECT_FLOAT_EQ(tf.opacityAt(7.0), 1.f);
}

TEST(TransferFunction, OpacityIsThatOfASlabOfUnitDistance) {
  TransferFunction tf;
  tf.color = {{0.0, glm::vec3(1.f)}};
  for (float unit : {0.37f, 1.f, 2.5f}) {
    for (float alpha : {0.f, 0.1f, 0.5f, 0.9f, 0.99f}) {
      tf.opacity = {{0.0, alpha}};
      tf.unitDistance = unit;
      const float mu = tf.extinctionAt(0.0, 123.f);  // the default must not matter
      EXPECT_NEAR(std::exp(-double(mu) * unit), 1.0 - alpha, 1e-6) << unit << " " << alpha;
      // Independent of the renderer's step: n steps of unit / n give the same slab opacity.
      for (int n : {1, 7, 100}) {
        double transmittance = 1.0;
        for (int i = 0; i < n; ++i) transmittance *= std::exp(-double(mu) * unit / n);
        EXPECT_NEAR(transmittance, 1.0 - alpha, 1e-5);
      }
    }
  }
  // unitDistance 0: the caller's default (the volume's smallest spacing) is the unit.
  tf.opacity = {{0.0, 0.6f}};
  tf.unitDistance = 0.f;
  EXPECT_NEAR(std::exp(-double(tf.extinctionAt(0.0, 0.7f)) * 0.7), 0.4, 1e-6);
  EXPECT_THROW(tf.extinctionAt(0.0, 0.f), Error);
  // Opacity 1 is clamped to 1 - 1e-4: large but finite.
  tf.opacity = {{0.0, 1.f}};
  tf.unitDistance = 2.f;
  const float mu = tf.extinctionAt(0.0, 1.f);
  EXPECT_TRUE(std::isfinite(mu));
  EXPECT_NEAR(std::exp(-double(mu) * 2.0), 1e-4, 1e-7);
}

TEST(TransferFunction, BakeSamplesTheDataRange) {
  TransferFunction tf = threePoint();
  tf.unitDistance = 2.f;
  // 5 entries over [0, 20]: values 0, 5, 10, 15, 20.
  const visopt::TransferTable table = tf.bake(0.0, 20.0, 1.f, 5);
  ASSERT_EQ(table.albedoExtinction.size(), 5u);
  const float alphas[5] = {0.f, 0.5f, 1.f, 0.75f, 0.5f};
  const glm::vec3 colors[5] = {
      {0.f, 0.f, 0.f}, {0.5f, 0.25f, 0.f}, {1.f, 0.5f, 0.f}, {1.f, 0.5f, 0.f}, {1.f, 0.5f, 0.f}};
  float maxMu = 0.f;
  for (int i = 0; i < 5; ++i) {
    const glm::vec4 e = table.albedoExtinction[size_t(i)];
    EXPECT_FLOAT_EQ(e.r, colors[i].r) << i;
    EXPECT_FLOAT_EQ(e.g, colors[i].g) << i;
    EXPECT_FLOAT_EQ(e.b, colors[i].b) << i;
    const double a = std::min(alphas[i], 1.f - 1e-4f);
    EXPECT_NEAR(e.w, -std::log(1.0 - a) / 2.0, 1e-3 * (1.0 + e.w)) << i;
    maxMu = std::max(maxMu, e.w);
  }
  EXPECT_FLOAT_EQ(table.maxExtinction, maxMu);
  EXPECT_FLOAT_EQ(table.maxExtinction, table.albedoExtinction[2].w);
  // Default size and a range narrower than the points.
  const visopt::TransferTable big = tf.bake(5.0, 15.0, 1.f);
  ASSERT_EQ(big.albedoExtinction.size(), 1024u);
  EXPECT_FLOAT_EQ(big.albedoExtinction.front().w, tf.extinctionAt(5.0, 1.f));
  EXPECT_FLOAT_EQ(big.albedoExtinction.back().w, tf.extinctionAt(15.0, 1.f));
  EXPECT_THROW(tf.bake(0.0, 1.0, 1.f, 1), Error);
  EXPECT_THROW(tf.bake(1.0, 0.0, 1.f), Error);
}

TEST(TransferFunction, JsonRoundTripIsExact) {
  TransferFunction tf;
  tf.name = "round \"trip\" \\ test";
  tf.unitDistance = 0.1f;
  tf.opacity = {{-1024.5, 0.f}, {1.0 / 3.0, 0.1f}, {1e-7, 0.33333334f}, {3071.0, 1.f}};
  tf.color = {{-1024.5, {0.1f, 0.2f, 0.3f}}, {2.0 / 3.0, {1.f / 3.f, 0.7f, 1.f}}};
  tf.validate();
  const std::string dir = tmpDir("roundtrip");
  const std::string path = dir + "/tf.json";
  tf.save(path);
  tf.save(path);  // overwriting works
  const TransferFunction back = TransferFunction::load(path);
  EXPECT_EQ(back.name, tf.name);
  EXPECT_EQ(back.unitDistance, tf.unitDistance);
  ASSERT_EQ(back.opacity.size(), tf.opacity.size());
  ASSERT_EQ(back.color.size(), tf.color.size());
  for (size_t i = 0; i < tf.opacity.size(); ++i) {
    EXPECT_EQ(back.opacity[i].value, tf.opacity[i].value);
    EXPECT_EQ(back.opacity[i].opacity, tf.opacity[i].opacity);
  }
  for (size_t i = 0; i < tf.color.size(); ++i) {
    EXPECT_EQ(back.color[i].value, tf.color[i].value);
    EXPECT_EQ(back.color[i].rgb, tf.color[i].rgb);
  }
  EXPECT_EQ(TransferFunction::fromJson(tf.toJson(), "mem").toJson(), tf.toJson());
  // The save is atomic: only the target is left in the folder.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "tf.json");
  }
  EXPECT_EQ(files, 1);
  // A file without a name takes its stem.
  writeFile(dir + "/unnamed.json",
            R"({"format":"visopt-transfer-function","opacity":[[0,0.5]],"color":[[0,1,1,1]]})");
  EXPECT_EQ(TransferFunction::load(dir + "/unnamed.json").name, "unnamed");
  expectBadInput([&] { tf.save(dir + "/no/such/dir/tf.json"); }, dir + "/no/such/dir/tf.json");
}

TEST(TransferFunction, ImportsParaViewExportArrayFormWithPoints) {
  const std::string path = kResources + "/transfer-functions/paraview-export-example.json";
  const TransferFunction tf = TransferFunction::load(path);
  EXPECT_EQ(tf.name, "Cool to Warm (CT export)");
  ASSERT_EQ(tf.color.size(), 3u);
  ASSERT_EQ(tf.opacity.size(), 4u);
  EXPECT_EQ(tf.unitDistance, 0.f);
  EXPECT_FLOAT_EQ(tf.opacityAt(-1000.0), 0.f);
  EXPECT_FLOAT_EQ(tf.opacityAt(-600.0), 0.05f);
  EXPECT_FLOAT_EQ(tf.opacityAt(400.0), 0.8f);
  EXPECT_FLOAT_EQ(tf.opacityAt(5000.0), 1.f);
  EXPECT_NEAR(tf.colorAt(500.0).r, 0.865f, 1e-6);
  EXPECT_NEAR(tf.colorAt(-1000.0).b, 0.752941176471f, 1e-6);
}

TEST(TransferFunction, ImportsParaViewObjectFormAndRampWithoutPoints) {
  // Object form (not wrapped in a list), no "Points": a linear ramp over the RGBPoints range.
  const TransferFunction obj = TransferFunction::fromJson(
      R"({"ColorSpace":"RGB","Name":"Ramp","RGBPoints":[10,0,0,0, 30,1,1,1]})", "obj.json");
  EXPECT_EQ(obj.name, "Ramp");
  ASSERT_EQ(obj.opacity.size(), 2u);
  EXPECT_FLOAT_EQ(obj.opacityAt(10.0), 0.f);
  EXPECT_FLOAT_EQ(obj.opacityAt(20.0), 0.5f);
  EXPECT_FLOAT_EQ(obj.opacityAt(30.0), 1.f);
  EXPECT_FLOAT_EQ(obj.colorAt(25.0).g, 0.75f);
  // Array form with Points; a leading categorical entry (no RGBPoints) is skipped.
  const TransferFunction arr = TransferFunction::fromJson(
      R"([{"Name":"cats","IndexedColors":[1,0,0]},
          {"ColorSpace":"Diverging","Name":"Preset","RGBPoints":[0,0,0,1, 1,1,0,0],
           "Points":[0,0.2,0.5,0, 1,0.6,0.5,0]}])",
      "arr.json");
  EXPECT_EQ(arr.name, "Preset");
  EXPECT_FLOAT_EQ(arr.opacityAt(0.5), 0.4f);
  EXPECT_FLOAT_EQ(arr.colorAt(0.25).b, 0.75f);
  // Array form without Points.
  const TransferFunction arrRamp =
      TransferFunction::fromJson(R"([{"Name":"r","RGBPoints":[-1,0,0,0, 1,1,1,1]}])", "r.json");
  EXPECT_FLOAT_EQ(arrRamp.opacityAt(0.0), 0.5f);
}

TEST(TransferFunction, MalformedInputIsBadInputNamingTheOrigin) {
  const auto parse = [](const std::string& text) {
    return [text] { TransferFunction::fromJson(text, "in.json"); };
  };
  expectBadInput(parse("{"), "in.json", "invalid JSON");
  expectBadInput(parse(""), "in.json", "invalid JSON");
  expectBadInput(parse(R"([{"RGBPoints":[0,0,0,0, 1,1,1]}])"), "in.json", "multiple of 4");
  expectBadInput(parse(R"([{"RGBPoints":[0,0,0,0], "Points":[0,1,0.5]}])"), "in.json",
                 "multiple of 4");
  expectBadInput(parse(R"([{"RGBPoints":[0,NaN,0,0]}])"), "in.json", "invalid JSON");
  expectBadInput(parse(R"([{"RGBPoints":[0,1e999,0,0]}])"), "in.json");
  expectBadInput(parse(R"([{"RGBPoints":[0,0,0,0], "Points":[0,1.5,0.5,0]}])"), "in.json",
                 "outside [0, 1]");
  expectBadInput(parse(R"([{"RGBPoints":[0,2,0,0]}])"), "in.json", "outside [0, 1]");
  expectBadInput(parse(R"([{"RGBPoints":[0,"red",0,0]}])"), "in.json", "expected a number");
  expectBadInput(parse(R"([{"RGBPoints":[]}])"), "in.json", "empty");
  expectBadInput(parse(R"([])"), "in.json");
  expectBadInput(parse(R"({"something":"else"})"), "in.json");
  expectBadInput(parse("42"), "in.json");
  const std::string head = R"({"format":"visopt-transfer-function","version":1,)";
  expectBadInput(parse(head + R"("opacity":[[0,1.5]],"color":[[0,1,1,1]]})"), "in.json",
                 "outside [0, 1]");
  expectBadInput(parse(head + R"("opacity":[[0,0.5,7]],"color":[[0,1,1,1]]})"), "in.json",
                 "opacity[0]");
  expectBadInput(parse(head + R"("opacity":[],"color":[[0,1,1,1]]})"), "in.json",
                 "no opacity points");
  expectBadInput(parse(head + R"("opacity":[[0,0.5]]})"), "in.json", "color");
  expectBadInput(parse(head + R"("opacity":"x","color":[[0,1,1,1]]})"), "in.json", "not a list");
  expectBadInput(parse(head + R"("unitDistance":-1,"opacity":[[0,0.5]],"color":[[0,1,1,1]]})"),
                 "in.json", "unitDistance");
  expectBadInput(parse(R"({"format":"visopt-transfer-function","version":99,"opacity":[[0,0.5]],
                           "color":[[0,1,1,1]]})"),
                 "in.json", "newer");
  expectBadInput(parse(R"({"format":"other","opacity":[[0,0.5]],"color":[[0,1,1,1]]})"), "in.json",
                 "format");

  // Values set in code are checked by validate() too.
  TransferFunction tf = threePoint();
  tf.opacity[1].value = std::nan("");
  expectBadInput([&] { tf.validate("mine"); }, "mine", "not finite");
  tf = threePoint();
  tf.color[0].rgb.g = -0.1f;
  expectBadInput([&] { tf.validate("mine"); }, "mine", "outside [0, 1]");

  // Files.
  const std::string dir = tmpDir("malformed");
  expectBadInput([&] { TransferFunction::load(dir + "/missing.json"); }, dir + "/missing.json",
                 "no such file");
  expectBadInput([&] { TransferFunction::load(dir); }, dir, "directory");
  writeFile(dir + "/bad.json", "[{\"RGBPoints\": [0, 0, 0]}]");
  expectBadInput([&] { TransferFunction::load(dir + "/bad.json"); }, dir + "/bad.json");
}

TEST(TransferFunction, PresetsLoadAndAreValid) {
  const auto names = TransferFunction::presetNames();
  for (const char* expected : {"ct-skin-bone", "ct-bone", "mri", "generic"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  for (const auto& name : names) {
    TransferFunction tf = TransferFunction::preset(name, -1000.0, 3000.0);
    EXPECT_EQ(tf.name, name);
    EXPECT_NO_THROW(tf.validate(name));
    EXPECT_FALSE(tf.opacity.empty());
    EXPECT_FALSE(tf.color.empty());
    EXPECT_GE(tf.unitDistance, 0.f);
    // The shipped file agrees with the compiled-in fallback.
    const std::string file = kResources + "/transfer-functions/" + name + ".json";
    ASSERT_TRUE(fs::exists(file)) << file;
    const TransferFunction fromFile = TransferFunction::load(file);
    const TransferFunction builtin = visopt::tfpresets::compiledIn(name);
    EXPECT_EQ(fromFile.toJson(), [&] {
      TransferFunction b = builtin;
      b.name = fromFile.name;
      return b.toJson();
    }()) << name;
  }
  // What the CT preset promises: air clear, skin visible, soft tissue faint, bone opaque ivory.
  const TransferFunction ct = TransferFunction::preset("ct-skin-bone");
  EXPECT_EQ(ct.opacityAt(-1000.0), 0.f);
  EXPECT_GT(ct.opacityAt(-300.0), 0.15f);
  EXPECT_LT(ct.opacityAt(50.0), 0.1f);
  EXPECT_GT(ct.opacityAt(1000.0), 0.8f);
  EXPECT_GT(ct.colorAt(1000.0).r, 0.9f);
  EXPECT_GT(ct.unitDistance, 0.5f);
  const TransferFunction bone = TransferFunction::preset("ct-bone");
  EXPECT_EQ(bone.opacityAt(0.0), 0.f);
  EXPECT_GT(bone.opacityAt(1000.0), 0.8f);
  const TransferFunction mri = TransferFunction::preset("mri");
  EXPECT_EQ(mri.opacityAt(0.0), 0.f);
  EXPECT_GT(mri.opacityAt(255.0), 0.3f);
  // "generic" spans the data range it is given.
  const TransferFunction generic = TransferFunction::preset("generic", -50.0, 150.0);
  EXPECT_EQ(generic.opacity.front().value, -50.0);
  EXPECT_EQ(generic.opacity.back().value, 150.0);
  EXPECT_EQ(generic.opacityAt(-50.0), 0.f);
  EXPECT_GT(generic.opacityAt(150.0), 0.f);
  EXPECT_GT(generic.colorAt(150.0).r, generic.colorAt(150.0).b);  // warm at the top
  try {
    TransferFunction::preset("no-such-preset");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

TEST(TransferFunction, PresetResourceDirectoryOverrideAndFallback) {
  const std::string dir = tmpDir("resources");
  fs::create_directories(dir + "/transfer-functions");
  // An empty override folder: the compiled-in copy is used.
  setenv("VISOPT_RESOURCES", dir.c_str(), 1);
  const TransferFunction fallback = TransferFunction::preset("ct-bone");
  EXPECT_EQ(fallback.toJson(), visopt::tfpresets::compiledIn("ct-bone").toJson());
  // A preset file in the override folder wins.
  TransferFunction custom = visopt::tfpresets::compiledIn("mri");
  custom.opacity = {{0.0, 0.f}, {255.0, 0.123f}};
  custom.save(dir + "/transfer-functions/mri.json");
  const TransferFunction overridden = TransferFunction::preset("mri");
  EXPECT_FLOAT_EQ(overridden.opacityAt(255.0), 0.123f);
  // A broken preset file is an error naming it, not a silent fallback.
  writeFile(dir + "/transfer-functions/ct-skin-bone.json", "{oops");
  expectBadInput([] { TransferFunction::preset("ct-skin-bone"); },
                 dir + "/transfer-functions/ct-skin-bone.json");
  unsetenv("VISOPT_RESOURCES");
  EXPECT_NE(TransferFunction::preset("mri").opacityAt(255.0), 0.123f);
}
