// visopt image-diff A.png B.png: PSNR, SSIM and LDR-ꟻLIP (mean, 95th percentile, weighted median,
// max) of two equally sized images, so that users and scripts can measure what a faster setting
// (fp16, fewer levels, a coarser grid) costs in the picture. --error-map writes ꟻLIP's per-pixel
// error in the magma colormap, as the reference tool shows it.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cli_common.h"
#include "commands.h"
#include "visopt/colormap.h"
#include "visopt/error.h"
#include "visopt/image.h"
#include "visopt/image_metrics.h"

namespace visopt::cli {

namespace {

std::string sizeText(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

// +infinity (identical images) is not JSON: null there, "inf" in the text.
nlohmann::json finiteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace

Runner addImageDiffCommand(CLI::App& app) {
  struct Options {
    std::string reference, test, errorMap;
    double ppd = flipDefaultPixelsPerDegree();
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option("reference", o->reference, "Reference PNG")->required();
  app.add_option("test", o->test, "PNG to compare with it")->required();
  app.add_option("--ppd", o->ppd,
                 "Pixels per degree of the observer for ꟻLIP (default: 0.7 m from a 0.7 m wide "
                 "monitor 3840 pixels across)")
      ->check(
          [](const std::string& text) {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            return end != text.c_str() && *end == '\0' && std::isfinite(v) && v > 0.0
                       ? std::string()
                       : "must be a positive number of pixels per degree, not " + text;
          },
          "positive");
  app.add_option("--error-map", o->errorMap, "Write ꟻLIP's per-pixel error as a magma PNG")
      ->default_str("none");
  app.add_flag("--json", o->json, "Print one JSON object");
  return [o]() {
    if (!o->errorMap.empty()) checkPngOutput(o->errorMap);
    const Image a = readPng(o->reference), b = readPng(o->test);
    if (a.width != b.width || a.height != b.height)
      throwBadInput(o->test, sizeText(b) + ", but " + o->reference + " is " + sizeText(a) +
                                 "; image-diff compares images of the same size");
    const double db = psnr(a, b);
    const bool hasSsim = ssimApplies(a);
    const double s = hasSsim ? ssim(a, b) : 0.0;
    const FlipResult f = flip(a, b, o->ppd);
    if (!o->errorMap.empty()) {
      Image map(f.width, f.height);
      for (size_t i = 0; i < f.error.size(); ++i)
        map.pixels[i] = evaluateColormap(Colormap::Magma, f.error[i]);
      writePng(map, o->errorMap);
    }
    if (o->json) {
      nlohmann::json j = {{"reference", o->reference},
                          {"test", o->test},
                          {"size", {a.width, a.height}},
                          {"psnr_db", finiteOrNull(db)},
                          {"identical", std::isinf(db)},
                          {"ssim", hasSsim ? nlohmann::json(s) : nlohmann::json(nullptr)},
                          {"flip",
                           {{"mean", f.mean},
                            {"p95", f.p95},
                            {"weighted_median", f.weightedMedian},
                            {"max", f.max},
                            {"pixels_per_degree", o->ppd}}}};
      if (!o->errorMap.empty()) j["error_map"] = o->errorMap;
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("%s vs %s (%s)\n", o->reference.c_str(), o->test.c_str(), sizeText(a).c_str());
      if (std::isinf(db))
        std::printf("PSNR  inf (identical)\n");
      else
        std::printf("PSNR  %.2f dB\n", db);
      if (hasSsim)
        std::printf("SSIM  %.5f\n", s);
      else
        std::printf("SSIM  n/a (smaller than its 11x11 window)\n");
      std::printf("FLIP  mean %.6f  p95 %.6f  weighted median %.6f  max %.6f  (%.2f px/deg)\n",
                  f.mean, f.p95, f.weightedMedian, f.max, o->ppd);
      if (!o->errorMap.empty()) std::printf("error map: %s\n", o->errorMap.c_str());
    }
    return kOk;
  };
}

}  // namespace visopt::cli
