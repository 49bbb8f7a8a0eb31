// Sessions never lose work: exact round trips (JSON and rendered image), migration of older
// versions, clear errors for damaged files, data found after a move and reported when missing,
// the world mask stored exactly, atomic saves that survive a crash mid-save, and the CLI.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "session/base64.h"
#include "session/content_hash.h"
#include "session/sha256.h"
#include "visopt/engine.h"
#include "visopt/error.h"
#include "visopt/session.h"

namespace fs = std::filesystem;
using namespace visopt;

namespace {

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::path(VISOPT_TEST_TMP) / "session" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// A float32 raw volume with its JSON sidecar: a smooth blob, anisotropic dims.
void writeRawVolume(const fs::path& raw, glm::ivec3 dims, float scale = 1.f) {
  std::vector<float> v(size_t(dims.x) * size_t(dims.y) * size_t(dims.z));
  size_t i = 0;
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int x = 0; x < dims.x; ++x) {
        const glm::vec3 p = (glm::vec3(x, j, k) + 0.5f) / glm::vec3(dims) - 0.5f;
        v[i++] = scale * std::max(0.f, 1.f - 2.5f * glm::length(p));
      }
  std::ofstream(raw, std::ios::binary)
      .write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
  writeText(raw.string() + ".json", "{\"dims\":[" + std::to_string(dims.x) + "," +
                                        std::to_string(dims.y) + "," + std::to_string(dims.z) +
                                        "],\"type\":\"float32\",\"spacing\":[1,1.5,2]}");
}

RenderSettings smallRender() {
  RenderSettings r;
  r.width = 40;
  r.height = 32;
  r.seed = 7;
  r.lightGridSize = 32;
  return r;
}

void expectSameImage(const Image& a, const Image& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  size_t differing = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) differing += a.pixels[i] != b.pixels[i];
  EXPECT_EQ(differing, 0u) << "PSNR " << psnr(a, b);
}

// Runs `f`, expecting Error(BadInput) with a one-line message that starts with `file`.
template <class F>
std::string expectBadInput(F&& f, const std::string& file) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput) << e.what();
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    return msg;
  }
  ADD_FAILURE() << "no error for " << file;
  return {};
}

// An engine with a built-in scene and every kind of setting changed from its default.
void setUpRichScene(Engine& engine) {
  engine.loadBuiltinScene("marschner-lobb", 24);
  ExtinctionSettings ext;
  ext.q = 12.5f;
  ext.optimizer = OptimizerKind::Adam;
  ext.levels = 2;
  engine.setExtinctionSettings(ext);
  LevelSetSettings ls;
  ls.lambda = 0.45f;
  ls.substeps = 3;
  engine.setLevelSetSettings(ls);
  engine.orbitCamera(33.f, 21.f, 2.7f);
  PointLight light = engine.light();
  light.intensity = 1.7f;
  light.color = {1.f, 0.9f, 0.8f};
  engine.setLight(light);
  engine.setLens({0.4f, 0.6f, 0.2f, 0.f});
  TransferFunction tf = engine.transferFunction();
  tf.name = "edited";
  tf.opacity.back().opacity = 0.61f;
  engine.setTransferFunction(tf);
  const GridSpec& g = engine.volume().grid();
  Field3D mask("mask", g, Precision::FP32);
  std::mt19937 rng(5);
  for (size_t i = 0; i < mask.size(); ++i) mask.set(i, float(rng() & 1u));
  engine.setWorldMask(std::move(mask));
  engine.setFrozen(true);
}

struct CliResult {
  int code = -1;
  std::string out, err;
};

CliResult runCli(const std::string& args) {
  const fs::path dir = fs::path(VISOPT_TEST_TMP) / "session";
  fs::create_directories(dir);
  const std::string errFile = (dir / "cli-stderr.txt").string();
  FILE* pipe = popen((std::string(VISOPT_CLI) + " " + args + " 2>" + errFile).c_str(), "r");
  CliResult r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = readText(errFile);
  return r;
}

}  // namespace

