#include "visopt/engine.h"

#include <chrono>
#include <cmath>
#include <optional>

#include "core/device_bit_mask.h"
#include "core/device_buffer.h"
#include "engine/clearview_cache.h"
#include "engine/context_surfaces.h"
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
  // Empty-space block ranges of the volume (computed at its first render, dropped with it) and
  // of the extinction change (computed with it): a preview spent ~15 % of its time on each.
  std::optional<DeviceBuffer<glm::vec2>> volumeBlockRange, changeBlockRange;
  int volumeBlockRangeToken = 0, changeBlockRangeToken = 0;
  float tableMaxExtinction = 0.f;
  FrustumGrid lightFrustum;
  std::optional<Field3D> lightTransmittance;
  bool lightDirty = true;
  // The optimisation changed mu since T_L and the extinction change were computed: a full frame
  // recomputes both, a preview reuses them (render()).
  bool muChanged = false;
  // followCamera corrected mu since the extinction change was drawn: a preview draws the change
  // again (a pass over the volume) but keeps T_L, so what the drag opened shows while dragging.
  bool followedSinceChange = false;
  // T_L holds the light's transmittance through an earlier mu (or, after a full frame that gave
  // way to a newer camera, partly through it): a full frame recomputes it, a preview may use it
  // (lightDirty, by contrast, means the light, the transfer function or the scene changed).
  bool lightFromOlderMu = false;
  // What T_L was computed for: the method (the scene it draws, and the baselines' surface
  // rules), the cut-away threshold and the baseline it drew (baselineRevision).
  RenderMethod lightMethod = RenderMethod::Optimized;
  float lightCut = 0.f;
  uint64_t lightBaseline = 0;
  int lightGridSize = 0, lightGridDepth = -1;

  std::optional<Field3D> importance;
  Engine::ImportanceSource importanceSource;
  std::vector<ContextSurfaceSpec> surfaceSpecs;
  std::vector<Field3D> surfaceBases;
  LevelSetSettings levelSet;
  std::optional<BitMask> worldMask;             // what worldMask() returns
  std::optional<DeviceBitMask> worldMaskWords;  // the same bits for the kernels
  ImportanceLens lens;
  std::optional<Field3D> screenMask;
  ExtinctionSettings extinctionSettings;
  ExtinctionOptimizer optimizer{&ledger, Precision::FP32};
  // The Fig. 10 baselines' volume: the optimisation of [9] with the surfaces held at phi0
  // (Engine::optimizeBaseline), current while what it was computed for stays (baselineKey).
  ExtinctionOptimizer baselineOptimizer{&ledger, Precision::FP32, " (baseline)"};
  struct BaselineKey {
    Camera camera;
    PointLight light;
    int width = 0, height = 0;
    uint64_t importance = 0;
    int table = 0;
    ExtinctionSettings settings;
    bool operator==(const BaselineKey&) const = default;
  };
  std::optional<BaselineKey> baselineKey;
  uint64_t baselineRevision = 0;  // counts the baselines computed
  bool frozen = false;
  bool renderOptimized = true;
  // The optimised mu as the renderer draws it (render/renderer.h), refreshed at each render.
  std::optional<Field3D> extinctionChange;
  int viewportWidth = 512, viewportHeight = 512;
  // Counts the changes of what ghat (Eq. 19) reads besides the frusta: the importance and the
  // screen weights (lens, windowing mask). The optimiser recomputes ghat when it changes.
  uint64_t importanceRevision = 0;
  // Counts the changes of the volume, the transfer function and the context surfaces (also the
  // optimisation's moves): ClearView extracts its layers again when it changes.
  uint64_t sceneRevision = 0;
  std::unique_ptr<ClearViewCache> clearView;
  // Ambient occlusion of the volume's samples (render/renderer.h): allocated only while a render
  // asks for ambient occlusion with an ambient term, recomputed when what it reads changes.
  struct OcclusionKey {
    uint64_t scene = 0, importance = 0;
    int table = 0, method = 0;
    float radius = 0.f, cutThreshold = 0.f;
    const Field3D* mu = nullptr;  // the optimised mu drawn, or null for mu_bar
    uint64_t baseline = 0;
    std::vector<bool> visible;
    bool operator==(const OcclusionKey&) const = default;
  };
  std::optional<Field3D> volumeOcclusion;
  OcclusionKey occlusionKey;

  explicit Impl(Precision p)
      : precision(p), optimizer(&ledger, p), baselineOptimizer(&ledger, p, " (baseline)") {}

  // What a method draws: ours (the optimised mu and surfaces), the Fig. 10 baselines' volume
  // (cut-away and transparency modulation: the baseline mu under the base surfaces), or the
  // scene as loaded (maximum importance projection).
  enum class Drawn { Ours, Baseline, Base };
  static Drawn drawnBy(RenderMethod m) {
    if (m == RenderMethod::Optimized) return Drawn::Ours;
    if (m == RenderMethod::CutAway || m == RenderMethod::TransparencyModulation)
      return Drawn::Baseline;
    return Drawn::Base;
  }
  // The optimised mu that `d` draws, or null for mu_bar.
  const Field3D* muOf(Drawn d) const {
    if (!renderOptimized) return nullptr;
    if (d == Drawn::Ours) return optimizer.extinction();
    if (d == Drawn::Baseline && baselineCurrent()) return baselineOptimizer.extinction();
    return nullptr;
  }
  Drawn changeDrawn = Drawn::Ours;  // what extinctionChange was computed for

  void resetBaseline() {
    baselineOptimizer.reset();
    baselineKey.reset();
  }

  BaselineKey currentBaselineKey() const {
    return BaselineKey{camera,
                       light,
                       viewportWidth,
                       viewportHeight,
                       importanceRevision,
                       tableToken,
                       extinctionSettings};
  }
  // The baseline was computed for what the scene now is (a transfer function set since then
  // is not baked yet: its table token is not current).
  bool baselineCurrent() const {
    return baselineKey && !tableDirty && *baselineKey == currentBaselineKey() &&
           baselineOptimizer.extinction();
  }

  void clearScene() {
    volumeOcclusion.reset();
    volumeBlockRange.reset();
    if (volumeBlockRangeToken) ledger.remove(volumeBlockRangeToken);
    volumeBlockRangeToken = 0;
    optimizer.reset();
    resetBaseline();
    importance.reset();
    importanceSource = {};
    surfaceSpecs.clear();
    surfaceBases.clear();
    worldMask.reset();
    worldMaskWords.reset();
    volume.reset();
    frozen = false;
    ++importanceRevision;
    ++sceneRevision;
    clearView.reset();
  }

  OptimizationInputs optimizationInputs() {
    if (!volume) throw Error(ErrorKind::Usage, "no volume loaded");
    if (!importance)
      throw Error(ErrorKind::Usage, "no importance: give an importance curve or volume first");
    checkCamera(camera, volume->grid().worldBounds());
    checkLight(light, volume->grid().worldBounds());
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
    for (const auto& b : surfaceBases) in.surfaceBases.push_back(&b);
    in.levelSet = levelSet;
    in.worldMask = worldMaskWords ? &*worldMaskWords : nullptr;
    in.lens = lens;
    in.screenMask = screenMask ? &*screenMask : nullptr;
    in.importanceRevision = importanceRevision;
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

  // The scene as `d` draws it: ours (the optimised mu and surfaces), the baselines' (their mu,
  // the base surfaces phi0 and their ghat) or the one loaded (mu_bar, phi0); mu_bar throughout
  // while the optimised mu is not drawn (setRenderOptimized).
  RenderScene scene(Drawn d = Drawn::Ours) const {
    RenderScene s;
    s.volume = &*volume;
    s.transfer = &table;
    s.camera = camera;
    s.light = light;
    const bool useOptimized = d == Drawn::Ours && renderOptimized;
    if (muOf(d) && extinctionChange && changeDrawn == d) s.extinctionChange = &*extinctionChange;
    const auto phis = optimizer.surfaces();
    for (size_t i = 0; i < surfaceSpecs.size(); ++i) {
      if (!surfaceSpecs[i].visible) continue;
      s.surfaces.push_back(useOptimized && i < phis.size() ? phis[i] : &surfaceBases[i]);
      s.surfaceBases.push_back(&surfaceBases[i]);
      s.surfaceColors.push_back(surfaceSpecs[i].color);
    }
    s.importanceBehind = d == Drawn::Baseline
                             ? (baselineCurrent() ? baselineOptimizer.importanceBehind() : nullptr)
                             : optimizer.importanceBehind();
    s.importance = importance ? &*importance : nullptr;
    if (worldMaskWords) s.worldMask = worldMaskWords->view();
    if (volumeBlockRange) s.volumeBlockRange = &*volumeBlockRange;
    if (s.extinctionChange && changeBlockRange) s.changeBlockRange = &*changeBlockRange;
    if (volumeOcclusion) s.volumeOcclusion = &*volumeOcclusion;
    if (lightTransmittance) {
      s.lightFrustum = &lightFrustum;
      s.lightTransmittance = &*lightTransmittance;
    }
    return s;
  }

  // Allocated only while an optimised mu is drawn.
  void updateExtinctionChange(Drawn d) {
    const Field3D* mu = muOf(d);
    changeDrawn = d;
    changeBlockRange.reset();
    if (changeBlockRangeToken) ledger.remove(changeBlockRangeToken);
    changeBlockRangeToken = 0;
    if (!mu) {
      extinctionChange.reset();
      return;
    }
    const GridSpec& g = volume->grid();
    if (!extinctionChange || extinctionChange->grid() != g ||
        extinctionChange->precision() != precision)
      extinctionChange.emplace("extinction-change (render)", g, precision, &ledger);
    computeExtinctionChange(*volume, table, *mu, *extinctionChange);
    changeBlockRange.emplace(computeBlockRange(*extinctionChange));
    changeBlockRangeToken =
        ledger.add("render-skip-ranges (change)", changeBlockRange->bytes(), "fp32");
  }

  void ensureVolumeBlockRange() {
    if (volumeBlockRange) return;
    volumeBlockRange.emplace(computeBlockRange(volume->normalized));
    volumeBlockRangeToken = ledger.add("render-skip-ranges", volumeBlockRange->bytes(), "fp32");
  }

  // The volume's ambient occlusion for these settings, or none when they ask for none. A preview
  // that reuses the last full frame's extinction change (`reuse`) reuses its occlusion too.
  // Returns the milliseconds spent.
  double ensureVolumeOcclusion(const RenderSettings& settings, bool reuse) {
    if (!settings.ambientOcclusion || !(settings.ambient > 0.f) ||
        !(settings.ambientOcclusionRadius > 0.f)) {
      volumeOcclusion.reset();
      return 0.0;
    }
    if (reuse && volumeOcclusion) return 0.0;
    const GridSpec& g = volume->grid();
    OcclusionKey key;
    key.scene = sceneRevision;
    key.importance = importanceRevision;
    key.table = tableToken;
    key.method = static_cast<int>(settings.method);
    key.radius = settings.ambientOcclusionRadius * g.minSpacing();
    key.cutThreshold = settings.cutAwayThreshold;
    key.mu = muOf(drawnBy(settings.method));
    key.baseline = drawnBy(settings.method) == Drawn::Baseline ? baselineRevision : 0;
    for (const auto& spec : surfaceSpecs) key.visible.push_back(spec.visible);
    if (volumeOcclusion && volumeOcclusion->grid() == g && key == occlusionKey) return 0.0;
    const auto start = std::chrono::steady_clock::now();
    if (!volumeOcclusion || volumeOcclusion->grid() != g ||
        volumeOcclusion->precision() != precision)
      volumeOcclusion.emplace("volume-occlusion (render)", g, precision, &ledger);
    RenderScene s = scene(drawnBy(settings.method));
    s.volumeOcclusion = nullptr;
    computeVolumeOcclusion(s, settings.method, settings.cutAwayThreshold, key.radius,
                           *volumeOcclusion);
    occlusionKey = std::move(key);
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  }

  // T_L for these settings; false when `abandon` stopped it (lightDirty / lightFromOlderMu then
  // stay set, so the next full frame computes it again).
  bool ensureLight(const RenderSettings& settings, const std::function<bool()>& abandon,
                   double& ms) {
    ms = 0.0;
    const bool sameGrid = settings.lightGridSize == lightGridSize &&
                          settings.lightGridDepth == lightGridDepth && lightTransmittance;
    if (!lightDirty && sameGrid && (!lightFromOlderMu || settings.preview)) return true;
    // Only mu changed: T_L given up part way (new on some rays, of an earlier mu on the others)
    // still serves a preview. Anything else given up part way must be computed again.
    const bool onlyOlderMu = !lightDirty && sameGrid;
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
    const bool done =
        computeLightTransmittance(scene(drawnBy(lightMethod)), lightFrustum, *lightTransmittance,
                                  abandon, lightMethod, lightCut);
    ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!done) {
      if (!onlyOlderMu) lightDirty = true;
      return false;
    }
    lightGridSize = settings.lightGridSize;
    lightGridDepth = settings.lightGridDepth;
    lightDirty = lightFromOlderMu = false;
    return true;
  }
};

