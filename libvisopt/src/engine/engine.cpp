#include "visopt/engine.h"

#include <chrono>
#include <optional>

#include "core/device_buffer.h"
#include "engine/importance.h"
#include "optimize/extinction_optimizer.h"
#include "render/renderer.h"
#include "visopt/error.h"
#include "visopt/frustum.h"
#include "visopt/volume_io.h"

namespace visopt {

struct Engine::Impl {
  Precision precision;
  MemoryLedger ledger;
  std::optional<Volume> volume;
  TransferFunction tf;
  bool hasTf = false;
  Camera camera;
  PointLight light;

  // Derived state, rebuilt lazily.
  DeviceBuffer<glm::vec4> table;
  bool tableDirty = true;
  int tableToken = 0;
  float tableMaxExtinction = 0.f;
  FrustumGrid lightFrustum;
  std::optional<Field3D> lightTransmittance;
  bool lightDirty = true;
  int lightGridSize = 0, lightGridDepth = -1;

  std::optional<Field3D> importance;
  ExtinctionSettings extinctionSettings;
  ExtinctionOptimizer optimizer{&ledger, Precision::FP32};
  bool frozen = false;
  bool renderOptimized = true;
  int viewportWidth = 512, viewportHeight = 512;

  explicit Impl(Precision p) : precision(p), optimizer(&ledger, p) {}

  void clearScene() {
    optimizer.reset();
    importance.reset();
    volume.reset();
    frozen = false;
  }

  OptimizationInputs optimizationInputs() {
    if (!volume) throw Error(ErrorKind::Usage, "no volume loaded");
    if (!importance)
      throw Error(ErrorKind::Usage, "no importance: give an importance curve or volume first");
    ensureTable();
    OptimizationInputs in;
    in.volume = &*volume;
    in.importance = &*importance;
    in.transfer = &table;
    in.transferMaxExtinction = tableMaxExtinction;
    in.camera = camera;
    in.light = light;
    in.imageWidth = viewportWidth;
    in.imageHeight = viewportHeight;
    return in;
  }

  void invalidateAll() {
    tableDirty = true;
    lightDirty = true;
  }

  void frameView(float az, float el, float dist) {
    camera = Camera::orbitBounds(volume->grid().worldBounds(), az, el, dist);
    light = PointLight::keyLightFor(camera, volume->grid().worldBounds());
    lightDirty = true;
  }

  void ensureTable() {
    if (!tableDirty) return;
    if (!hasTf)
      tf = TransferFunction::preset("generic", volume->valueMin, volume->valueMax), hasTf = true;
    TransferTable baked =
        tf.bake(volume->valueMin, volume->valueMax, volume->grid().minSpacing(), 1024);
    if (tableToken) ledger.remove(tableToken);
    table = DeviceBuffer<glm::vec4>(baked.albedoExtinction.size());
    for (size_t i = 0; i < table.size(); ++i) table[i] = baked.albedoExtinction[i];
    tableToken = ledger.add("transfer-table", table.bytes(), "fp32");
    tableMaxExtinction = baked.maxExtinction;
    tableDirty = false;
    lightDirty = true;
  }

  RenderScene scene() const {
    RenderScene s;
    s.volume = &*volume;
    s.transfer = &table;
    s.camera = camera;
    s.light = light;
    if (renderOptimized) s.extinction = optimizer.extinction();
    if (lightTransmittance) {
      s.lightFrustum = &lightFrustum;
      s.lightTransmittance = &*lightTransmittance;
    }
    return s;
  }

