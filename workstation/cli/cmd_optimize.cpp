// visopt optimize: the extinction optimisation of Himmler & Günther 2026, §II-C on a volume or
// built-in scene, with per-iteration statistics, before/after images and an optional second
// viewpoint for the frozen result.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "cli_common.h"
#include "commands.h"
#include "visopt/error.h"

namespace visopt::cli {

namespace {

std::atomic<bool> interrupted{false};
void onInterrupt(int) {
  interrupted = true;
}

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

nlohmann::json statsJson(const IterationStats& s) {
  return {{"level", s.level},
          {"iteration", s.iteration},
          {"energy", s.energy()},
          {"energy_rho", s.energyRho},
          {"energy_q", s.energyQ},
          {"energy_r", s.energyR},
          {"visibility_view", s.visibilityView},
          {"visibility_light", s.visibilityLight},
          {"visibility_view_occluders", s.visibilityViewOccluders},
          {"step_norm", s.stepNorm},
          {"grid_updates_ms", s.gridUpdatesMs},
          {"extinction_step_ms", s.extinctionStepMs},
          {"sdf_step_ms", s.sdfStepMs},
          {"redistance_ms", s.redistanceMs},
          {"redistance_iterations", s.redistanceIterations},
          {"redistance_calls", s.redistanceCalls},
          {"redistance_passes", s.redistancePasses},
          {"band_voxels", s.bandVoxels},
          {"band_work_voxels", s.bandWorkVoxels},
          {"redistance_residual", s.redistanceResidual},
          {"level_set_time_step", s.levelSetTimeStep},
          {"level_set_substeps", s.levelSetSubsteps},
          {"level_set_motion_voxels", s.levelSetMotionVoxels},
          {"level_set_crossed_voxels", s.levelSetCrossedVoxels},
          {"max_deviation_voxels", s.maxDeviationVoxels},
          {"mean_deviation_voxels", s.meanDeviationVoxels}};
}

std::string beforePath(const std::string& out) {
  std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + "-before" + p.extension().string())).string();
}

}  // namespace