TEST(Sha256, KnownVectors) {
  using session::sha256Hex;
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // One million 'a' fed in uneven pieces exercises the block buffering.
  session::Sha256 h;
  const std::string chunk(997, 'a');
  size_t fed = 0;
  while (fed < 1000000) {
    const size_t n = std::min(chunk.size() - fed % 7, 1000000 - fed);
    h.update(chunk.data(), n);
    fed += n;
  }
  EXPECT_EQ(h.hexDigest(), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, DataReferenceHashesFilesAndFolders) {
  const fs::path dir = freshDir("hash");
  writeText(dir / "a.bin", "abc");
  const DataReference ref = makeDataReference((dir / "a.bin").string(), (dir / "s.json").string());
  EXPECT_EQ(ref.sha256, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(ref.bytes, 3u);
  EXPECT_EQ(ref.relativePath, "a.bin");
  EXPECT_TRUE(fs::path(ref.absolutePath).is_absolute());
  // A folder (a DICOM series): names and contents in name order; renaming a file changes it.
  fs::create_directories(dir / "series");
  writeText(dir / "series" / "2.dcm", "second");
  writeText(dir / "series" / "1.dcm", "first");
  const DataReference folder = makeDataReference((dir / "series").string(), {});
  EXPECT_EQ(folder.bytes, 11u);
  EXPECT_EQ(folder.sha256.size(), 64u);
  fs::rename(dir / "series" / "2.dcm", dir / "series" / "3.dcm");
  EXPECT_NE(makeDataReference((dir / "series").string(), {}).sha256, folder.sha256);
}

TEST(Session, Base64RoundTripsAndRejectsGarbage) {
  for (size_t n = 0; n < 8; ++n) {
    std::vector<uint8_t> bytes;
    for (size_t i = 0; i < n; ++i) bytes.push_back(uint8_t(251 * i + 3));
    EXPECT_EQ(session::base64Decode(session::base64Encode(bytes)), bytes);
  }
  EXPECT_EQ(session::base64Encode({'f', 'o', 'o', 'b'}), "Zm9vYg==");
  EXPECT_FALSE(session::base64Decode("Zm9vYg="));
  EXPECT_FALSE(session::base64Decode("Zm9v!g=="));
  EXPECT_FALSE(session::base64Decode("Zm=vYg=="));
}

TEST(Session, DefaultsAreNotWritten) {
  Engine engine;
  engine.loadBuiltinScene("marschner-lobb", 16);
  const auto doc = nlohmann::json::parse(sessionToJson(captureSession(engine)));
  EXPECT_EQ(doc["format"], "visopt-session");
  EXPECT_EQ(doc["version"], kSessionFormatVersion);
  EXPECT_EQ(doc["data"]["builtin"], "marschner-lobb");
  EXPECT_EQ(doc["data"]["resolution"], 16);
  for (const char* key : {"extinction", "levelSet", "lens", "render", "frozen", "worldMask",
                          "precision", "contextSurfaces", "clearView"})
    EXPECT_FALSE(doc.contains(key)) << key;
  EXPECT_TRUE(doc.contains("camera"));
}

TEST(Session, SaveLoadGivesTheSameSessionAndTheSameImage) {
  const fs::path dir = freshDir("roundtrip");
  const std::string path = (dir / "scene.visopt-session").string();
  Engine engine;
  setUpRichScene(engine);
  RenderSettings render = smallRender();
  render.deviationView = true;
  render.exposure = 1.25f;
  const Session saved = captureSession(engine, render);
  saveSession(saved, path);

  const Session loaded = loadSession(path);
  EXPECT_EQ(sessionToJson(loaded, path), sessionToJson(saved, path));
  EXPECT_EQ(readText(path), sessionToJson(saved, path));
  ASSERT_TRUE(loaded.worldMask);
  EXPECT_EQ(*loaded.worldMask, *saved.worldMask);
  EXPECT_EQ(loaded.extinction.optimizer, OptimizerKind::Adam);
  EXPECT_EQ(loaded.render.exposure, 1.25f);
  EXPECT_TRUE(loaded.frozen);

  Engine restored;
  const SessionLoadReport report = applySession(restored, loaded, path);
  EXPECT_TRUE(report.sceneLoaded);
  EXPECT_TRUE(report.allDataFound());
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  EXPECT_TRUE(restored.frozen());
  EXPECT_EQ(restored.transferFunction().name, "edited");
  // Capturing the restored engine gives the same session again.
  EXPECT_EQ(sessionToJson(captureSession(restored, loaded.render), path),
            sessionToJson(saved, path));
  expectSameImage(engine.render(render), restored.render(loaded.render));
}

TEST(Session, WorldMaskRoundTripsExactlyOnAnisotropicDims) {
  const fs::path dir = freshDir("mask");
  const fs::path raw = dir / "blob.raw";
  writeRawVolume(raw, {13, 7, 5});
  Engine engine;
  engine.loadVolume(raw.string());
  Field3D mask("mask", engine.volume().grid(), Precision::FP32);
  std::mt19937 rng(11);
  for (size_t i = 0; i < mask.size(); ++i) mask.set(i, float(rng() % 3 == 0));
  engine.setWorldMask(std::move(mask));
  const std::string path = (dir / "s.json").string();
  saveSession(captureSession(engine, {}, path), path);

  Engine restored;
  const SessionLoadReport report = applySession(restored, loadSession(path), path);
  ASSERT_TRUE(report.sceneLoaded);
  ASSERT_NE(restored.worldMask(), nullptr);
  const BitMask& a = *engine.worldMask();
  const BitMask& b = *restored.worldMask();
  ASSERT_EQ(b.dims, glm::ivec3(13, 7, 5));
  ASSERT_EQ(a.voxelCount(), size_t(13 * 7 * 5));
  for (size_t i = 0; i < a.voxelCount(); ++i) ASSERT_EQ(a.get(i), b.get(i)) << "voxel " << i;
  EXPECT_GT(a.count(), 0u);
  EXPECT_EQ(nlohmann::json::parse(readText(path))["worldMask"]["dims"], nlohmann::json({13, 7, 5}));
}

// Version 1 stored the camera as an orbit and called two sections "tf" and "surfaces"; version 2
// stored the camera as a frame. Both load through the converter chain.
TEST(Session, OlderVersionsLoadThroughTheMigrations) {
  const std::string tf =
      R"({"format":"visopt-transfer-function","version":1,"name":"old","unitDistance":0,)"
      R"("opacity":[[0,0],[1,0.5]],"color":[[0,1,1,1],[1,1,0,0]]})";
  const std::string v1 =
      R"({"format":"visopt-session","version":1,"data":{"builtin":"marschner-lobb","resolution":16},)"
      R"("tf":)" +
      tf +
      R"(,"camera":{"target":[0,0,0],"azimuth":90,"elevation":0,"distance":5,"fovY":25},)"
      R"("surfaces":[{"source":"iso:0.5","filled":false,"shell":0.1}],"extinction":{"q":10}})";
  const Session s1 = sessionFromJson(v1, "v1.json");
  EXPECT_EQ(s1.version, 1);
  ASSERT_TRUE(s1.camera);
  const Camera expected = Camera::orbit(glm::vec3(0.f), 90.f, 0.f, 5.f);
  EXPECT_NEAR(glm::length(s1.camera->eye - expected.eye), 0.f, 1e-5f);
  EXPECT_EQ(s1.camera->fovYDegrees, 25.f);
  ASSERT_TRUE(s1.transferFunction);
  EXPECT_EQ(s1.transferFunction->name, "old");
  ASSERT_EQ(s1.contextSurfaces.size(), 1u);
  EXPECT_EQ(s1.contextSurfaces[0].spec.source, "iso:0.5");
  EXPECT_FALSE(s1.contextSurfaces[0].spec.filled);
  EXPECT_EQ(s1.extinction.q, 10.f);
  const auto written = nlohmann::json::parse(sessionToJson(s1));
  EXPECT_EQ(written["version"], kSessionFormatVersion);
  EXPECT_TRUE(written.contains("transferFunction"));
  EXPECT_FALSE(written.contains("tf"));

  const std::string v2 =
      R"({"format":"visopt-session","version":2,"data":{"builtin":"marschner-lobb","resolution":16},)"
      R"("tf":)" +
      tf + R"(,"camera":{"eye":[0,-4,1],"target":[0,0,0],"up":[0,0,1]}})";
  const Session s2 = sessionFromJson(v2, "v2.json");
  EXPECT_EQ(s2.camera->eye, glm::vec3(0.f, -4.f, 1.f));
  EXPECT_EQ(s2.transferFunction->name, "old");

  // The migrated session applies.
  Engine engine;
  const SessionLoadReport report = applySession(engine, s1, {});
  EXPECT_TRUE(report.sceneLoaded);
  for (const auto& w : report.warnings) ADD_FAILURE() << w;
  EXPECT_EQ(engine.contextSurfaces().size(), 1u);
  EXPECT_EQ(engine.camera().fovYDegrees, 25.f);
}

// The ClearView hotspot's settings (versions 4 and 5): every stored member comes back; width,
// height and the focus pixel belong to the view and are not stored; only the layers and
// non-defaults are written.
TEST(Session, ClearViewSettingsRoundTripEveryField) {
  const fs::path dir = freshDir("clearview");
  const std::string path = (dir / "hotspot.visopt-session").string();
  Engine engine;
  engine.loadBuiltinScene("marschner-lobb", 16);
  Session saved = captureSession(engine, {}, path);
  EXPECT_FALSE(saved.clearView);  // no Engine state: the caller sets it

  ClearViewSettings c;
  c.width = 300;  // not stored
  c.height = 200;
  c.focusPixel = {12.f, 34.f};
  c.context = {ClearViewLayerKind::Isosurface, 0.37, 0};
  c.focus = {ClearViewLayerKind::ContextSurface, 0.0, 2};
  c.deeperContexts = {{ClearViewLayerKind::Isosurface, 0.61, 0},
                      {ClearViewLayerKind::ContextSurface, 0.0, 1}};
  c.moreFoci = {{ClearViewLayerKind::Importance, 0.25, 0}};
  c.volumeLayer = true;
  c.measure = ClearViewMeasure::ViewDistance;
  c.contextShader = ClearViewShader::CoolWarm;
  c.focusShader = ClearViewShader::Diffuse;
  c.size = 12.25f;
  c.weight = 0.3f;
  c.distanceScale = 4.5f;
  c.border = false;
  c.ambient = 0.4f;
  c.headlight = false;
  c.contextColor = {0.1f, 0.2f, 0.3f};
  c.focusColor = {0.4f, 0.5f, 0.6f};
  c.background = {0.7f, 0.8f, 0.9f};
  // Every member differs from the default (so a member left out of the format would show).
  const ClearViewSettings d;
  ASSERT_NE(c.context, d.context);
  ASSERT_NE(c.focus, d.focus);
  ASSERT_NE(c.contextColor, d.contextColor);
  ASSERT_NE(c.focusColor, d.focusColor);
  ASSERT_NE(c.background, d.background);
  saved.clearView = c;
  saveSession(saved, path);

  const Session loaded = loadSession(path);
  ASSERT_TRUE(loaded.clearView);
  const ClearViewSettings& r = *loaded.clearView;
  EXPECT_EQ(r.context, c.context);
  EXPECT_EQ(r.focus, c.focus);
  EXPECT_EQ(r.deeperContexts, c.deeperContexts);
  EXPECT_EQ(r.moreFoci, c.moreFoci);
  EXPECT_EQ(r.volumeLayer, c.volumeLayer);
  EXPECT_EQ(r.measure, c.measure);
  EXPECT_EQ(r.contextShader, c.contextShader);
  EXPECT_EQ(r.focusShader, c.focusShader);
  EXPECT_EQ(r.size, c.size);
  EXPECT_EQ(r.weight, c.weight);
  EXPECT_EQ(r.distanceScale, c.distanceScale);
  EXPECT_EQ(r.border, c.border);
  EXPECT_EQ(r.ambient, c.ambient);
  EXPECT_EQ(r.headlight, c.headlight);
  EXPECT_EQ(r.contextColor, c.contextColor);
  EXPECT_EQ(r.focusColor, c.focusColor);
  EXPECT_EQ(r.background, c.background);
  EXPECT_EQ(r.width, d.width);
  EXPECT_EQ(r.height, d.height);
  EXPECT_EQ(r.focusPixel, d.focusPixel);
  EXPECT_EQ(readText(path), sessionToJson(loaded, path));
  const auto doc = nlohmann::json::parse(readText(path));
  EXPECT_EQ(doc["version"], 5);
  EXPECT_EQ(
      doc["clearView"]["deeperContexts"],
      nlohmann::json::parse(R"([{"kind":"iso","isovalue":0.61},{"kind":"surface","surface":1}])"));
  EXPECT_EQ(doc["clearView"]["moreFoci"],
            nlohmann::json::parse(R"([{"kind":"importance","isovalue":0.25}])"));
  EXPECT_EQ(doc["clearView"]["context"],
            nlohmann::json::parse(R"({"kind":"iso","isovalue":0.37})"));
  EXPECT_EQ(doc["clearView"]["focus"], nlohmann::json::parse(R"({"kind":"surface","surface":2})"));
  EXPECT_EQ(doc["clearView"]["measure"], "view-distance");
  EXPECT_EQ(doc["clearView"]["contextShader"], "cool-warm");
  for (const char* key : {"width", "height", "focusPixel"})
    EXPECT_FALSE(doc["clearView"].contains(key)) << key;

  // The defaults but for the layers: only the layers are written (the importance layer too).
  ClearViewSettings plain;
  plain.context = {ClearViewLayerKind::ContextSurface, 0.0, 0};
  plain.focus = {ClearViewLayerKind::Importance, 0.75, 0};
  saved.clearView = plain;
  saveSession(saved, path);
  const auto plainDoc = nlohmann::json::parse(readText(path));
  EXPECT_EQ(plainDoc["clearView"],
            nlohmann::json::parse(R"({"context":{"kind":"surface","surface":0},)"
                                  R"("focus":{"kind":"importance","isovalue":0.75}})"));
  const Session plainLoaded = loadSession(path);
  ASSERT_TRUE(plainLoaded.clearView);
  EXPECT_EQ(plainLoaded.clearView->context, plain.context);
  EXPECT_EQ(plainLoaded.clearView->focus, plain.focus);
  EXPECT_EQ(plainLoaded.clearView->measure, d.measure);
  EXPECT_EQ(plainLoaded.clearView->size, d.size);

  // The engine applies such a session as before (the settings are the caller's).
  Engine restored;
  const SessionLoadReport report = applySession(restored, loaded, path);
  EXPECT_TRUE(report.sceneLoaded);
  for (const auto& w : report.warnings) ADD_FAILURE() << w;
}

// Version 4 had one context and one focus layer: a version-4 reader ignored "deeperContexts" and
// "moreFoci", so in a version-4 file they are not visopt's and are dropped, not read as layers.
// Damaged lists in a version-5 file are refused, naming the key.
TEST(Session, VersionFourHasOneLayerEachAndBadLayerListsAreRefused) {
  const std::string head =
      R"({"format":"visopt-session","version":VERSION,"data":{"builtin":"marschner-lobb",)"
      R"("resolution":16},"clearView":{"context":{"kind":"surface","surface":0},)"
      R"("focus":{"kind":"importance","isovalue":0.5},)";
  auto doc = [&](const std::string& version, const std::string& rest) {
    std::string text = head;
    text.replace(text.find("VERSION"), 7, version);
    return text + rest + "}}";
  };
  const Session v4 =
      sessionFromJson(doc("4", R"("moreFoci":[{"kind":"iso","isovalue":1}],"weight":0.5)"), "v4");
  ASSERT_TRUE(v4.clearView);
  EXPECT_TRUE(v4.clearView->moreFoci.empty());
  EXPECT_EQ(v4.clearView->weight, 0.5f);
  const Session v5 = sessionFromJson(doc("5", R"("moreFoci":[{"kind":"iso","isovalue":1}])"), "v5");
  ASSERT_TRUE(v5.clearView);
  ASSERT_EQ(v5.clearView->moreFoci.size(), 1u);
  EXPECT_EQ(v5.clearView->moreFoci[0].isovalue, 1.0);
  for (const std::string& bad :
       {std::string(R"("moreFoci":{"kind":"iso","isovalue":1})"),
        std::string(R"("deeperContexts":[{"kind":"importance","isovalue":3}])"),
        std::string(R"("deeperContexts":[{"kind":"iso","isovalue":1},{"kind":"iso","isovalue":1},)"
                    R"({"kind":"iso","isovalue":1},{"kind":"iso","isovalue":1}])")}) {
    try {
      (void)sessionFromJson(doc("5", bad), "bad.visopt-session");
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("bad.visopt-session"), std::string::npos) << what;
      EXPECT_TRUE(what.find("moreFoci") != std::string::npos ||
                  what.find("deeperContexts") != std::string::npos)
          << what;
    }
  }
}

// Version 3 had no hotspot settings: such a file loads with none (the scene's defaults), and a
// "clearView" that a version-3 reader would have ignored is not taken for settings.
TEST(Session, VersionThreeLoadsWithoutHotspotSettings) {
  const std::string v3 =
      R"({"format":"visopt-session","version":3,"data":{"builtin":"marschner-lobb","resolution":16},)"
      R"("extinction":{"q":11},"clearView":{"weight":"not from visopt"}})";
  const Session s = sessionFromJson(v3, "v3.json");
  EXPECT_EQ(s.version, 3);
  EXPECT_FALSE(s.clearView);
  EXPECT_EQ(s.extinction.q, 11.f);
  const auto written = nlohmann::json::parse(sessionToJson(s));
  EXPECT_EQ(written["version"], kSessionFormatVersion);
  EXPECT_FALSE(written.contains("clearView"));
  Engine engine;
  const SessionLoadReport report = applySession(engine, s, {});
  EXPECT_TRUE(report.sceneLoaded);
  for (const auto& w : report.warnings) ADD_FAILURE() << w;
}

TEST(Session, BadHotspotSettingsAreRefusedNamingTheFile) {
  const fs::path dir = freshDir("clearview-bad");
  const std::string head =
      R"({"format":"visopt-session","version":4,"data":{"builtin":"marschner-lobb"},"clearView":)";
  const std::string layers =
      R"("context":{"kind":"surface","surface":0},"focus":{"kind":"importance","isovalue":0.5})";
  auto check = [&](const std::string& name, const std::string& clearView, const char* needle) {
    const std::string path = (dir / name).string();
    writeText(path, head + clearView + "}");
    const std::string msg = expectBadInput([&] { loadSession(path); }, path);
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
  };
  // The good one loads (so each failure below is the one value's).
  writeText(dir / "good.json", head + "{" + layers + R"(,"weight":2})" + "}");
  EXPECT_EQ(loadSession((dir / "good.json").string()).clearView->weight, 2.f);

  check("notobject.json", "[1]", "clearView: expected an object");
  check("nofocus.json", R"({"context":{"kind":"surface","surface":0}})",
        "clearView: missing \"focus\"");
  check("kind.json", R"({"context":{"kind":"mesh"},"focus":{"kind":"importance","isovalue":1}})",
        "clearView.context.kind: expected \"iso\", \"surface\" or \"importance\"");
  check("noiso.json", R"({"context":{"kind":"iso"},"focus":{"kind":"importance","isovalue":1}})",
        "clearView.context: missing \"isovalue\"");
  check(
      "level.json",
      R"({"context":{"kind":"surface","surface":0},"focus":{"kind":"importance","isovalue":1.5}})",
      "clearView.focus.isovalue: an importance level must lie in (0, 1]");
  check("index.json",
        R"({"context":{"kind":"surface","surface":-1},"focus":{"kind":"importance","isovalue":1}})",
        "clearView.context.surface: must be a context-surface index >= 0");
  check("weight.json", "{" + layers + R"(,"weight":-1})", "clearView.weight: must be >= 0");
  check("ambient.json", "{" + layers + R"(,"ambient":2})", "clearView.ambient: must lie in [0, 1]");
  check("size.json", "{" + layers + R"(,"size":"big"})", "clearView.size: expected a number");
  check("negsize.json", "{" + layers + R"(,"size":-3})", "clearView.size: must be >= 0");
  check("scale.json", "{" + layers + R"(,"distanceScale":-1})", "clearView.distanceScale");
  check("border.json", "{" + layers + R"(,"border":1})",
        "clearView.border: expected true or false");
  check("measure.json", "{" + layers + R"(,"measure":"depth"})",
        "clearView.measure: unknown \"depth\" (expected \"curvature\", \"distance\", "
        "\"view-distance\")");
  check("shader.json", "{" + layers + R"(,"focusShader":"metal"})",
        "clearView.focusShader: unknown \"metal\"");
  check("colour.json", "{" + layers + R"(,"background":[0,-1,0]})",
        "clearView.background: colour components must be >= 0");
  check("nan.json", "{" + layers + R"(,"weight":1e999})", "invalid JSON");
}

// The importance as a hotspot ball (Engine::setImportanceHotspot) is stored by its centre and
// radius and rebuilt from them.
TEST(Session, HotspotImportanceRoundTrips) {
  const fs::path dir = freshDir("hotspot-importance");
  const std::string path = (dir / "s.json").string();
  Engine engine;
  engine.loadBuiltinScene("marschner-lobb", 16);
  engine.setImportanceHotspot({0.1f, -0.2f, 0.05f}, 0.4f);
  saveSession(captureSession(engine, {}, path), path);
  const auto doc = nlohmann::json::parse(readText(path));
  EXPECT_EQ(doc["importance"]["kind"], "hotspot");
  const Session loaded = loadSession(path);
  EXPECT_EQ(loaded.importance.kind, ImportanceKind::Hotspot);
  EXPECT_EQ(loaded.importance.hotspotCentre, glm::vec3(0.1f, -0.2f, 0.05f));
  EXPECT_EQ(loaded.importance.hotspotRadius, 0.4f);
  Engine restored;
  const SessionLoadReport report = applySession(restored, loaded, path);
  for (const auto& w : report.warnings) ADD_FAILURE() << w;
  ASSERT_TRUE(restored.hasImportance());
  EXPECT_EQ(restored.importanceSource().kind, ImportanceKind::Hotspot);
  EXPECT_EQ(restored.importanceSource().hotspotRadius, 0.4f);
  const Field3D& a = *engine.importance();
  const Field3D& b = *restored.importance();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.get(i), b.get(i)) << i;
  const std::string bad = (dir / "bad.json").string();
  writeText(bad, R"({"format":"visopt-session","version":4,"data":{"builtin":"a"},)"
                 R"("importance":{"kind":"hotspot","centre":[0,0,0],"radius":0}})");
  const std::string msg = expectBadInput([&] { loadSession(bad); }, bad);
  EXPECT_NE(msg.find("importance.radius: must be positive"), std::string::npos) << msg;
}