  double ensureLight(const RenderSettings& settings) {
    if (!lightDirty && settings.lightGridSize == lightGridSize &&
        settings.lightGridDepth == lightGridDepth && lightTransmittance)
      return 0.0;
    auto start = std::chrono::steady_clock::now();
    const GridSpec& g = volume->grid();
    // One depth cell per smallest voxel spacing unless asked otherwise.
    lightFrustum = FrustumGrid::forLight(
        light, g.worldBounds(),
        glm::ivec3(settings.lightGridSize, settings.lightGridSize, settings.lightGridDepth),
        2.f * g.minSpacing());
    GridSpec lg;
    lg.dims = lightFrustum.dims;
    if (!lightTransmittance || lightTransmittance->grid().dims != lg.dims)
      lightTransmittance.emplace("light-transmittance", lg, precision, &ledger);
    computeLightTransmittance(scene(), lightFrustum, *lightTransmittance);
    lightGridSize = settings.lightGridSize;
    lightGridDepth = settings.lightGridDepth;
    lightDirty = false;
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  }
};

Engine::Engine(Precision precision) : impl_(std::make_unique<Impl>(precision)) {}
Engine::~Engine() = default;

Precision Engine::precision() const { return impl_->precision; }

void Engine::loadVolume(const std::string& path, const ProgressCallback& progress) {
  impl_->clearScene();
  impl_->volume.emplace(readVolume(path, impl_->precision, &impl_->ledger, progress));
  impl_->hasTf = false;
  impl_->invalidateAll();
  impl_->frameView(0.f, 10.f, 2.6f);
}

void Engine::loadBuiltinScene(const std::string& name, int resolution) {
  impl_->clearScene();
  BuiltinScene scene = makeBuiltinScene(name, resolution, impl_->precision, &impl_->ledger);
  impl_->volume.emplace(std::move(scene.volume));
  if (!scene.importance.empty())
    impl_->importance.emplace(std::move(scene.importance));
  else if (!scene.importanceCurve.empty())
    impl_->importance.emplace(importanceFromNormalizedCurve(*impl_->volume, scene.importanceCurve,
                                                            impl_->precision, &impl_->ledger));
  impl_->tf = std::move(scene.transferFunction);
  impl_->hasTf = true;
  impl_->invalidateAll();
  impl_->frameView(scene.azimuthDeg, scene.elevationDeg, scene.distanceInRadii);
}

void Engine::setVolume(Volume volume) {
  impl_->clearScene();
  impl_->volume.emplace(std::move(volume));
  impl_->hasTf = false;
  impl_->invalidateAll();
  impl_->frameView(0.f, 10.f, 2.6f);
}

bool Engine::hasVolume() const { return impl_->volume.has_value(); }

const Volume& Engine::volume() const {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  return *impl_->volume;
}

void Engine::setTransferFunction(TransferFunction tf) {
  tf.validate();
  impl_->tf = std::move(tf);
  impl_->hasTf = true;
  impl_->tableDirty = true;
  impl_->optimizer.reset();  // mu_bar changed: the optimised mu no longer applies
}

const TransferFunction& Engine::transferFunction() const {
  if (!impl_->hasTf && impl_->volume) {
    impl_->tf = TransferFunction::preset("generic", impl_->volume->valueMin, impl_->volume->valueMax);
    impl_->hasTf = true;
  }
  return impl_->tf;
}

void Engine::setCamera(const Camera& camera) { impl_->camera = camera; }
const Camera& Engine::camera() const { return impl_->camera; }

void Engine::orbitCamera(float azimuthDeg, float elevationDeg, float distanceInRadii) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  impl_->camera = Camera::orbitBounds(impl_->volume->grid().worldBounds(), azimuthDeg,
                                      elevationDeg, distanceInRadii);
}

void Engine::setLight(const PointLight& light) {
  impl_->light = light;
  impl_->lightDirty = true;
}
const PointLight& Engine::light() const { return impl_->light; }

Image Engine::render(const RenderSettings& settings, RenderStats* stats) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  impl_->ensureTable();
  double lightMs = impl_->ensureLight(settings);
  Image image = renderImage(impl_->scene(), settings, stats);
  if (stats) stats->lightMilliseconds = lightMs;
  return image;
}

const MemoryLedger& Engine::ledger() const { return impl_->ledger; }

void Engine::setImportanceCurve(const std::vector<glm::dvec2>& points, const std::string& origin) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before its importance");
  impl_->importance.reset();
  impl_->importance.emplace(importanceFromCurve(*impl_->volume, points, origin, impl_->precision,
                                                &impl_->ledger));
  impl_->optimizer.reset();
}

void Engine::loadImportance(const std::string& path) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before its importance");
  if (isCurveFile(path)) {
    setImportanceCurve(readImportanceCurve(path), path);
    return;
  }
  Field3D g = importanceFromVolumeFile(*impl_->volume, path, impl_->precision, &impl_->ledger);
  impl_->importance.reset();
  impl_->importance.emplace(std::move(g));
  impl_->optimizer.reset();
}

bool Engine::hasImportance() const { return impl_->importance.has_value(); }
const Field3D* Engine::importance() const {
  return impl_->importance ? &*impl_->importance : nullptr;
}

void Engine::setExtinctionSettings(const ExtinctionSettings& settings) {
  impl_->extinctionSettings = settings;
}
const ExtinctionSettings& Engine::extinctionSettings() const { return impl_->extinctionSettings; }

void Engine::setViewportSize(int width, int height) {
  if (width <= 0 || height <= 0) throw Error(ErrorKind::Usage, "viewport size must be positive");
  impl_->viewportWidth = width;
  impl_->viewportHeight = height;
}

std::vector<IterationStats> Engine::optimize(
    const std::function<bool(const IterationStats&)>& callback) {
  if (impl_->frozen) return {};
  auto stats =
      impl_->optimizer.runMultigrid(impl_->optimizationInputs(), impl_->extinctionSettings, callback);
  impl_->lightDirty = true;
  return stats;
}

std::vector<IterationStats> Engine::continueOptimization(
    int iterations, const std::function<bool(const IterationStats&)>& callback) {
  if (impl_->frozen || iterations <= 0) return {};
  auto stats = impl_->optimizer.iterate(impl_->optimizationInputs(), impl_->extinctionSettings,
                                        iterations, callback);
  impl_->lightDirty = true;
  return stats;
}

void Engine::setFrozen(bool frozen) { impl_->frozen = frozen; }
bool Engine::frozen() const { return impl_->frozen; }

void Engine::resetOptimization() {
  impl_->optimizer.reset();
  impl_->lightDirty = true;
}

bool Engine::hasOptimizedExtinction() const { return impl_->optimizer.extinction() != nullptr; }
const Field3D* Engine::optimizedExtinction() const { return impl_->optimizer.extinction(); }

void Engine::setRenderOptimized(bool useOptimized) {
  if (impl_->renderOptimized != useOptimized) impl_->lightDirty = true;
  impl_->renderOptimized = useOptimized;
}

}  // namespace visopt
