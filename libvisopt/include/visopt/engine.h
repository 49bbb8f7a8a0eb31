// The Engine: the one facade the workstation, the CLI and the tests use. It owns the scene's
// fields and the order of the stages; a user of the library never touches a kernel.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "visopt/bit_mask.h"
#include "visopt/camera.h"
#include "visopt/clearview.h"
#include "visopt/context_surface.h"
#include "visopt/exec.h"
#include "visopt/image.h"
#include "visopt/importance_kind.h"
#include "visopt/level_set.h"
#include "visopt/memory_ledger.h"
#include "visopt/optimization.h"
#include "visopt/precision.h"
#include "visopt/progress.h"
#include "visopt/render_settings.h"
#include "visopt/scenes.h"
#include "visopt/transfer_function.h"
#include "visopt/volume.h"

namespace visopt {

class Engine {
 public:
  explicit Engine(Precision precision = Precision::FP32);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  Precision precision() const;

  // Scene input. Loading replaces the volume and frames the camera and light on it.
  void loadVolume(const std::string& path, const ProgressCallback& progress = {});
  // Loads a built-in scene with its transfer function, view, light and importance; with
  // `contextSurfaces` also its context surfaces and the transfer function meant for them.
  void loadBuiltinScene(const std::string& name, int resolution = 128, bool contextSurfaces = true);
  void setVolume(Volume volume);
  bool hasVolume() const;
  const Volume& volume() const;

  void setTransferFunction(TransferFunction tf);
  const TransferFunction& transferFunction() const;

  void setCamera(const Camera& camera);
  const Camera& camera() const;
  // Orbit around the volume centre; distance in bounding-sphere radii.
  void orbitCamera(float azimuthDeg, float elevationDeg, float distanceInRadii);
  void setLight(const PointLight& light);
  const PointLight& light() const;

  // ---- importance g(x) in [0, 1] (Himmler & Günther 2026, §III-A) ----
  // A piecewise-linear curve over data values: points (value, g), g in [0, 1].
  void setImportanceCurve(const std::vector<glm::dvec2>& points,
                          const std::string& origin = "importance curve");
  // A JSON curve file ({"points": [[value, g], ...]} or a visopt transfer function whose opacity
  // is read as g) or a volume file on the same grid with values in [0, 1].
  void loadImportance(const std::string& path);
  // ClearView's hotspot as the importance (beyond both papers): g = 1 within radius / 2 of
  // `centre` (world units), falling smoothly (C1) to 0 at `radius`, so that the optimisation
  // opens the context where the user points. Usage error for a non-finite centre or a radius
  // that is not positive and finite.
  void setImportanceHotspot(glm::vec3 centre, float radius);
  bool hasImportance() const;
  const Field3D* importance() const;
  // Where the importance came from, so a session can rebuild it.
  struct ImportanceSource {
    using Kind = ImportanceKind;
    Kind kind = Kind::None;
    std::vector<glm::dvec2> curve;  // Kind::Curve: (value, g) points in data units
    std::string path;               // Kind::Volume: the file
    glm::vec3 hotspotCentre{0.f};   // Kind::Hotspot: world units
    float hotspotRadius = 0.f;      // Kind::Hotspot: world units
  };
  const ImportanceSource& importanceSource() const;

  // ---- context surfaces (Himmler & Günther 2026, §III) ----
  // Builds the base SDF phi0 on the volume grid; returns the surface's index. Errors: Usage for a
  // malformed source, BadInput for unreadable files or meshes unfit for a filled SDF.
  int addContextSurface(const ContextSurfaceSpec& spec, const ProgressCallback& progress = {});
  // A surface given directly as its base SDF on the volume grid (spec.source is descriptive).
  int addContextSurface(const ContextSurfaceSpec& spec, const Field3D& baseSdf);
  void clearContextSurfaces();
  // Removes one surface; those after it move down one index. Like adding one, this resets the
  // optimisation. Usage error for an index out of range.
  void removeContextSurface(int index);
  const std::vector<ContextSurfaceSpec>& contextSurfaces() const;
  void setContextSurfaceVisible(int index, bool visible);
  // Linear RGB albedo, each component finite and >= 0 (Usage error otherwise).
  void setContextSurfaceColor(int index, glm::vec3 rgb);
  // phi: the optimised SDF when there is one, else the base SDF; phi0: the base SDF.
  const Field3D* contextSurfacePhi(int index) const;
  const Field3D* contextSurfaceBase(int index) const;
  void setLevelSetSettings(const LevelSetSettings& settings);
  const LevelSetSettings& levelSetSettings() const;
  // World-space mask (R5): where set, surfaces keep their base shape. Held as bits (one per
  // voxel, "world-mask" in the ledger) and absent when unused. A volume file on the data's grid
  // (non-zero = masked), a bit mask whose dims are the volume grid's (Usage error otherwise), or
  // a field on that grid (> 0.5 = masked); clearWorldMask() removes it.
  void loadWorldMask(const std::string& path);
  void setWorldMask(BitMask mask);
  void setWorldMask(const Field3D& mask);
  void clearWorldMask();
  const BitMask* worldMask() const;
  void setLens(const ImportanceLens& lens);
  const ImportanceLens& lens() const;
  // Screen-space windowing mask (Fig. 8): weights in [0, 1] over a width x height raster that
  // covers the image (row 0 at the top), multiplying the importance along the view rays.
  void setScreenMask(const std::vector<float>& weights, int width, int height);
  void clearScreenMask();
  // ghat (Eq. 19) of the last optimisation iteration, when there are surfaces.
  const Field3D* importanceBehind() const;