TEST(Session, DamagedFilesGiveOneLineBadInputAndLeaveTheEngineUsable) {
  const fs::path dir = freshDir("damaged");
  Engine engine;
  engine.loadBuiltinScene("marschner-lobb", 16);
  engine.setWorldMask([&] {
    Field3D m("m", engine.volume().grid(), Precision::FP32);
    m.fill(1.f);
    return m;
  }());
  const std::string good = sessionToJson(captureSession(engine));

  auto check = [&](const std::string& name, const std::string& text, const char* needle) {
    const std::string path = (dir / name).string();
    writeText(path, text);
    const std::string msg = expectBadInput([&] { loadSession(path); }, path);
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
  };
  check("truncated.json", good.substr(0, good.size() / 2), "invalid JSON");
  check("text.json", "hello, world", "invalid JSON");
  check("array.json", "[1, 2]", "expected a JSON object");
  check("foreign.json", R"({"format":"something-else","version":1})", "not a session file");
  check("newer.json", R"({"format":"visopt-session","version":99,"data":{"builtin":"x"}})",
        "newer than this visopt");
  check("nodata.json", R"({"format":"visopt-session","version":3})", "missing \"data\"");
  // A number beyond double: nlohmann reports it as out_of_range, which went out as an anonymous
  // failure (exit 3) without the file's name.
  check(
      "overflow.json",
      R"({"format":"visopt-session","version":3,"data":{"builtin":"a"},"extinction":{"q":1e999}})",
      "invalid JSON");
  check("badtype.json",
        R"({"format":"visopt-session","version":3,"data":{"builtin":"a"},"extinction":{"q":"x"}})",
        "extinction.q: expected a number");
  std::string corrupt = good;
  const auto at = corrupt.find("\"data\": \"") + 12;
  corrupt[at] = corrupt[at] == 'A' ? 'B' : 'A';
  check("mask.json", corrupt, "worldMask");
  check("empty.json", "", "file is empty");
  expectBadInput([&] { loadSession((dir / "none.json").string()); }, (dir / "none.json").string());
  // The engine was never touched.
  EXPECT_EQ(engine.render(smallRender()).width, 40);
}

