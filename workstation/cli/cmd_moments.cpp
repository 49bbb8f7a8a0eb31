// visopt moments generate | render | info: moment images (Rapp, Peters, Dachsbacher 2022). A
// moment image holds, per pixel of a fixed view, the bounded trigonometric moments of the
// density along the pixel's ray; any transfer function can then be applied without the volume.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "cli_common.h"
#include "commands.h"
#include "visopt/error.h"
#include "visopt/moment_image.h"

namespace visopt::cli {

namespace {

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

nlohmann::json describe(const MomentImage& image, const std::string& path) {
  int64_t hit = 0;
  std::vector<int64_t> histogram(size_t(image.order) + 2, 0);
  for (uint8_t c : image.counts) {
    hit += c > 0;
    ++histogram[c];
  }
  const double bytes = double(std::filesystem::file_size(path));
  return {{"file", path},
          {"size", {image.width, image.height}},
          {"order", image.order},
          {"error_threshold", image.errorThreshold},
          {"bounds_margin", image.boundsMargin},
          {"pixels_hit", hit},
          {"moments_stored", image.moments.size()},
          {"moments_per_hit_pixel", hit > 0 ? double(image.moments.size()) / double(hit) : 0.0},
          {"moments_histogram", histogram},
          {"bytes", bytes},
          {"bytes_per_pixel", bytes / double(image.pixelCount())},
          {"bytes_all_moments_fp32", double(image.pixelCount()) * double(image.order + 1) * 4.0},
          {"value_range", {image.valueMin, image.valueMax}}};
}

void printSummary(const nlohmann::json& d) {
  std::printf(
      "%s: %dx%d pixels, order %d, %lld pixels hit, %.1f moments per hit pixel, "
      "%.1f bytes per pixel (%.0f KiB; all %d moments in fp32 would be %.0f KiB)\n",
      d["file"].get<std::string>().c_str(), d["size"][0].get<int>(), d["size"][1].get<int>(),
      d["order"].get<int>(), static_cast<long long>(d["pixels_hit"].get<int64_t>()),
      d["moments_per_hit_pixel"].get<double>(), d["bytes_per_pixel"].get<double>(),
      d["bytes"].get<double>() / 1024.0, d["order"].get<int>() + 1,
      d["bytes_all_moments_fp32"].get<double>() / 1024.0);
}

// --volume / --scene / --resolution: the volume or built-in scene a subcommand reads.
struct Input {
  std::string volume, scene;
  int resolution = 128;
};

void addInputOptions(CLI::App& app, Input& in, const std::string& volumeHelp,
                     const std::string& sceneHelp) {
  CLI::Option* volume = app.add_option("--volume", in.volume, volumeHelp);
  CLI::Option* scene = app.add_option("--scene", in.scene, sceneHelp);
  volume->excludes(scene);
  app.add_option("--resolution", in.resolution, "Built-in scene resolution (longest axis)")
      ->capture_default_str();
}

}  // namespace

Runner addMomentsCommand(CLI::App& app) {
  app.require_subcommand(1);
  struct Generate {
    Input input;
    std::string camera, size = "512x512", out;
    MomentImageSettings settings;
    bool json = false;
  };
  struct Render {
    Input input;
    std::string file, tf, out, reconstruction = "mese", referenceOut;
    MomentRenderSettings settings;
    bool noPreintegration = false, uncertainty = false, json = false;
    float uncertaintyMax = 0.f;
  };
  struct Info {
    std::string file;
    bool json = false;
  };
  auto g = std::make_shared<Generate>();
  auto r = std::make_shared<Render>();
  auto i = std::make_shared<Info>();

  CLI::App* gen = app.add_subcommand("generate", "March a volume and write its moment image");
  addInputOptions(*gen, g->input, "Volume file or DICOM folder",
                  "Built-in scene, builtin:NAME (see `visopt scenes`)");
  gen->add_option("--camera", g->camera,
                  "Orbit AZ,EL,DIST: degrees about +z, degrees above the xy-plane, distance in "
                  "bounding-sphere radii")
      ->default_str("the scene's view");
  gen->add_option("--size", g->size, "Image size WxH")->capture_default_str();
  gen->add_option("--moments", g->settings.moments,
                  "Order m: moments 0..m are generated (at most 127)")
      ->capture_default_str();
  gen->add_option("--error", g->settings.errorThreshold,
                  "Per-pixel moment count: the fewest within this rRMSE of all m + 1 (0 keeps all)")
      ->capture_default_str();
  gen->add_option("--margin", g->settings.boundsMargin,
                  "Epsilon of the per-pixel bounds [min - eps, max + eps] (density units)")
      ->capture_default_str();
  gen->add_option("--step", g->settings.stepVoxels,
                  "Ray-march step in units of the smallest voxel spacing")
      ->capture_default_str();
  gen->add_option("--uncertainty", g->settings.uncertaintyQuantile,
                  "Also store per pixel this quantile of the reconstruction's error along the "
                  "ray (§4.1; a second march; 0: none), e.g. 0.95")
      ->capture_default_str();
  gen->add_option("--out", g->out, "Output .vmi file")->required();
  gen->add_flag("--json", g->json, "Print per-stage times and sizes as JSON");

  CLI::App* ren = app.add_subcommand("render", "Render a moment image with a transfer function");
  ren->add_option("file", r->file, "Moment image (.vmi)")->required();
  ren->add_option("--tf", r->tf, "Transfer function: a JSON file or preset:NAME")
      ->default_str(
          "that of --volume/--scene when given, else preset:generic over the image's "
          "value range");
  ren->add_option("--reconstruction", r->reconstruction, "mese (bounded MESE) or fourier")
      ->capture_default_str();
  ren->add_option("--step", r->settings.stepVoxels,
                  "Ray-march step in units of the smallest voxel spacing")
      ->capture_default_str();
  ren->add_flag("--no-preintegration", r->noPreintegration,
                "Sample each segment at its midpoint instead of the pre-integrated transfer "
                "function");
  ren->add_flag("--uncertainty", r->uncertainty,
                "Draw the stored error quantile (§4.1) as a magma heat map instead");
  ren->add_option("--uncertainty-max", r->uncertaintyMax,
                  "Error (normalised density) at the top of the heat map; 0: the image's largest")
      ->capture_default_str();
  ren->add_option("--out", r->out, "Output PNG")->required();
  addInputOptions(*ren, r->input, "The volume the image was made from: also render it directly",
                  "The built-in scene the image was made from");
  ren->add_option("--reference-out", r->referenceOut,
                  "PNG of the direct rendering of --volume/--scene (same view, transfer function "
                  "and step); its PSNR against the moment image's rendering is printed");
  ren->add_flag("--json", r->json, "Print per-stage times as JSON");

  CLI::App* inf = app.add_subcommand("info", "Describe a moment image");
  inf->add_option("file", i->file, "Moment image (.vmi)")->required();
  inf->add_flag("--json", i->json, "Print one JSON object");

  return [g, r, i, gen, ren, inf]() {
    if (gen->parsed()) {
      resetStageTimings();
      if (!std::filesystem::path(g->out).has_filename())
        throw Error(ErrorKind::Usage, "--out must name a file");
      const glm::ivec2 size = parseSize(g->size);
      g->settings.width = size.x;
      g->settings.height = size.y;
      checkMomentImageSettings(g->settings);
      const auto t0 = std::chrono::steady_clock::now();
      Engine engine(Precision::FP32);
      loadInput(engine, g->input.volume, g->input.scene, g->input.resolution, !g->json);
      const double loadMs = msSince(t0);
      if (!g->camera.empty()) {
        const glm::vec3 c = parseTriple(g->camera, "--camera");
        checkOrbit(c.x, c.y, c.z, "--camera");
        engine.orbitCamera(c.x, c.y, c.z);
      }
      MomentGenerationStats stats;
      const MomentImage image =
          generateMomentImage(engine.volume(), engine.camera(), g->settings, &stats);
      const auto tw = std::chrono::steady_clock::now();
      writeMomentImage(image, g->out);
      const double writeMs = msSince(tw);
      nlohmann::json d = describe(image, g->out);
      if (g->json) {
        d["command"] = "moments generate";
        d["times_ms"] = {{"load", loadMs},
                         {"march", stats.marchMs},
                         {"count", stats.countMs},
                         {"uncertainty", stats.uncertaintyMs},
                         {"write", writeMs}};
        d["samples"] = stats.samples;
        d["stages"] = stageTimingsJson();
        std::printf("%s\n", d.dump(2).c_str());
      } else {
        printSummary(d);
        std::printf("march %.0f ms, moment count %.0f ms, write %.0f ms\n", stats.marchMs,
                    stats.countMs, writeMs);
      }
      return int(kOk);
    }
    if (ren->parsed()) {
      resetStageTimings();
      checkPngOutput(r->out);
      if (!r->referenceOut.empty()) checkPngOutput(r->referenceOut);
      if (!r->referenceOut.empty() && r->input.volume.empty() && r->input.scene.empty())
        throw Error(ErrorKind::Usage, "--reference-out needs --volume or --scene");
      if (r->reconstruction == "mese")
        r->settings.reconstruction = MomentReconstruction::BoundedMese;
      else if (r->reconstruction == "fourier")
        r->settings.reconstruction = MomentReconstruction::Fourier;
      else
        throw Error(ErrorKind::Usage,
                    "--reconstruction must be mese or fourier, not " + r->reconstruction);
      r->settings.preintegrate = !r->noPreintegration;
      const auto t0 = std::chrono::steady_clock::now();
      const MomentImage image = readMomentImage(r->file);
      const double readMs = msSince(t0);
      if (r->uncertainty) {
        if (image.uncertainty.empty())
          throw Error(ErrorKind::Usage, r->file +
                                            " holds no uncertainty (generate it with "
                                            "--uncertainty Q)");
        const float top = uncertaintyHeatMapTop(image, r->uncertaintyMax);
        writePng(renderMomentUncertainty(image, top), r->out);
        std::printf(
            "%s: the %g quantile of the reconstruction error along each ray, 0 (black "
            "in magma) to %g (yellow) in normalised density\n",
            r->out.c_str(), double(image.uncertaintyQuantile), double(top));
        return int(kOk);
      }
      // The volume or scene the image was made from, when given: its own transfer function is
      // the default, and its direct rendering the comparison.
      std::optional<Engine> source;
      if (!r->input.volume.empty() || !r->input.scene.empty()) {
        source.emplace(Precision::FP32);
        loadInput(*source, r->input.volume, r->input.scene, r->input.resolution, false);
        if (!(source->volume().grid() == image.grid))
          throw Error(ErrorKind::Usage,
                      "the volume's grid is not the one " + r->file + " was generated from");
      }
      Volume range;  // the value range a preset such as generic spans
      range.valueMin = image.valueMin;
      range.valueMax = image.valueMax;
      const TransferFunction tf = !r->tf.empty()
                                      ? loadTransferFunction(r->tf, range)
                                      : (source ? source->transferFunction()
                                                : loadTransferFunction("preset:generic", range));
      const auto t1 = std::chrono::steady_clock::now();
      const Image out = renderMomentImage(image, tf, r->settings);
      const double renderMs = msSince(t1);
      writePng(out, r->out);
      nlohmann::json d = {{"command", "moments render"},
                          {"file", r->file},
                          {"reconstruction", toString(r->settings.reconstruction)},
                          {"preintegration", r->settings.preintegrate},
                          {"times_ms", {{"read", readMs}, {"render", renderMs}}}};
      if (source) {
        const auto t2 = std::chrono::steady_clock::now();
        const Image direct = renderVolumeEmissionAbsorption(
            source->volume(), image.camera, image.width, image.height, tf, r->settings);
        d["times_ms"]["direct_render"] = msSince(t2);
        d["psnr_against_direct_db"] = psnr(out, direct);
        if (!r->referenceOut.empty()) writePng(direct, r->referenceOut);
      }
      if (r->json) {
        d["stages"] = stageTimingsJson();
        std::printf("%s\n", d.dump(2).c_str());
      } else {
        std::printf("rendered %s (%s) in %.0f ms", r->out.c_str(),
                    toString(r->settings.reconstruction), renderMs);
        if (d.contains("psnr_against_direct_db"))
          std::printf(", %.1f dB against the direct rendering",
                      d["psnr_against_direct_db"].get<double>());
        std::printf("\n");
      }
      return int(kOk);
    }
    const MomentImage image = readMomentImage(i->file);
    const nlohmann::json d = describe(image, i->file);
    if (i->json)
      std::printf("%s\n", d.dump(2).c_str());
    else
      printSummary(d);
    return int(kOk);
  };
}

}  // namespace visopt::cli