Engine::Engine(Precision precision) : impl_(std::make_unique<Impl>(precision)) {}
Engine::~Engine() = default;

Precision Engine::precision() const {
  return impl_->precision;
}

void Engine::loadVolume(const std::string& path, const ProgressCallback& progress) {
  impl_->clearScene();
  impl_->volume.emplace(readVolume(path, impl_->precision, &impl_->ledger, progress));
  impl_->hasTf = false;
  impl_->invalidateAll();
  impl_->frameView(kDefaultVolumeView.azimuthDeg, kDefaultVolumeView.elevationDeg,
                   kDefaultVolumeView.distanceInRadii);
}

void Engine::loadBuiltinScene(const std::string& name, int resolution, bool contextSurfaces) {
  impl_->clearScene();
  BuiltinScene scene = makeBuiltinScene(name, resolution, impl_->precision, &impl_->ledger);
  impl_->volume.emplace(std::move(scene.volume));
  impl_->importanceSource.kind = ImportanceSource::Kind::Scene;
  if (!scene.importance.empty())
    impl_->importance.emplace(std::move(scene.importance));
  else if (!scene.importanceCurve.empty())
    impl_->importance.emplace(importanceFromNormalizedCurve(*impl_->volume, scene.importanceCurve,
                                                            impl_->precision, &impl_->ledger));
  const bool withSurfaces = contextSurfaces && !scene.contextSurfaces.empty();
  impl_->tf =
      withSurfaces ? std::move(scene.contextTransferFunction) : std::move(scene.transferFunction);
  impl_->hasTf = true;
  impl_->invalidateAll();
  impl_->frameView(scene.azimuthDeg, scene.elevationDeg, scene.distanceInRadii);
  if (withSurfaces)
    for (const auto& spec : scene.contextSurfaces) addContextSurface(spec);
}