TEST(Session, MovedDataIsFoundThroughTheRelativePath) {
  const fs::path root = freshDir("moved");
  const fs::path a = root / "a", b = root / "b";
  fs::create_directories(a / "data");
  fs::create_directories(a / "sessions");
  writeRawVolume(a / "data" / "vol.raw", {9, 8, 6}, 100.f);
  writeRawVolume(a / "data" / "imp.raw", {9, 8, 6}, 1.f);
  Engine engine;
  engine.loadVolume((a / "data" / "vol.raw").string());
  engine.loadImportance((a / "data" / "imp.raw").string());
  const std::string path = (a / "sessions" / "s.json").string();
  saveSession(captureSession(engine, smallRender(), path), path);
  const auto doc = nlohmann::json::parse(readText(path));
  EXPECT_EQ(doc["data"]["volume"]["relative"], "../data/vol.raw");
  fs::rename(a, b);

  const std::string moved = (b / "sessions" / "s.json").string();
  Engine restored;
  const SessionLoadReport report = applySession(restored, loadSession(moved), moved);
  ASSERT_TRUE(report.sceneLoaded);
  ASSERT_EQ(report.data.size(), 2u);
  for (const auto& d : report.data) {
    EXPECT_EQ(d.status, DataStatus::Moved) << describe(d);
    EXPECT_EQ(fs::path(d.resolvedPath).parent_path(), b / "data");
  }
  EXPECT_EQ(restored.importanceSource().kind, Engine::ImportanceSource::Kind::Volume);
  expectSameImage(engine.render(smallRender()), restored.render(smallRender()));
}