Runner addOptimizeCommand(CLI::App& app) {
  // The library's defaults, which the help shows (main.cpp: always_capture_default), so that
  // the two cannot drift apart.
  static const ExtinctionSettings kExtinction{};
  static const LevelSetSettings kLevelSet{};
  struct Options {
    std::string volume, scene, tf, importance, camera, light, viewFrom,
        size = "512x512", precision = "fp32", optimizer = "ademamix", out, worldMask, lens,
        deviationColormap = "viridis";
    std::vector<std::string> contexts;
    float shell = 0.f, lambda = kLevelSet.lambda;
    int redistIterations = kLevelSet.redistanceIterations;
    float reach = kLevelSet.reach;
    float band = kLevelSet.band;
    std::string integrator = kLevelSet.semiImplicit ? "semi-implicit" : "explicit";
    bool filled = false, deviationView = false, noAo = false;
    int resolution = 128, levels = kExtinction.levels,
        iterations = kExtinction.maxIterationsPerLevel;
    float rho = kExtinction.rho, q = kExtinction.q, r = kExtinction.r,
          lr = kExtinction.learningRate, muMax = kExtinction.muMax,
          frustumScale = kExtinction.frustumScale, tolerance = kExtinction.tolerance;
    bool json = false, quiet = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option("--volume", o->volume, "Volume file or DICOM folder");
  app.add_option("--scene", o->scene, "Built-in scene, builtin:NAME (carries its own importance)");
  app.add_option("--resolution", o->resolution, "Built-in scene resolution (longest axis, voxels)");
  app.add_option("--tf", o->tf, "Transfer function: JSON file (visopt or ParaView) or preset:NAME")
      ->default_str("the scene's own; preset:generic for a volume");
  app.add_option("--importance", o->importance,
                 "Importance g in [0,1]: preset:NAME (the importance a transfer-function preset "
                 "is made for, the default with --tf preset:ct-skin-bone or preset:ct-bone: "
                 "bone), hotspot:X,Y,Z,R (ClearView's hotspot as the importance: a smooth ball of "
                 "radius R about the world point X,Y,Z, 1 within R/2), a curve JSON "
                 "{\"points\":[[value,g],...]} or a volume file on the same grid");
  app.add_option("--camera", o->camera, "Orbit AZ,EL,DIST (degrees, degrees, bounding radii)")
      ->default_str("the scene's view");
  app.add_option("--light", o->light, "Point light on an orbit AZ,EL,DIST")
      ->default_str("key light of the view");
  app.add_option("--rho", o->rho,
                 "Weight of staying close to the transfer function (<0: 1/mu_max)");
  app.add_option("--q", o->q, "Weight of seeing the important parts from the camera");
  app.add_option(
      "--r", o->r,
      "Weight of lighting the important parts (0: no light term, and no light grids without "
      "context surfaces)");
  app.add_option("--optimizer", o->optimizer, "ademamix or adam");
  app.add_option("--lr", o->lr, "Learning rate in units of mu_max per step");
  app.add_option("--mu-max", o->muMax,
                 "Upper bound of the extinction (0: the transfer function's)");
  app.add_option("--levels", o->levels, "Coarse-to-fine multigrid levels");
  app.add_option("--iterations", o->iterations, "Iteration cap per level");
  app.add_option("--tolerance", o->tolerance, "Relative energy change that ends a level");
  app.add_option("--frustum-scale", o->frustumScale, "Frustum rays per image pixel (per side)");
  app.add_option("--context", o->contexts,
                 "Context surface (repeatable): iso:VALUE[:inside-high|inside-low], mesh:FILE "
                 "or vdb:FILE")
      ->default_str("");
  auto* shellOpt = app.add_option("--shell", o->shell,
                                  "Context surfaces as thin shells reaching D (world units) to "
                                  "either side of the surface (Eq. 26)")
                       ->default_str("one voxel for iso:, filled for mesh: and vdb:");
  app.add_flag("--filled", o->filled,
               "Context surfaces filled (default for mesh: and vdb:; an isosurface of a scan is "
               "a thin shell unless this is given)")
      ->excludes(shellOpt);
  app.add_option("--lambda", o->lambda,
                 "How strongly surfaces return to their base shape (Eq. 23)");
  app.add_option("--level-set-reach", o->reach,
                 "How far surfaces can travel per run, in bounding radii (0: a fixed number of "
                 "level-set substeps per iteration)");
  app.add_option("--level-set-band", o->band,
                 "Half-width in voxels of the narrow band the level-set step and redistancing run "
                 "in (0: the whole grid, the dense reference path)");
  app.add_option("--level-set-integrator", o->integrator,
                 "How each iteration integrates Eq. 23: semi-implicit (one stable step per half "
                 "voxel of motion) or explicit (Euler substeps, the paper's Eq. 25)")
      ->check(CLI::IsMember({"semi-implicit", "explicit"}));
  app.add_option("--redist-iterations", o->redistIterations,
                 "Redistancing iterations at most (Eq. 18)");
  app.add_option("--world-mask", o->worldMask,
                 "Volume file on the data grid: non-zero voxels keep their context surface");
  app.add_option("--lens", o->lens,
                 "Importance lens X,Y,R[,STRENGTH] in output-image pixels (strength multiplies g)");
  app.add_flag("--deviation-view", o->deviationView,
               "Colour surfaces by how far they moved from their base (|phi0| in voxels)");
  app.add_option("--deviation-colormap", o->deviationColormap,
                 "Colormap of the deviation view: viridis, magma, inferno, coolwarm or grey");
  app.add_flag("--no-ambient-occlusion", o->noAo,
               "Render the images with the ambient light unoccluded (volume samples and surfaces)");
  app.add_option("--precision", o->precision, "Field storage: fp32 or fp16");
  app.add_option("--size", o->size, "Image size WxH (the frustum grids follow it)");
  app.add_option("--out", o->out,
                 "Render the optimised view here (and the unoptimised one "
                 "next to it as NAME-before.png)");
  app.add_option("--view-from", o->viewFrom,
                 "Also render the frozen result from this orbit AZ,EL,DIST (NAME-view.png)");
  app.add_flag("--json", o->json, "Print per-iteration statistics, stage times and memory as JSON");
  app.add_flag("--quiet", o->quiet, "No progress lines on stderr");

  return [o, &app]() {
    // Options without a library default of their own apply only when given (any value: a NaN
    // or a negative one is refused by the library, not taken for "not given").
    auto given = [&app](const char* name) { return app.get_option(name)->count() > 0; };
    resetStageTimings();
    const auto t0 = std::chrono::steady_clock::now();
    const Colormap deviationColormap = parseColormap(o->deviationColormap);
    Engine engine(parsePrecision(o->precision));
    ExtinctionSettings s;
    s.rho = o->rho;
    s.q = o->q;
    s.r = o->r;
    s.optimizer = parseOptimizerKind(o->optimizer);
    s.learningRate = o->lr;
    s.muMax = o->muMax;
    s.levels = o->levels;
    s.maxIterationsPerLevel = o->iterations;
    s.tolerance = o->tolerance;
    s.frustumScale = o->frustumScale;
    const glm::ivec2 size = parseSize(o->size);
    // Checked before anything runs: a bad output path or second view must not cost a whole
    // optimisation.
    if (!o->out.empty()) {
      checkPngOutput(o->out);
      checkPngOutput(beforePath(o->out));
    }
    glm::vec3 viewFrom(0.f);
    if (!o->viewFrom.empty()) {
      viewFrom = parseTriple(o->viewFrom, "--view-from");
      checkOrbit(viewFrom.x, viewFrom.y, viewFrom.z, "--view-from");
    }
    loadInput(engine, o->volume, o->scene, o->resolution, !o->json && !o->quiet);
    if (!o->tf.empty()) engine.setTransferFunction(loadTransferFunction(o->tf, engine.volume()));
    if (applyPresetImportance(engine, o->importance, o->scene, o->tf)) {
      // --importance preset:NAME or the --tf preset's own importance is set.
    } else if (o->importance.rfind("hotspot:", 0) == 0) {
      const std::vector<float> v = parseFloats(o->importance.substr(8), ',', "--importance");
      if (v.size() != 4)
        throw Error(ErrorKind::Usage,
                    "--importance " + o->importance + ": expected hotspot:X,Y,Z,R (world units)");
      if (!(v[3] > 0.f))
        throw Error(ErrorKind::Usage,
                    "--importance " + o->importance + ": the radius R must be positive");
      engine.setImportanceHotspot({v[0], v[1], v[2]}, v[3]);
    } else if (!o->importance.empty()) {
      engine.loadImportance(o->importance);
    }
    LevelSetSettings ls = engine.levelSetSettings();
    if (given("--lambda")) ls.lambda = o->lambda;
    if (given("--redist-iterations")) ls.redistanceIterations = o->redistIterations;
    if (given("--level-set-reach")) ls.reach = o->reach;
    if (given("--level-set-band")) ls.band = o->band;
    if (given("--level-set-integrator")) ls.semiImplicit = o->integrator == "semi-implicit";
    engine.setLevelSetSettings(ls);
    if ((given("--shell") || o->filled) && !engine.contextSurfaces().empty()) {
      // --shell and --filled apply to a scene's own context surfaces too.
      std::vector<ContextSurfaceSpec> own = engine.contextSurfaces();
      engine.clearContextSurfaces();
      for (ContextSurfaceSpec spec : own) {
        spec.filled = o->filled;
        spec.shell = o->filled ? 0.f : o->shell;
        engine.addContextSurface(spec);
      }
    }
    for (const auto& c : o->contexts) {
      ContextSurfaceSpec spec;
      spec.source = c;
      if (o->filled) {
        spec.filled = true;
      } else if (given("--shell")) {
        spec.filled = false;
        spec.shell = o->shell;
      } else {
        spec = defaultContextSurfaceSpec(c, engine.volume().grid());
      }
      engine.addContextSurface(spec);
    }
    if (!o->worldMask.empty()) engine.loadWorldMask(o->worldMask);
    if (!o->lens.empty()) {
      std::vector<float> v;
      std::stringstream ss(o->lens);
      std::string part;
      while (std::getline(ss, part, ',')) v.push_back(parseTriple(part + ",0,0", "--lens").x);
      if (v.size() < 3 || v.size() > 4 || !(v[2] > 0.f))
        throw Error(ErrorKind::Usage, "--lens: expected X,Y,R[,STRENGTH] with R > 0");
      ImportanceLens lens;
      lens.x = v[0] / float(size.x);
      lens.y = v[1] / float(size.y);
      lens.radius = v[2] / float(size.x);
      if (v.size() == 4) lens.strength = v[3];
      engine.setLens(lens);
    }
    if (!engine.hasImportance())
      throw Error(ErrorKind::Usage, "--importance is needed for a volume file (scenes carry one)");
    const Bounds bounds = engine.volume().grid().worldBounds();
    if (!o->camera.empty()) {
      glm::vec3 c = parseTriple(o->camera, "--camera");
      checkOrbit(c.x, c.y, c.z, "--camera");
      engine.orbitCamera(c.x, c.y, c.z);
      engine.setLight(PointLight::keyLightFor(engine.camera(), bounds));
    }
    if (!o->light.empty()) {
      glm::vec3 l = parseTriple(o->light, "--light");
      checkOrbit(l.x, l.y, l.z, "--light");
      PointLight light = engine.light();
      light.position = Camera::orbitBounds(bounds, l.x, l.y, l.z).eye;
      engine.setLight(light);
    }
    engine.setExtinctionSettings(s);
    engine.setViewportSize(size.x, size.y);
    const double setupMs = msSince(t0);

    RenderSettings rs;
    rs.width = size.x;
    rs.height = size.y;
    rs.deviationView = o->deviationView;
    rs.deviationColormap = deviationColormap;
    rs.ambientOcclusion = !o->noAo;
    nlohmann::json images = nlohmann::json::object();
    if (!o->out.empty()) {
      writePng(engine.render(rs), beforePath(o->out));
      images["before"] = beforePath(o->out);
    }

    interrupted = false;
    auto previous = std::signal(SIGINT, onInterrupt);
    const auto tOpt = std::chrono::steady_clock::now();
    auto stats = engine.optimize([&](const IterationStats& st) {
      if (!o->json && !o->quiet)
        std::fprintf(stderr,
                     "level %d  iteration %3d  energy %+.5e  V_view %.3f (occluders %.3f)  V_light "
                     "%.3f  step %.2e\n",
                     st.level, st.iteration, st.energy(), st.visibilityView,
                     st.visibilityViewOccluders, st.visibilityLight, st.stepNorm);
      return !interrupted.load();
    });
    const double optimizeMs = msSince(tOpt);
    std::signal(SIGINT, previous);

    double renderMs = 0.0;
    if (!o->out.empty()) {
      const auto tr = std::chrono::steady_clock::now();
      writePng(engine.render(rs), o->out);
      renderMs = msSince(tr);
      images["after"] = o->out;
      if (!o->viewFrom.empty()) {
        engine.setFrozen(true);
        engine.orbitCamera(viewFrom.x, viewFrom.y, viewFrom.z);
        std::filesystem::path p(o->out);
        const std::string viewPath =
            (p.parent_path() / (p.stem().string() + "-view" + p.extension().string())).string();
        writePng(engine.render(rs), viewPath);
        images["view_from"] = viewPath;
      }
    }

    if (o->json) {
      nlohmann::json iterations = nlohmann::json::array();
      for (const auto& st : stats) iterations.push_back(statsJson(st));
      nlohmann::json j = {{"command", "optimize"},
                          {"backend", backendDescription()},
                          {"input", engine.volume().sourcePath},
                          {"dims",
                           {engine.volume().grid().dims.x, engine.volume().grid().dims.y,
                            engine.volume().grid().dims.z}},
                          {"precision", o->precision},
                          {"settings",
                           {{"rho", s.rho},
                            {"q", s.q},
                            {"r", s.r},
                            {"optimizer", toString(s.optimizer)},
                            {"learning_rate", s.learningRate},
                            {"levels", s.levels},
                            {"iterations_per_level", s.maxIterationsPerLevel},
                            {"tolerance", s.tolerance},
                            {"frustum_scale", s.frustumScale}}},
                          {"interrupted", interrupted.load()},
                          {"iterations", iterations},
                          {"final", stats.empty() ? nlohmann::json() : statsJson(stats.back())},
                          {"initial", stats.empty() ? nlohmann::json() : statsJson(stats.front())},
                          {"times_ms",
                           {{"setup", setupMs},
                            {"optimize", optimizeMs},
                            {"render", renderMs},
                            {"total", msSince(t0)}}},
                          {"stages", stageTimingsJson()},
                          {"images", images},
                          {"memory", ledgerJson(engine.ledger())}};
      std::printf("%s\n", j.dump(2).c_str());
    } else if (!stats.empty()) {
      const auto& f = stats.back();
      std::printf("optimised in %.0f ms: energy %+.5e, visibility %.3f -> %.3f%s\n", optimizeMs,
                  f.energy(), stats.front().visibilityView, f.visibilityView,
                  o->out.empty() ? "" : (", wrote " + o->out).c_str());
    }
    return interrupted.load() ? kFailure : kOk;
  };
}

}  // namespace visopt::cli