void Engine::setVolume(Volume volume) {
  impl_->clearScene();
  impl_->volume.emplace(std::move(volume));
  impl_->hasTf = false;
  impl_->invalidateAll();
  impl_->frameView(kDefaultVolumeView.azimuthDeg, kDefaultVolumeView.elevationDeg,
                   kDefaultVolumeView.distanceInRadii);
}

bool Engine::hasVolume() const {
  return impl_->volume.has_value();
}

const Volume& Engine::volume() const {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  return *impl_->volume;
}

void Engine::setTransferFunction(TransferFunction tf) {
  tf.validate();
  impl_->tf = std::move(tf);
  impl_->hasTf = true;
  impl_->tableDirty = true;  // mu_bar changes; the optimisation continues from its current mu
  ++impl_->sceneRevision;
}

const TransferFunction& Engine::transferFunction() const {
  if (!impl_->hasTf && impl_->volume) {
    impl_->tf =
        TransferFunction::preset("generic", impl_->volume->valueMin, impl_->volume->valueMax);
    impl_->hasTf = true;
  }
  return impl_->tf;
}

void Engine::setCamera(const Camera& camera) {
  if (impl_->volume) checkCamera(camera, impl_->volume->grid().worldBounds());
  impl_->camera = camera;
}
const Camera& Engine::camera() const {
  return impl_->camera;
}