namespace {

// An 8³ raw volume DIR/vol.raw and a session of it saved as DIR/s.json; returns the session's
// path.
std::string saveRawVolumeSession(const fs::path& dir) {
  writeRawVolume(dir / "vol.raw", {8, 8, 8});
  Engine engine;
  engine.loadVolume((dir / "vol.raw").string());
  const std::string path = (dir / "s.json").string();
  saveSession(captureSession(engine, {}, path), path);
  return path;
}

}  // namespace

TEST(Session, MissingAndChangedDataAreReportedNotThrown) {
  const fs::path dir = freshDir("missing");
  const fs::path raw = dir / "vol.raw";
  const std::string path = saveRawVolumeSession(dir);

  // Changed: same place, other content; used, and reported.
  writeRawVolume(raw, {8, 8, 8}, 2.f);
  {
    Engine e;
    const SessionLoadReport r = applySession(e, loadSession(path), path);
    EXPECT_TRUE(r.sceneLoaded);
    ASSERT_EQ(r.data.size(), 1u);
    EXPECT_EQ(r.data[0].status, DataStatus::Changed);
    EXPECT_FALSE(r.allDataFound());
    Engine refuse;
    EXPECT_FALSE(applySession(refuse, loadSession(path), path, {}, {false}).sceneLoaded);
  }

  // Missing: reported; the engine keeps the scene it had.
  fs::rename(raw, dir / "elsewhere.raw");
  fs::rename(dir / "vol.raw.json", dir / "elsewhere.raw.json");
  Engine e;
  e.loadBuiltinScene("marschner-lobb", 12);
  Session loaded = loadSession(path);
  const SessionLoadReport r = applySession(e, loaded, path);
  EXPECT_FALSE(r.sceneLoaded);
  ASSERT_EQ(r.data.size(), 1u);
  EXPECT_EQ(r.data[0].status, DataStatus::Missing);
  EXPECT_NE(describe(r.data[0]).find("vol.raw"), std::string::npos);
  EXPECT_EQ(e.volume().sourcePath, "builtin:marschner-lobb");
  EXPECT_EQ(checkSessionData(loaded, path)[0].status, DataStatus::Missing);

  // The user points to the file: it loads (its content is the changed one).
  relocate(loaded, "volume", (dir / "elsewhere.raw").string());
  const SessionLoadReport again = applySession(e, loaded, path);
  EXPECT_TRUE(again.sceneLoaded);
  EXPECT_EQ(again.data[0].status, DataStatus::Changed);
  EXPECT_THROW(relocate(loaded, "importance", "x"), Error);
}

