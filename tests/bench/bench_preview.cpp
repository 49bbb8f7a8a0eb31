// A workstation preview frame (the default scene at 128³, a 512² view drawn at a quarter of its
// size, shadows from T_L) with the empty-space block ranges built for the frame (the renderer's
// reference path) against the ranges the Engine keeps across frames (docs/benchmarks.md), in the
// same run. With `change:1` an optimised mu's change to mu_bar is drawn too, whose ranges the
// Engine keeps with the change.
//
//   bench_preview --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <memory>
#include <optional>

#include "core/device_buffer.h"
#include "render/renderer.h"
#include "visopt/camera.h"
#include "visopt/frustum.h"
#include "visopt/scenes.h"

namespace {

using namespace visopt;

struct PreviewScene {
  BuiltinScene built = makeBuiltinScene(defaultSceneName(), 128, Precision::FP32);
  DeviceBuffer<glm::vec4> table;
  FrustumGrid lightFrustum;
  std::optional<Field3D> lightTransmittance, change;
  DeviceBuffer<glm::vec2> volumeRanges, changeRanges;
  RenderScene scene;
  RenderSettings settings;

  PreviewScene() {
    const Volume& volume = built.volume;
    const GridSpec& g = volume.grid();
    const TransferTable baked =
        built.contextTransferFunction.bake(volume.valueMin, volume.valueMax, g.minSpacing(), 1024);
    table = DeviceBuffer<glm::vec4>(baked.albedoExtinction.size());
    for (size_t i = 0; i < table.size(); ++i) table[i] = baked.albedoExtinction[i];
    scene.volume = &volume;
    scene.transfer = &table;
    scene.camera = Camera::orbitBounds(g.worldBounds(), built.azimuthDeg, built.elevationDeg,
                                       built.distanceInRadii);
    scene.light = PointLight::keyLightFor(scene.camera, g.worldBounds());
    settings.width = settings.height = 512;
    settings.preview = true;
    lightFrustum = FrustumGrid::forLight(
        scene.light, g.worldBounds(),
        glm::ivec3(settings.lightGridSize, settings.lightGridSize, settings.lightGridDepth),
        2.f * g.minSpacing());
    GridSpec lg;
    lg.dims = lightFrustum.dims;
    lightTransmittance.emplace("light-transmittance", lg, Precision::FP32);
    computeLightTransmittance(scene, lightFrustum, *lightTransmittance);
    scene.lightFrustum = &lightFrustum;
    scene.lightTransmittance = &*lightTransmittance;
    // A change as an optimisation leaves one: extinction taken away where the importance lies
    // (the tumours open), nothing elsewhere.
    change.emplace("change", g, Precision::FP32);
    for (size_t v = 0; v < change->size(); ++v)
      change->set(v, built.importance.get(v) > 0.1f ? -table[0].w - 1.f : 0.f);
    volumeRanges = computeBlockRange(volume.normalized);
    changeRanges = computeBlockRange(*change);
  }
};

PreviewScene& previewScene() {
  static PreviewScene s;
  return s;
}

void BM_PreviewFrame(benchmark::State& state) {
  PreviewScene& p = previewScene();
  RenderScene scene = p.scene;
  const bool kept = state.range(0) != 0, withChange = state.range(1) != 0;
  if (withChange) scene.extinctionChange = &*p.change;
  if (kept) {
    scene.volumeBlockRange = &p.volumeRanges;
    if (withChange) scene.changeBlockRange = &p.changeRanges;
  }
  for (auto _ : state) {
    Image image = renderImage(scene, p.settings, nullptr, {});
    benchmark::DoNotOptimize(image.pixels.data());
  }
}
BENCHMARK(BM_PreviewFrame)
    ->ArgNames({"kept", "change"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