void Engine::orbitCamera(float azimuthDeg, float elevationDeg, float distanceInRadii) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  checkOrbit(azimuthDeg, elevationDeg, distanceInRadii);
  const Bounds bounds = impl_->volume->grid().worldBounds();
  const Camera camera = Camera::orbitBounds(bounds, azimuthDeg, elevationDeg, distanceInRadii);
  checkCamera(camera, bounds);
  impl_->camera = camera;
}

void Engine::setLight(const PointLight& light) {
  if (impl_->volume) checkLight(light, impl_->volume->grid().worldBounds());
  impl_->light = light;
  impl_->lightDirty = true;
}
const PointLight& Engine::light() const {
  return impl_->light;
}

Image Engine::render(const RenderSettings& settings, RenderStats* stats,
                     const std::function<bool()>& abandon) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  checkRenderSettings(settings);  // before the light grid or the image is allocated
  // A camera or light set before the volume (or one a session carried) meets its bounds here.
  const Bounds bounds = impl_->volume->grid().worldBounds();
  checkCamera(impl_->camera, bounds);
  checkLight(impl_->light, bounds);
  impl_->ensureTable();
  using Drawn = Impl::Drawn;
  const Drawn drawn = Impl::drawnBy(settings.method);
  // Cut-away and transparency modulation draw the extinction optimised as in [9].
  if (drawn == Drawn::Baseline) {
    optimizeBaseline({}, abandon);
    if (!impl_->baselineCurrent()) return Image();  // abandoned
  }
  // T_L of another scene, or of the baselines' surfaces cut or faded otherwise.
  const bool baseline = drawn == Drawn::Baseline;
  if (settings.method != impl_->lightMethod ||
      (baseline && impl_->baselineRevision != impl_->lightBaseline) ||
      (settings.method == RenderMethod::CutAway && settings.cutAwayThreshold != impl_->lightCut))
    impl_->lightDirty = true;
  impl_->lightMethod = settings.method;
  impl_->lightCut = settings.cutAwayThreshold;
  impl_->lightBaseline = baseline ? impl_->baselineRevision : 0;
  // A preview while the optimisation runs (the user drags the camera) draws the latest mu with
  // the T_L and extinction change of the last full frame: recomputing them took twice the
  // preview's own render time.
  const bool reuse =
      settings.preview && impl_->muChanged && !impl_->lightDirty && impl_->lightTransmittance &&
      (!impl_->muOf(drawn) || (impl_->extinctionChange && impl_->changeDrawn == drawn));
  if (!reuse) {
    if (impl_->muChanged) impl_->lightFromOlderMu = true;
    impl_->muChanged = impl_->followedSinceChange = false;
    impl_->updateExtinctionChange(drawn);
  } else if (impl_->followedSinceChange && drawn == Drawn::Ours) {
    impl_->lightFromOlderMu = true;  // muChanged stays: the next full frame computes T_L again
    impl_->followedSinceChange = false;
    impl_->updateExtinctionChange(drawn);
  }
  // A full frame's T_L gives way to a newer camera too: the preview that answers it draws with
  // the T_L of an earlier mu (lightFromOlderMu), the next full frame computes it whole.
  double lightMs = 0.0;
  if (!impl_->ensureLight(settings, abandon, lightMs)) return Image();
  impl_->ensureVolumeBlockRange();
  if (abandon && abandon()) return Image();
  const double occlusionMs = impl_->ensureVolumeOcclusion(settings, reuse);
  if (abandon && abandon()) return Image();
  Image image = renderImage(impl_->scene(drawn), settings, stats, abandon);
  if (stats) {
    stats->lightMilliseconds = lightMs;
    stats->occlusionMilliseconds = occlusionMs;
  }
  return image;
}