// Item 4 of issue 13: a session's data is not read before the session opens. Sizes decide what
// they can (a size other than the recorded one is Changed unread); the content is hashed later,
// streamed, with progress and cancel.
TEST(Session, DataIsMatchedBySizeFirstAndHashedLaterWithProgressAndCancel) {
  const fs::path dir = freshDir("lazy-hash");
  const fs::path raw = dir / "vol.raw";
  const std::string path = saveRawVolumeSession(dir);
  const Session saved = loadSession(path);

  // Same size, other content: a size check cannot tell and reads nothing.
  writeRawVolume(raw, {8, 8, 8}, 2.f);
  EXPECT_FALSE(session::cachedContentHash(raw.string()));
  std::vector<SessionDataReport> data = checkSessionData(saved, path, DataCheck::Size);
  ASSERT_EQ(data.size(), 1u);
  EXPECT_EQ(data[0].status, DataStatus::Ok);
  EXPECT_FALSE(data[0].contentVerified);
  EXPECT_NE(describe(data[0]).find("not yet checked"), std::string::npos);
  EXPECT_FALSE(session::cachedContentHash(raw.string())) << "a size check hashed the file";
  // Applying with size checks loads the data; verifying afterwards finds the change.
  Engine lazy;
  SessionApplyOptions sizes;
  sizes.check = DataCheck::Size;
  SessionLoadReport report = applySession(lazy, saved, path, {}, sizes);
  EXPECT_TRUE(report.sceneLoaded);
  ASSERT_EQ(report.data.size(), 1u);
  EXPECT_FALSE(report.data[0].contentVerified);
  EXPECT_EQ(verifySessionData(report.data), 1u);
  EXPECT_EQ(report.data[0].status, DataStatus::Changed);
  EXPECT_TRUE(report.data[0].contentVerified);
  EXPECT_EQ(verifySessionData(report.data), 0u) << "a verified report is not hashed again";

  // Another size: Changed, from the file system alone, in either mode.
  writeRawVolume(raw, {8, 8, 9});
  for (DataCheck mode : {DataCheck::Size, DataCheck::Content}) {
    const std::vector<SessionDataReport> d = checkSessionData(saved, path, mode);
    EXPECT_EQ(d[0].status, DataStatus::Changed);
    EXPECT_TRUE(d[0].contentVerified);
  }
  EXPECT_FALSE(session::cachedContentHash(raw.string())) << "a differing size was hashed";

  // The original content back: the content check finds it Ok.
  writeRawVolume(raw, {8, 8, 8});
  data = checkSessionData(saved, path, DataCheck::Size);
  EXPECT_EQ(verifySessionData(data), 0u);
  EXPECT_EQ(data[0].status, DataStatus::Ok);
  EXPECT_TRUE(data[0].contentVerified);
}