  // ---- extinction optimisation (Himmler & Günther 2026, §II-C, Eqs. 10-14) ----
  void setExtinctionSettings(const ExtinctionSettings& settings);
  const ExtinctionSettings& extinctionSettings() const;
  // The frustum grids follow this image size (set it to the render size).
  void setViewportSize(int width, int height);
  glm::ivec2 viewportSize() const;
  // Coarse to fine from mu_bar. The callback sees every iteration; returning false stops.
  // `abandon` (optional) is polled between the stages of every iteration, for an interface that
  // must answer a newer camera or edit at once: when it returns true before the iteration's
  // extinction step, that iteration is abandoned and changes nothing (mu, the surfaces and the
  // optimiser state stay bit for bit), and the call returns the iterations done before it; when
  // it returns true during the surfaces' level-set substeps, they stop at the next chunk (the
  // iteration ends with fewer substeps, a consistent state) and the call returns after it.
  std::vector<IterationStats> optimize(
      const std::function<bool(const IterationStats&)>& callback = {},
      const std::function<bool()>& abandon = {});
  // Continues at the finest level from the current mu, for the current camera and light (warm
  // start: what the workstation runs while the user navigates). Does nothing while frozen.
  // `abandon` as for optimize().
  std::vector<IterationStats> continueOptimization(
      int iterations, const std::function<bool(const IterationStats&)>& callback = {},
      const std::function<bool()>& abandon = {});
  // While the camera moves (Himmler & Günther 2026, §III-F: the optimisation adjusts to new
  // viewpoints during navigation): iterations on the coarsest multigrid level
  // (ExtinctionSettings::levels) for the current camera, their change to mu and the surfaces
  // prolonged onto the finest level, at a small fraction of a finest iteration's cost; the
  // finest level then refines with continueOptimization() once the camera rests. Stats carry
  // level 0. Does nothing while frozen. `abandon` as for optimize(): an abandoned iteration
  // changes nothing.
  std::vector<IterationStats> followCamera(
      int iterations, const std::function<bool(const IterationStats&)>& callback = {},
      const std::function<bool()>& abandon = {});
  // A frozen result keeps its mu when the camera moves (Himmler & Günther 2026, §III-F, Fig. 7).
  void setFrozen(bool frozen);
  bool frozen() const;
  void resetOptimization();
  bool hasOptimizedExtinction() const;
  const Field3D* optimizedExtinction() const;
  // The Fig. 10 baselines' volume (Himmler & Günther 2026, §IV-A: cut-away and transparency
  // modulation "both utilize the extinction optimization of [9] for the volume"): the extinction
  // optimised coarse to fine from mu_bar with the context surfaces held at phi0 and taking no
  // part in the visibility (the surfaces are cut or faded by ghat instead), and that run's ghat
  // (Eq. 19). Computed for the current camera, light, viewport, importance, transfer function
  // and extinction settings; kept while they stay, so a call with nothing changed returns {}
  // at once. render() of either baseline calls it (with no callback) when it is not current.
  // Runs while frozen too (freezing concerns ours). `callback` and `abandon` as for optimize():
  // an abandoned run leaves no baseline, and the next call starts again.
  std::vector<IterationStats> optimizeBaseline(
      const std::function<bool(const IterationStats&)>& callback = {},
      const std::function<bool()>& abandon = {});
  // The baselines' optimised extinction and ghat, when current; null otherwise.
  const Field3D* baselineExtinction() const;
  const Field3D* baselineImportanceBehind() const;

  // Render with the optimised mu (default when there is one) or with the transfer function's
  // mu_bar (the baselines then draw mu_bar too).
  void setRenderOptimized(bool useOptimized);
  bool renderOptimized() const;

  // Renders the current scene. T_L is recomputed only when the light, the transfer function,
  // the volume or the light grid size changed since the last render, or the optimisation
  // changed mu: a preview (settings.preview) then reuses the last full frame's T_L and drawn
  // extinction change, so that it answers a moving camera at once; the next full frame
  // recomputes them.
  // `abandon` (optional) is polled between bands of the image: when it returns true the render
  // stops and returns an empty (0 x 0) image, for an interface whose camera moved meanwhile.
  Image render(const RenderSettings& settings, RenderStats* stats = nullptr,
               const std::function<bool()>& abandon = {});

  // ---- ClearView (Krüger, Schneider, Westermann 2006; visopt/clearview.h) ----
  // Renders the context-preserving hotspot for the current camera. The layers are extracted
  // again only when the camera, the image size, the layers' sources, the volume, the transfer
  // function or the context surfaces changed since the last call; otherwise only the
  // compositing runs (stats->extracted says which). Usage error for settings that fail
  // checkClearViewSettings or name a context surface or importance the scene lacks.
  Image renderClearView(const ClearViewSettings& settings, ClearViewStats* stats = nullptr);
  // The same into `image`, whose pixels are reused when it already has the size: an interactive
  // caller keeps its frame, since a new 800x600 image costs page faults worth about as much as
  // the compositing itself (docs/clearview.md).
  void renderClearView(const ClearViewSettings& settings, Image& image,
                       ClearViewStats* stats = nullptr);

  const MemoryLedger& ledger() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace visopt