Image Engine::renderClearView(const ClearViewSettings& settings, ClearViewStats* stats) {
  Image image;
  renderClearView(settings, image, stats);
  return image;
}

void Engine::renderClearView(const ClearViewSettings& settings, Image& image,
                             ClearViewStats* stats) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "no volume loaded");
  checkClearViewSettings(settings);
  const Volume& volume = *impl_->volume;
  const Bounds bounds = volume.grid().worldBounds();
  checkCamera(impl_->camera, bounds);
  checkLight(impl_->light, bounds);
  impl_->ensureTable();
  const auto source = [&](const ClearViewLayer& layer, const std::string& r) {
    ClearViewSurfaceSource s;
    switch (layer.kind) {
      case ClearViewLayerKind::Isosurface:
        if (!(layer.isovalue > volume.valueMin && layer.isovalue < volume.valueMax))
          throw Error(ErrorKind::Usage,
                      "ClearView: the " + r + " isovalue " + std::to_string(layer.isovalue) +
                          " lies outside the data's range (" + std::to_string(volume.valueMin) +
                          ", " + std::to_string(volume.valueMax) + ")");
        s.field = &volume.normalized;
        s.iso = volume.toNormalized(layer.isovalue);
        break;
      case ClearViewLayerKind::ContextSurface:
        if (layer.surface >= int(impl_->surfaceBases.size()))
          throw Error(ErrorKind::Usage, "ClearView: the " + r + " layer names context surface " +
                                            std::to_string(layer.surface) + ", the scene has " +
                                            std::to_string(impl_->surfaceBases.size()));
        // The surface as the renderer draws it: optimised when that is what is shown.
        s.field = impl_->renderOptimized ? contextSurfacePhi(layer.surface)
                                         : &impl_->surfaceBases[size_t(layer.surface)];
        s.sign = -1.f;  // inside negative
        break;
      case ClearViewLayerKind::Importance:
        if (!impl_->importance)
          throw Error(ErrorKind::Usage, "ClearView: the " + r + " layer needs an importance");
        s.field = &*impl_->importance;
        s.iso = float(layer.isovalue);
        break;
    }
    return s;
  };
  ClearViewInputs in;
  in.volume = &volume;
  in.transfer = &impl_->table;
  in.transferToken = impl_->tableToken;
  in.camera = impl_->camera;
  in.light = impl_->light;
  in.contexts.push_back(source(settings.context, "context"));
  for (size_t i = 0; i < settings.deeperContexts.size(); ++i)
    in.contexts.push_back(source(settings.deeperContexts[i], "context " + std::to_string(i + 2)));
  in.foci.push_back(source(settings.focus, "focus"));
  for (size_t i = 0; i < settings.moreFoci.size(); ++i)
    in.foci.push_back(source(settings.moreFoci[i], "focus " + std::to_string(i + 2)));
  in.sceneRevision = impl_->sceneRevision;
  in.importanceRevision = impl_->importanceRevision;
  if (!impl_->clearView) impl_->clearView = std::make_unique<ClearViewCache>(&impl_->ledger);
  impl_->clearView->render(in, settings, stats, image);
}

const MemoryLedger& Engine::ledger() const {
  return impl_->ledger;
}