TEST(Sha256, HashingReportsProgressAndStopsWhenCancelled) {
  const fs::path dir = freshDir("hash-progress");
  const fs::path big = dir / "big.bin";
  {
    std::ofstream out(big, std::ios::binary);
    const std::string mib(1 << 20, 'x');
    for (int i = 0; i < 40; ++i) out << mib;  // 40 MiB: reported at 16 and 32 MiB
  }
  // Cancelled at the first report: Cancelled, and nothing cached.
  int calls = 0;
  try {
    makeDataReference(big.string(), {}, [&](float, const std::string&) { return ++calls > 1; });
    ADD_FAILURE() << "not cancelled";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Cancelled);
    EXPECT_NE(std::string(e.what()).find("big.bin"), std::string::npos);
  }
  EXPECT_EQ(calls, 1);
  EXPECT_FALSE(session::cachedContentHash(big.string()));
  // Through: fractions rise within (0, 1]; the stage names the file.
  std::vector<float> fractions;
  const DataReference ref =
      makeDataReference(big.string(), {}, [&](float f, const std::string& stage) {
        EXPECT_NE(stage.find("big.bin"), std::string::npos);
        fractions.push_back(f);
        return true;
      });
  ASSERT_EQ(fractions.size(), 2u);
  EXPECT_NEAR(fractions[0], 16.f / 40.f, 1e-6f);
  EXPECT_NEAR(fractions[1], 32.f / 40.f, 1e-6f);
  EXPECT_EQ(ref.bytes, 40u << 20);
  ASSERT_TRUE(session::cachedContentHash(big.string()));
  EXPECT_EQ(session::cachedContentHash(big.string())->sha256, ref.sha256);
  // A cancelled verification leaves the report unverified.
  std::vector<SessionDataReport> data{{"volume", ref, DataStatus::Ok, big.string(), {}, false}};
  std::ofstream(big, std::ios::binary | std::ios::app) << "";  // same bytes, newer time
  fs::last_write_time(big, fs::last_write_time(big) + std::chrono::seconds(1));
  EXPECT_THROW(verifySessionData(data, [](float, const std::string&) { return false; }), Error);
  EXPECT_FALSE(data[0].contentVerified);
  EXPECT_EQ(verifySessionData(data), 0u);
  EXPECT_TRUE(data[0].contentVerified);
}

