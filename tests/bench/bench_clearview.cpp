// ClearView (Krüger, Schneider, Westermann 2006) on the CPU: the compositing alone (what moving
// the hotspot costs) at the paper's two viewport sizes, 800x600 and 1600x1200, per measure; the
// layer extraction (what moving the camera costs) per precision; and, as the peer in the same
// run, a full single-scattering render of the same view (Engine::render). The memory bandwidth
// is measured in the same run (STREAM triad) and the compositing's bytes reported against it.
//
//   ./build/tests/bench/bench_clearview [--benchmark_filter=composite]
//
// Scenes: the default scene (builtin:shepp-logan, 128^3, its skull as the context surface and
// the tumours' importance as the focus) and, when data/Cranium.raw is present, the Cranium CT
// (skin at -400 HU as context, bone at 250 HU as focus).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>

#include "stream_counters.h"
#include "visopt/engine.h"
#include "visopt/exec.h"
#include "visopt/transfer_function.h"

namespace {

using visopt::ClearViewLayerKind;
using visopt::ClearViewMeasure;
using visopt::ClearViewSettings;
using visopt::Engine;
using visopt::Precision;

struct Scene {
  std::string name;
  bool available = false;
};

std::string cranium() {
  return std::string(VISOPT_SOURCE_DIR) + "/data/Cranium.raw";
}

std::unique_ptr<Engine> load(const std::string& scene, Precision precision, ClearViewSettings& cv) {
  auto e = std::make_unique<Engine>(precision);
  if (scene == "shepp-logan") {
    e->loadBuiltinScene("shepp-logan", 128, true);
    cv.context = {ClearViewLayerKind::ContextSurface, 0.0, 0};
    cv.focus = {ClearViewLayerKind::Importance, 0.5, 0};
  } else {
    e->loadVolume(cranium());
    e->setTransferFunction(visopt::TransferFunction::preset("ct-skin-bone", e->volume().valueMin,
                                                            e->volume().valueMax));
    e->orbitCamera(0.f, 10.f, 2.4f);
    cv.context = {ClearViewLayerKind::Isosurface, -400.0, 0};
    cv.focus = {ClearViewLayerKind::Isosurface, 250.0, 0};
  }
  return e;
}

// Per pixel the compositing reads the context's position, normal and depth, the focus's
// position, normal and depth, the normal distance, and writes the linear colour; the four
// neighbours' normals and depths come from cache lines already read for the rows around.
constexpr double kCompositeBytesPerPixel = 12 + 12 + 4 + 12 + 12 + 4 + 4 + 12;

// `reuse`: into the same image each frame, as the workstation does; else a new image each time.
void composite(benchmark::State& state, const std::string& scene, int w, int h,
               ClearViewMeasure measure, bool reuse) {
  ClearViewSettings cv;
  cv.width = w;
  cv.height = h;
  cv.measure = measure;
  auto e = load(scene, Precision::FP32, cv);
  visopt::ClearViewStats st;
  e->renderClearView(cv, &st);  // extracts
  int frame = 0;
  visopt::Image image;
  for (auto _ : state) {
    // The hotspot follows a cursor moving over the image, as in the workstation.
    cv.focusPixel = {float((frame * 7) % w), float((frame * 5) % h)};
    ++frame;
    if (reuse)
      e->renderClearView(cv, image, &st);
    else
      image = e->renderClearView(cv, &st);
    benchmark::DoNotOptimize(image.pixels.data());
    if (st.extracted) state.SkipWithError("the compositing extracted again");
  }
  const double pixels = double(w) * h;
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["ns_per_pixel"] =
      benchmark::Counter(pixels * double(state.iterations()) * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  visopt::bench::setTriadFraction(state, "frac_triad", pixels * kCompositeBytesPerPixel);
}

void extract(benchmark::State& state, const std::string& scene, int w, int h, Precision p) {
  ClearViewSettings cv;
  cv.width = w;
  cv.height = h;
  auto e = load(scene, p, cv);
  visopt::ClearViewStats st;
  float az = 0.f;
  for (auto _ : state) {
    // A new camera each time: the layers are extracted again.
    e->orbitCamera(az, 10.f, 2.4f);
    az += 0.5f;
    benchmark::DoNotOptimize(e->renderClearView(cv, &st));
    if (!st.extracted) state.SkipWithError("the layers were not extracted");
  }
  state.counters["ns_per_pixel"] =
      benchmark::Counter(double(w) * h * double(state.iterations()) * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// The peer: a full single-scattering frame of the same view (T_L kept from the first frame, as
// while the camera moves with the light fixed).
void fullRender(benchmark::State& state, const std::string& scene, int w, int h, Precision p) {
  ClearViewSettings cv;
  auto e = load(scene, p, cv);
  visopt::RenderSettings rs;
  rs.width = w;
  rs.height = h;
  e->render(rs);
  float az = 0.f;
  for (auto _ : state) {
    e->orbitCamera(az, 10.f, 2.4f);
    e->setLight(e->light());  // orbitCamera moved the key light with the camera: keep T_L honest
    az += 0.5f;
    benchmark::DoNotOptimize(e->render(rs));
  }
  state.counters["ns_per_pixel"] =
      benchmark::Counter(double(w) * h * double(state.iterations()) * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  std::vector<std::string> scenes = {"shepp-logan"};
  if (std::filesystem::exists(cranium())) scenes.push_back("cranium");
  const std::pair<int, int> sizes[] = {{800, 600}, {1600, 1200}};
  for (const std::string& scene : scenes)
    for (auto [w, h] : sizes) {
      const std::string size = std::to_string(w) + "x" + std::to_string(h);
      for (ClearViewMeasure m : {ClearViewMeasure::Curvature, ClearViewMeasure::Distance,
                                 ClearViewMeasure::ViewDistance})
        benchmark::RegisterBenchmark(
            ("composite/" + scene + "/" + size + "/" + visopt::toString(m)).c_str(),
            [=](benchmark::State& st) { composite(st, scene, w, h, m, true); })
            ->UseRealTime()
            ->MinTime(0.5)
            ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(
          ("composite-new-image/" + scene + "/" + size + "/curvature").c_str(),
          [=](benchmark::State& st) {
            composite(st, scene, w, h, ClearViewMeasure::Curvature, false);
          })
          ->UseRealTime()
          ->MinTime(0.5)
          ->Unit(benchmark::kMillisecond);
      for (Precision p : {Precision::FP32, Precision::FP16}) {
        benchmark::RegisterBenchmark(
            ("extract/" + scene + "/" + size + "/" + visopt::toString(p)).c_str(),
            [=](benchmark::State& st) { extract(st, scene, w, h, p); })
            ->UseRealTime()
            ->MinTime(0.5)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(
            ("full-render/" + scene + "/" + size + "/" + visopt::toString(p)).c_str(),
            [=](benchmark::State& st) { fullRender(st, scene, w, h, p); })
            ->UseRealTime()
            ->MinTime(0.5)
            ->Unit(benchmark::kMillisecond);
      }
    }
  return visopt::bench::runWithSameRunStream();
}