int Engine::addContextSurface(const ContextSurfaceSpec& spec, const ProgressCallback& progress) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before its context surfaces");
  if (impl_->surfaceBases.size() >= 4)
    throw Error(ErrorKind::Usage, "at most 4 context surfaces are supported");
  impl_->surfaceBases.push_back(buildContextSurface(spec, *impl_->volume, impl_->levelSet,
                                                    impl_->precision, &impl_->ledger, progress));
  impl_->surfaceSpecs.push_back(spec);
  impl_->optimizer.reset();
  impl_->resetBaseline();
  impl_->lightDirty = true;
  ++impl_->sceneRevision;
  return int(impl_->surfaceSpecs.size()) - 1;
}

int Engine::addContextSurface(const ContextSurfaceSpec& spec, const Field3D& baseSdf) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before its context surfaces");
  if (impl_->surfaceBases.size() >= 4)
    throw Error(ErrorKind::Usage, "at most 4 context surfaces are supported");
  if (baseSdf.grid().dims != impl_->volume->grid().dims)
    throw Error(ErrorKind::Usage, "a context surface's SDF must be on the volume's grid");
  Field3D base("surface-base", impl_->volume->grid(), impl_->precision, &impl_->ledger);
  for (size_t i = 0; i < base.size(); ++i) base.set(i, baseSdf.get(i));
  impl_->surfaceBases.push_back(std::move(base));
  impl_->surfaceSpecs.push_back(spec);
  impl_->optimizer.reset();
  impl_->resetBaseline();
  impl_->lightDirty = true;
  ++impl_->sceneRevision;
  return int(impl_->surfaceSpecs.size()) - 1;
}

void Engine::clearContextSurfaces() {
  impl_->surfaceSpecs.clear();
  impl_->surfaceBases.clear();
  impl_->optimizer.reset();
  impl_->resetBaseline();
  impl_->lightDirty = true;
  ++impl_->sceneRevision;
}

void Engine::removeContextSurface(int index) {
  if (index < 0 || index >= int(impl_->surfaceSpecs.size()))
    throw Error(ErrorKind::Usage, "no context surface " + std::to_string(index));
  impl_->surfaceSpecs.erase(impl_->surfaceSpecs.begin() + index);
  impl_->surfaceBases.erase(impl_->surfaceBases.begin() + index);
  impl_->optimizer.reset();
  impl_->resetBaseline();
  impl_->lightDirty = true;
  ++impl_->sceneRevision;
}

void Engine::setContextSurfaceColor(int index, glm::vec3 rgb) {
  if (index < 0 || index >= int(impl_->surfaceSpecs.size()))
    throw Error(ErrorKind::Usage, "no context surface " + std::to_string(index));
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(rgb[c]) || rgb[c] < 0.f)
      throw Error(ErrorKind::Usage, "a surface colour must be finite and non-negative");
  impl_->surfaceSpecs[size_t(index)].color = rgb;
}

const std::vector<ContextSurfaceSpec>& Engine::contextSurfaces() const {
  return impl_->surfaceSpecs;
}

void Engine::setContextSurfaceVisible(int index, bool visible) {
  if (index < 0 || index >= int(impl_->surfaceSpecs.size()))
    throw Error(ErrorKind::Usage, "no context surface " + std::to_string(index));
  impl_->surfaceSpecs[size_t(index)].visible = visible;
  impl_->lightDirty = true;
}

const Field3D* Engine::contextSurfacePhi(int index) const {
  if (index < 0 || index >= int(impl_->surfaceBases.size())) return nullptr;
  auto optimized = impl_->optimizer.surfaces();
  if (size_t(index) < optimized.size()) return optimized[size_t(index)];
  return &impl_->surfaceBases[size_t(index)];
}

const Field3D* Engine::contextSurfaceBase(int index) const {
  if (index < 0 || index >= int(impl_->surfaceBases.size())) return nullptr;
  return &impl_->surfaceBases[size_t(index)];
}

void Engine::setLevelSetSettings(const LevelSetSettings& settings) {
  checkLevelSetSettings(settings);
  impl_->levelSet = settings;
}
const LevelSetSettings& Engine::levelSetSettings() const {
  return impl_->levelSet;
}

void Engine::loadWorldMask(const std::string& path) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before a mask");
  Volume m = readVolume(path, Precision::FP32, nullptr);
  if (m.grid().dims != impl_->volume->grid().dims)
    throwBadInput(path, "the mask's dimensions differ from the data's");
  BitMask mask = BitMask::cleared(m.grid().dims);
  for (size_t i = 0; i < m.normalized.size(); ++i)
    if (m.toValue(m.normalized.get(i)) != 0.0) mask.set(i, true);
  setWorldMask(std::move(mask));
}