TEST(Session, CrashMidSaveLeavesThePreviousFileIntact) {
  const fs::path dir = freshDir("crash");
  const std::string path = (dir / "s.json").string();
  Engine engine;
  engine.loadBuiltinScene("marschner-lobb", 12);
  const Session first = captureSession(engine);
  saveSession(first, path);
  const std::string before = readText(path);
  engine.orbitCamera(120.f, 40.f, 4.f);
  const Session second = captureSession(engine);

  for (const char* stage : {"temporary-open", "mid-write", "after-write"}) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      setenv("VISOPT_SESSION_FAULT", stage, 1);
      try {
        saveSession(second, path);
      } catch (...) {
      }
      _exit(0);  // not reached when the fault fires
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 70) << stage;
    EXPECT_EQ(readText(path), before) << stage;
    EXPECT_EQ(sessionToJson(loadSession(path)), sessionToJson(first)) << stage;
  }

  // A failure reported by the hook (an exception) leaves no temporary behind.
  setSessionSaveHook([](const char* stage) {
    if (std::string(stage) == "mid-write") throw Error(ErrorKind::Failure, "disk full");
  });
  EXPECT_THROW(saveSession(second, path), Error);
  setSessionSaveHook(nullptr);
  EXPECT_EQ(readText(path), before);

  // The killed saves left temporaries behind; the next save to the same path removes them (no
  // process holds their lock), but not one whose writer is still at work (it holds the lock).
  const fs::path live = dir / ".s.json.tmp-LIVE00";
  { std::ofstream(live) << "in progress"; }
  const int liveFd = ::open(live.c_str(), O_RDONLY);
  ASSERT_GE(liveFd, 0);
  ASSERT_EQ(::flock(liveFd, LOCK_EX), 0);
  int leftovers = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) {
      // Older than the few seconds during which a fresh temporary is never touched.
      fs::last_write_time(entry.path(), fs::file_time_type::clock::now() - std::chrono::minutes(1));
      ++leftovers;
    }
  EXPECT_GE(leftovers, 3) << "the two killed mid-write saves' temporaries, and the live one";
  saveSession(second, path);
  EXPECT_EQ(sessionToJson(loadSession(path)), sessionToJson(second));
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos)
      left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{live.filename().string()});
  ::close(liveFd);
}

TEST(Session, CliRendersASessionAndDescribesIt) {
  const fs::path dir = freshDir("cli");
  const std::string path = (dir / "s.json").string();
  Engine engine;
  engine.loadBuiltinScene("marschner-lobb", 16);
  RenderSettings render = smallRender();
  saveSession(captureSession(engine, render), path);
  const std::string png = (dir / "out.png").string();

  CliResult r = runCli("render --session " + path + " --out " + png + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["image"]["width"], 40);  // from the session
  EXPECT_EQ(j["image"]["height"], 32);
  expectSameImage(readPng(png), [&] {
    Image img = engine.render(render);
    writePng(img, (dir / "direct.png").string());
    return readPng((dir / "direct.png").string());
  }());

  r = runCli("render --session " + path + " --size 20x10 --out " + png + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["image"]["width"], 20);  // explicit options override

  EXPECT_EQ(
      runCli("render --session " + path + " --scene builtin:marschner-lobb --out " + png).code, 1);

  r = runCli("session-info " + path + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  j = nlohmann::json::parse(r.out);  // exactly one JSON object
  EXPECT_EQ(j["file_version"], kSessionFormatVersion);
  EXPECT_EQ(j["source"], "builtin:marschner-lobb at 16");

  // A session whose volume is gone: reported on stderr, exit 2.
  const fs::path raw = dir / "vol.raw";
  writeRawVolume(raw, {8, 8, 8});
  Engine e;
  e.loadVolume(raw.string());
  const std::string gone = (dir / "gone.json").string();
  saveSession(captureSession(e, render, gone), gone);
  // Present: the content is compared, or with --sizes-only only the size.
  for (const std::string flag : {"", " --sizes-only"}) {
    r = runCli("session-info " + gone + " --json" + flag);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto file = nlohmann::json::parse(r.out)["data"][0];
    EXPECT_EQ(file["status"], "ok");
    EXPECT_EQ(file["content_verified"], flag.empty()) << flag;
  }
  fs::remove(raw);
  r = runCli("render --session " + gone + " --out " + png);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("volume: missing"), std::string::npos) << r.err;
  r = runCli("session-info " + gone + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["data"][0]["status"], "missing");
  writeText(dir / "bad.json", "{");
  EXPECT_EQ(runCli("session-info " + (dir / "bad.json").string()).code, 2);
}
