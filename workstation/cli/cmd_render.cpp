#include <chrono>
#include <cstdio>
#include <optional>

#include "clearview_spec.h"
#include "cli_common.h"
#include "commands.h"
#include "visopt/error.h"
#include "visopt/session.h"

namespace visopt::cli {

namespace {
double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

Runner addRenderCommand(CLI::App& app) {
  struct Options {
    std::string volume, scene, session, tf, size = "512x512", camera, precision = "fp32", out;
    std::string deviationColormap = "viridis";
    std::string clearview;
    int resolution = 128;
    float step = RenderSettings{}.stepFactor;  // the library's default
    float aoRadius = RenderSettings{}.ambientOcclusionRadius;
    bool deviationView = false, preview = false, json = false, noJitter = false, noAo = false;
  };
  auto o = std::make_shared<Options>();
  CLI::Option* volumeOption = app.add_option(
      "--volume", o->volume, "Volume file (NIfTI, MetaImage, VTK, NRRD, raw+json) or DICOM folder");
  CLI::Option* sceneOption =
      app.add_option("--scene", o->scene, "Built-in scene, builtin:NAME (see `visopt scenes`)");
  app.add_option("--session", o->session,
                 "Session file: supplies data, transfer function, view and render settings "
                 "(options given explicitly override them)")
      ->excludes(volumeOption)
      ->excludes(sceneOption);
  app.add_option("--resolution", o->resolution, "Built-in scene resolution (longest axis, voxels)");
  app.add_option("--tf", o->tf,
                 "Transfer function: a JSON file (visopt or ParaView) or preset:NAME")
      ->default_str("the session's or scene's own; preset:generic for a volume");
  app.add_option("--size", o->size, "Image size WxH");
  app.add_option("--camera", o->camera,
                 "Orbit AZ,EL,DIST: degrees about +z, degrees above the xy-plane, distance in "
                 "bounding-sphere radii")
      ->default_str("the session's or scene's view");
  app.add_option("--precision", o->precision, "Field storage: fp32 or fp16");
  app.add_option("--step", o->step, "Ray-march step in units of the smallest voxel spacing");
  app.add_flag("--deviation-view", o->deviationView,
               "Colour context surfaces by |phi0| at the hit, in voxels (Fig. 5)");
  app.add_option("--deviation-colormap", o->deviationColormap,
                 "Colormap of the deviation view: viridis, magma, inferno, coolwarm or grey");
  app.add_flag("--preview", o->preview, "Low-resolution preview (1/4 size, double step)");
  app.add_flag("--no-jitter", o->noJitter, "Sample at segment midpoints (shows wood grain)");
  app.add_flag("--no-ambient-occlusion", o->noAo,
               "Leave the ambient light unoccluded (volume samples and surfaces)");
  app.add_option("--ambient-occlusion-radius", o->aoRadius,
                 "Ambient occlusion radius in voxels (smallest spacing)");
  app.add_option("--out", o->out, "Output PNG")->required();
  app.add_flag("--json", o->json, "Print per-stage times and the memory ledger as JSON");
  app.add_option("--clearview", o->clearview,
                 "ClearView hotspot render (Krüger et al. 2006): comma-separated key=value, see "
                 "docs/clearview.md");

  return [o, &app]() {
    resetStageTimings();
    const auto t0 = std::chrono::steady_clock::now();
    auto given = [&app](const char* name) { return app.get_option(name)->count() > 0; };
    const bool clearview = given("--clearview");
    if (clearview) {
      // ClearView has its own layers and shaders: the ray caster's options would do nothing.
      for (const char* other :
           {"--deviation-view", "--preview", "--deviation-colormap", "--step", "--no-jitter",
            "--no-ambient-occlusion", "--ambient-occlusion-radius"})
        if (given(other))
          throw Error(ErrorKind::Usage, std::string("--clearview and ") + other +
                                            " cannot be combined (the ClearView render has "
                                            "its own layers and shaders)");
    }
    checkPngOutput(o->out);  // before any loading: a device or folder is refused up front
    // A session supplies the scene and the render settings; explicit options override them.
    std::optional<Session> session;
    if (!o->session.empty()) session = loadSession(o->session);
    const Precision precision =
        session && !given("--precision") ? session->precision : parsePrecision(o->precision);
    Engine engine(precision);
    nlohmann::json sessionData = nlohmann::json::array();
    if (session) {
      const SessionLoadReport report = applySession(engine, *session, o->session);
      bool missing = !report.sceneLoaded;
      for (const SessionDataReport& d : report.data) {
        if (d.status != DataStatus::Ok)
          std::fprintf(stderr, "visopt: %s: %s\n", o->session.c_str(), describe(d).c_str());
        missing |= d.status == DataStatus::Missing || d.status == DataStatus::Unreadable;
        sessionData.push_back(
            {{"role", d.role}, {"status", toString(d.status)}, {"resolved", d.resolvedPath}});
      }
      for (const std::string& w : report.warnings)
        std::fprintf(stderr, "visopt: %s: %s\n", o->session.c_str(), w.c_str());
      if (missing)
        throw Error(ErrorKind::BadInput,
                    o->session + ": the session's data cannot be found or read (see above)");
    } else {
      loadInput(engine, o->volume, o->scene, o->resolution, !o->json);
    }
    const double loadMs = msSince(t0);
    if (!o->tf.empty()) engine.setTransferFunction(loadTransferFunction(o->tf, engine.volume()));
    if (!o->camera.empty()) {
      glm::vec3 c = parseTriple(o->camera, "--camera");
      checkOrbit(c.x, c.y, c.z, "--camera");
      engine.orbitCamera(c.x, c.y, c.z);
      engine.setLight(
          PointLight::keyLightFor(engine.camera(), engine.volume().grid().worldBounds()));
    }
    RenderSettings settings = session ? session->render : RenderSettings{};
    if (!session || given("--size")) {
      glm::ivec2 size = parseSize(o->size);
      settings.width = size.x;
      settings.height = size.y;
    }
    if (!session || given("--step")) settings.stepFactor = o->step;
    if (!session || o->preview) settings.preview = o->preview;
    if (!session || o->deviationView) settings.deviationView = o->deviationView;
    if (!session || given("--deviation-colormap"))
      settings.deviationColormap = parseColormap(o->deviationColormap);
    if (!session || o->noJitter) settings.jitter = !o->noJitter;
    if (!session || o->noAo) settings.ambientOcclusion = !o->noAo;
    if (!session || given("--ambient-occlusion-radius"))
      settings.ambientOcclusionRadius = o->aoRadius;
    if (clearview) {
      // After the scene, the camera and the size: the layers' defaults follow the scene.
      // A session's hotspot settings (the workstation's Hotspot panel) are the defaults here.
      const ClearViewSettings* saved =
          session && session->clearView ? &*session->clearView : nullptr;
      const ClearViewSettings cv =
          parseClearViewSpec(engine, o->clearview, {settings.width, settings.height}, saved);
      ClearViewStats cvStats;
      Image image;
      try {
        image = engine.renderClearView(cv, &cvStats);
      } catch (const Error& e) {
        // The Engine checks the layers against the scene: a usage error is this option's.
        if (e.kind() != ErrorKind::Usage) throw;
        throw asClearViewOptionError(e);
      }
      const auto tw = std::chrono::steady_clock::now();
      writePng(image, o->out);
      const double writeMs = msSince(tw);
      const double renderMs = cvStats.extractMs + cvStats.compositeMs;
      if (o->json) {
        const nlohmann::json focusPoint =
            cvStats.hasFocusPoint
                ? nlohmann::json::array(
                      {cvStats.focusPoint.x, cvStats.focusPoint.y, cvStats.focusPoint.z})
                : nlohmann::json(nullptr);
        nlohmann::json j = {{"command", "render"},
                            {"backend", backendDescription()},
                            {"input", engine.volume().sourcePath},
                            {"precision", toString(precision)},
                            {"out", o->out},
                            {"image",
                             {{"width", cv.width},
                              {"height", cv.height},
                              {"rendered_width", image.width},
                              {"rendered_height", image.height}}},
                            {"times_ms",
                             {{"load", loadMs},
                              {"render", renderMs},
                              {"write_png", writeMs},
                              {"total", msSince(t0)}}},
                            {"clearview",
                             {{"context", describeClearViewLayer(cv.context)},
                              {"focus", describeClearViewLayer(cv.focus)},
                              {"measure", toString(cv.measure)},
                              {"extract_ms", cvStats.extractMs},
                              {"composite_ms", cvStats.compositeMs},
                              {"context_pixels", cvStats.contextPixels},
                              {"focus_pixels", cvStats.focusPixels},
                              {"focus_point", focusPoint}}},
                            {"clearview_extract_ms", cvStats.extractMs},
                            {"clearview_composite_ms", cvStats.compositeMs},
                            {"stages", stageTimingsJson()},
                            {"memory", ledgerJson(engine.ledger())}};
        // The further layers, when there are any, in the order SPEC gives them.
        nlohmann::json deeper = nlohmann::json::array(), more = nlohmann::json::array();
        for (size_t i = 0; i < cv.deeperContexts.size(); ++i)
          deeper.push_back(
              {{"layer", describeClearViewLayer(cv.deeperContexts[i])},
               {"pixels", i < cvStats.deeperContextPixels.size() ? cvStats.deeperContextPixels[i]
                                                                 : int64_t(0)}});
        for (const ClearViewLayer& l : cv.moreFoci) more.push_back(describeClearViewLayer(l));
        if (!deeper.empty()) j["clearview"]["deeper_contexts"] = deeper;
        if (!more.empty()) j["clearview"]["more_foci"] = more;
        if (session) j["session"] = {{"path", o->session}, {"data", sessionData}};
        std::printf("%s\n", j.dump(2).c_str());
      } else {
        std::printf("wrote %s (%dx%d ClearView, %.0f ms extract, %.1f ms composite, %s)\n",
                    o->out.c_str(), cv.width, cv.height, cvStats.extractMs, cvStats.compositeMs,
                    backendDescription().c_str());
      }
      return kOk;
    }

    RenderStats stats;
    Image image = engine.render(settings, &stats);
    const auto tw = std::chrono::steady_clock::now();
    writePng(image, o->out);
    const double writeMs = msSince(tw);

    if (o->json) {
      nlohmann::json j = {
          {"command", "render"},
          {"backend", backendDescription()},
          {"input", engine.volume().sourcePath},
          {"precision", toString(precision)},
          {"out", o->out},
          {"image",
           {{"width", settings.width},
            {"height", settings.height},
            {"rendered_width", stats.width},
            {"rendered_height", stats.height}}},
          {"times_ms",
           {{"load", loadMs},
            {"light_transmittance", stats.lightMilliseconds},
            {"volume_occlusion", stats.occlusionMilliseconds},
            {"render", stats.milliseconds},
            {"write_png", writeMs},
            {"total", msSince(t0)}}},
          {"samples", stats.samples},
          {"samples_per_second",
           stats.milliseconds > 0 ? double(stats.samples) / (stats.milliseconds * 1e-3) : 0.0},
          {"stages", stageTimingsJson()},
          {"memory", ledgerJson(engine.ledger())}};
      if (session) j["session"] = {{"path", o->session}, {"data", sessionData}};
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("wrote %s (%dx%d, %.0f ms render, %s)\n", o->out.c_str(), settings.width,
                  settings.height, stats.milliseconds, backendDescription().c_str());
    }
    return kOk;
  };
}

}  // namespace visopt::cli
