// visopt compare: the four methods of Himmler & Günther 2026, Fig. 10 side by side for one scene
// and camera — maximum importance projection, cut-away, transparency modulation, and ours — and
// ClearView's hotspot (Krüger, Schneider, Westermann 2006) as a fifth.
#include <chrono>
#include <cstdio>

#include "clearview_spec.h"
#include "cli_common.h"
#include "commands.h"
#include "visopt/error.h"

namespace visopt::cli {

Runner addCompareCommand(CLI::App& app) {
  struct Options {
    std::string volume, scene, tf, importance, camera, size = "384x384", out, clearview;
    std::vector<std::string> contexts;
    int resolution = 128, iterations = 60, levels = 3;
    float cut = 0.3f;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option("--volume", o->volume, "Volume file or DICOM folder");
  app.add_option("--scene", o->scene, "Built-in scene, builtin:NAME");
  app.add_option("--resolution", o->resolution, "Built-in scene resolution");
  app.add_option("--tf", o->tf, "Transfer function: JSON file or preset:NAME")
      ->default_str("the scene's own; preset:generic for a volume");
  app.add_option("--importance", o->importance,
                 "Importance: curve JSON, volume, or preset:NAME (the CT presets' bone; without it "
                 "the --tf preset's own)");
  app.add_option("--context", o->contexts, "Context surface (repeatable), as for optimize")
      ->default_str("");
  app.add_option("--camera", o->camera, "Orbit AZ,EL,DIST")->default_str("the scene's view");
  app.add_option("--size", o->size, "Size WxH of each of the four images");
  app.add_option("--iterations", o->iterations,
                 "Iteration cap per level, for ours and for the baselines' volume");
  app.add_option("--levels", o->levels, "Multigrid levels, for ours and for the baselines' volume");
  app.add_option("--cut-threshold", o->cut, "ghat above which the cut-away removes geometry");
  app.add_option("--clearview", o->clearview,
                 "The fifth panel's ClearView settings, as for render --clearview "
                 "(docs/clearview.md)")
      ->default_str("the scene's context surface 0 over its importance");
  app.add_option("--out", o->out, "Output PNG (five panels, left to right)")->required();
  app.add_flag("--json", o->json, "Print the panel order and times as JSON");
  return [o]() {
    const auto t0 = std::chrono::steady_clock::now();
    Engine engine;
    loadInput(engine, o->volume, o->scene, o->resolution, !o->json);
    if (!o->tf.empty()) engine.setTransferFunction(loadTransferFunction(o->tf, engine.volume()));
    if (!applyPresetImportance(engine, o->importance, o->scene, o->tf) && !o->importance.empty())
      engine.loadImportance(o->importance);
    if (!engine.hasImportance())
      throw Error(ErrorKind::Usage, "--importance is needed for a volume file (scenes carry one)");
    for (const auto& c : o->contexts) {
      ContextSurfaceSpec spec;
      spec.source = c;
      engine.addContextSurface(spec);
    }
    if (!o->camera.empty()) {
      glm::vec3 c = parseTriple(o->camera, "--camera");
      checkOrbit(c.x, c.y, c.z, "--camera");
      engine.orbitCamera(c.x, c.y, c.z);
      engine.setLight(
          PointLight::keyLightFor(engine.camera(), engine.volume().grid().worldBounds()));
    }
    const glm::ivec2 size = parseSize(o->size);
    engine.setViewportSize(size.x, size.y);
    ExtinctionSettings s = engine.extinctionSettings();
    s.maxIterationsPerLevel = o->iterations;
    s.levels = o->levels;
    engine.setExtinctionSettings(s);
    // Before the optimisation, so that a malformed SPEC fails at once.
    const ClearViewSettings cv = parseClearViewSpec(engine, o->clearview, size);
    engine.optimize();          // ours
    engine.optimizeBaseline();  // cut-away's and transparency's volume: [9], surfaces held

    const RenderMethod methods[4] = {RenderMethod::MaxImportanceProjection, RenderMethod::CutAway,
                                     RenderMethod::TransparencyModulation, RenderMethod::Optimized};
    constexpr int kPanels = 5;
    Image panel(kPanels * size.x + (kPanels - 1) * 4, size.y);
    for (auto& px : panel.pixels) px = glm::vec3(1.f);  // white gutters
    nlohmann::json order = nlohmann::json::array();
    for (int m = 0; m < 4; ++m) {
      RenderSettings rs;
      rs.width = size.x;
      rs.height = size.y;
      rs.method = methods[m];
      rs.cutAwayThreshold = o->cut;
      const Image img = engine.render(rs);
      for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) panel.at(m * (size.x + 4) + x, y) = img.at(x, y);
      order.push_back(toString(methods[m]));
    }
    {
      // ClearView draws the base surfaces: its layers are the scene as loaded, not as optimised.
      engine.setRenderOptimized(false);
      Image img;
      try {
        img = engine.renderClearView(cv);
      } catch (const Error& e) {
        if (e.kind() != ErrorKind::Usage) throw;
        throw asClearViewOptionError(e);
      }
      engine.setRenderOptimized(true);
      for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) panel.at(4 * (size.x + 4) + x, y) = img.at(x, y);
      order.push_back("clearview");
    }
    writePng(panel, o->out);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (o->json)
      std::printf("%s\n",
                  nlohmann::json{
                      {"command", "compare"}, {"out", o->out}, {"panels", order}, {"total_ms", ms}}
                      .dump(2)
                      .c_str());
    else
      std::printf("wrote %s: %s | %s | %s | %s | clearview\n", o->out.c_str(), toString(methods[0]),
                  toString(methods[1]), toString(methods[2]), toString(methods[3]));
    return kOk;
  };
}

}  // namespace visopt::cli