void Engine::setWorldMask(BitMask mask) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before a mask");
  const glm::ivec3 d = impl_->volume->grid().dims;
  if (mask.dims != d)
    throw Error(ErrorKind::Usage, "the mask's dimensions " + std::to_string(mask.dims.x) + "x" +
                                      std::to_string(mask.dims.y) + "x" +
                                      std::to_string(mask.dims.z) + " differ from the volume's " +
                                      std::to_string(d.x) + "x" + std::to_string(d.y) + "x" +
                                      std::to_string(d.z));
  if (mask.bits.size() != (mask.voxelCount() + 7) / 8)
    throw Error(ErrorKind::Usage, "the mask holds " + std::to_string(mask.bits.size()) +
                                      " bytes, not one bit per voxel");
  impl_->worldMaskWords.reset();
  impl_->worldMaskWords.emplace(mask, "world-mask", &impl_->ledger);
  impl_->worldMask = std::move(mask);
}

void Engine::setWorldMask(const Field3D& mask) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before a mask");
  if (mask.grid().dims != impl_->volume->grid().dims)
    throw Error(ErrorKind::Usage, "the mask must be on the volume's grid");
  setWorldMask(packMask(mask));
}

void Engine::clearWorldMask() {
  impl_->worldMaskWords.reset();
  impl_->worldMask.reset();
}
const BitMask* Engine::worldMask() const {
  return impl_->worldMask ? &*impl_->worldMask : nullptr;
}

void Engine::setLens(const ImportanceLens& lens) {
  if (!std::isfinite(lens.radius) || lens.radius < 0.f || !std::isfinite(lens.strength) ||
      lens.strength < 0.f || !std::isfinite(lens.x) || !std::isfinite(lens.y))
    throw Error(ErrorKind::Usage, "the lens needs a finite position, radius >= 0, strength >= 0");
  impl_->lens = lens;
  ++impl_->importanceRevision;
}
const ImportanceLens& Engine::lens() const {
  return impl_->lens;
}

void Engine::setScreenMask(const std::vector<float>& weights, int width, int height) {
  if (width <= 0 || height <= 0 || weights.size() != size_t(width) * size_t(height))
    throw Error(ErrorKind::Usage, "a screen mask needs width x height weights");
  for (const float w : weights)  // checked before anything changes: a bad mask keeps the old one
    if (!std::isfinite(w) || w < 0.f || w > 1.f)
      throw Error(ErrorKind::Usage, "screen-mask weights must lie in [0, 1]");
  GridSpec g;
  g.dims = glm::ivec3(width, height, 1);
  impl_->screenMask.reset();
  impl_->screenMask.emplace("screen-mask", g, Precision::FP32, &impl_->ledger);
  for (size_t i = 0; i < weights.size(); ++i)
    impl_->screenMask->set(i, weights[i]);  // row 0 at the top, as ScreenWeights reads it
  ++impl_->importanceRevision;
}

void Engine::clearScreenMask() {
  impl_->screenMask.reset();
  ++impl_->importanceRevision;
}

const Field3D* Engine::importanceBehind() const {
  return impl_->optimizer.importanceBehind();
}

void Engine::setImportanceCurve(const std::vector<glm::dvec2>& points, const std::string& origin) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before its importance");
  impl_->importance.reset();
  impl_->importance.emplace(
      importanceFromCurve(*impl_->volume, points, origin, impl_->precision, &impl_->ledger));
  impl_->importanceSource = {ImportanceSource::Kind::Curve, points, {}};
  ++impl_->importanceRevision;
  // The optimisation continues from its current state with the new importance (warm start).
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
  impl_->importanceSource = {ImportanceSource::Kind::Volume, {}, path};
  ++impl_->importanceRevision;
}

void Engine::setImportanceHotspot(glm::vec3 centre, float radius) {
  if (!impl_->volume) throw Error(ErrorKind::Usage, "load a volume before its importance");
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z))
    throw Error(ErrorKind::Usage, "the hotspot's centre must be finite");
  if (!std::isfinite(radius) || !(radius > 0.f))
    throw Error(ErrorKind::Usage, "the hotspot's radius must be positive and finite");
  Field3D g =
      importanceFromHotspot(*impl_->volume, centre, radius, impl_->precision, &impl_->ledger);
  impl_->importance.reset();
  impl_->importance.emplace(std::move(g));
  impl_->importanceSource = {ImportanceSource::Kind::Hotspot, {}, {}, centre, radius};
  ++impl_->importanceRevision;
}

const Engine::ImportanceSource& Engine::importanceSource() const {
  return impl_->importanceSource;
}

bool Engine::hasImportance() const {
  return impl_->importance.has_value();
}
const Field3D* Engine::importance() const {
  return impl_->importance ? &*impl_->importance : nullptr;
}

void Engine::setExtinctionSettings(const ExtinctionSettings& settings) {
  impl_->extinctionSettings = settings;
}
const ExtinctionSettings& Engine::extinctionSettings() const {
  return impl_->extinctionSettings;
}

void Engine::setViewportSize(int width, int height) {
  if (width <= 0 || height <= 0) throw Error(ErrorKind::Usage, "viewport size must be positive");
  impl_->viewportWidth = width;
  impl_->viewportHeight = height;
}
glm::ivec2 Engine::viewportSize() const {
  return {impl_->viewportWidth, impl_->viewportHeight};
}

std::vector<IterationStats> Engine::optimize(
    const std::function<bool(const IterationStats&)>& callback,
    const std::function<bool()>& abandon) {
  if (impl_->frozen) return {};
  // Every iteration changes mu, also for a frame the callback renders.
  const auto noted = [&](const IterationStats& st) {
    impl_->muChanged = true;
    ++impl_->sceneRevision;
    return !callback || callback(st);
  };
  auto stats = impl_->optimizer.runMultigrid(impl_->optimizationInputs(), impl_->extinctionSettings,
                                             noted, abandon);
  impl_->muChanged = true;
  ++impl_->sceneRevision;
  return stats;
}

std::vector<IterationStats> Engine::continueOptimization(
    int iterations, const std::function<bool(const IterationStats&)>& callback,
    const std::function<bool()>& abandon) {
  if (impl_->frozen || iterations <= 0) return {};
  const auto noted = [&](const IterationStats& st) {
    impl_->muChanged = true;
    ++impl_->sceneRevision;
    return !callback || callback(st);
  };
  auto stats = impl_->optimizer.iterate(impl_->optimizationInputs(), impl_->extinctionSettings,
                                        iterations, noted, abandon);
  if (!stats.empty()) {
    impl_->muChanged = true;
    ++impl_->sceneRevision;
  }
  return stats;
}

std::vector<IterationStats> Engine::followCamera(
    int iterations, const std::function<bool(const IterationStats&)>& callback,
    const std::function<bool()>& abandon) {
  if (impl_->frozen || iterations <= 0) return {};
  auto stats = impl_->optimizer.follow(impl_->optimizationInputs(), impl_->extinctionSettings,
                                       iterations, callback, abandon);
  if (!stats.empty()) {  // the finest mu and surfaces changed by the correction
    impl_->muChanged = impl_->followedSinceChange = true;
    ++impl_->sceneRevision;
  }
  return stats;
}

std::vector<IterationStats> Engine::optimizeBaseline(
    const std::function<bool(const IterationStats&)>& callback,
    const std::function<bool()>& abandon) {
  OptimizationInputs in = impl_->optimizationInputs();  // bakes the table: its token is current
  const Impl::BaselineKey key = impl_->currentBaselineKey();
  if (impl_->baselineCurrent()) return {};
  impl_->resetBaseline();
  in.surfacesHeld = true;
  bool abandoned = false;
  const std::function<bool()> watch = [&] {
    abandoned = abandoned || (abandon && abandon());
    return abandoned;
  };
  auto stats = impl_->baselineOptimizer.runMultigrid(in, impl_->extinctionSettings, callback,
                                                     abandon ? watch : std::function<bool()>{});
  if (abandoned || !impl_->baselineOptimizer.extinction()) {
    impl_->resetBaseline();  // a part-way run is no baseline
    return stats;
  }
  impl_->baselineKey = key;
  ++impl_->baselineRevision;
  return stats;
}

const Field3D* Engine::baselineExtinction() const {
  return impl_->baselineCurrent() ? impl_->baselineOptimizer.extinction() : nullptr;
}
const Field3D* Engine::baselineImportanceBehind() const {
  return impl_->baselineCurrent() ? impl_->baselineOptimizer.importanceBehind() : nullptr;
}

void Engine::setFrozen(bool frozen) {
  impl_->frozen = frozen;
}
bool Engine::frozen() const {
  return impl_->frozen;
}

void Engine::resetOptimization() {
  impl_->optimizer.reset();
  impl_->resetBaseline();
  impl_->lightDirty = true;
  ++impl_->sceneRevision;
}

bool Engine::hasOptimizedExtinction() const {
  return impl_->optimizer.extinction() != nullptr;
}
const Field3D* Engine::optimizedExtinction() const {
  return impl_->optimizer.extinction();
}

void Engine::setRenderOptimized(bool useOptimized) {
  if (impl_->renderOptimized != useOptimized) {
    impl_->lightDirty = true;
    ++impl_->sceneRevision;
  }
  impl_->renderOptimized = useOptimized;
}
bool Engine::renderOptimized() const {
  return impl_->renderOptimized;
}

}  // namespace visopt
