#include "cli_common.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "visopt/error.h"

namespace visopt::cli {

std::vector<float> parseFloats(const std::string& text, char sep, const std::string& what) {
  std::vector<float> out;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, sep)) {
    try {
      size_t used = 0;
      float v = std::stof(part, &used);
      if (used != part.size()) throw std::invalid_argument(part);
      if (!std::isfinite(v)) throw std::invalid_argument(part);  // stof takes "nan" and "inf"
      out.push_back(v);
    } catch (const std::exception&) {
      throw Error(ErrorKind::Usage, what + ": '" + text + "' is not a list of finite numbers");
    }
  }
  return out;
}

glm::ivec2 parseSize(const std::string& text) {
  auto v = parseFloats(text, 'x', "--size");
  if (v.size() != 2 || v[0] < 1 || v[1] < 1 || v[0] > 16384 || v[1] > 16384 ||
      v[0] != float(int(v[0])) || v[1] != float(int(v[1])))
    throw Error(ErrorKind::Usage, "--size: expected WxH with 1..16384 pixels, got '" + text + "'");
  return {int(v[0]), int(v[1])};
}

glm::vec3 parseTriple(const std::string& text, const std::string& what) {
  auto v = parseFloats(text, ',', what);
  if (v.size() != 3) throw Error(ErrorKind::Usage, what + ": expected three numbers A,B,C");
  return {v[0], v[1], v[2]};
}

void loadInput(Engine& engine, const std::string& volume, const std::string& scene,
               int sceneResolution, bool showProgress) {
  if (volume.empty() == scene.empty())
    throw Error(ErrorKind::Usage, "give exactly one of --volume FILE or --scene builtin:NAME");
  if (!scene.empty()) {
    const std::string prefix = "builtin:";
    std::string name = scene.rfind(prefix, 0) == 0 ? scene.substr(prefix.size()) : scene;
    engine.loadBuiltinScene(name, sceneResolution);
    return;
  }
  ProgressCallback progress;
  if (showProgress)
    progress = [](float fraction, const std::string& stage) {
      std::fprintf(stderr, "\r%-24s %3d%%", stage.c_str(), int(fraction * 100.f + 0.5f));
      if (fraction >= 1.f) std::fprintf(stderr, "\n");
      return true;
    };
  engine.loadVolume(volume, progress);
  for (const std::string& w : engine.volume().warnings)
    std::fprintf(stderr, "visopt: warning: %s\n", w.c_str());
}

TransferFunction loadTransferFunction(const std::string& spec, const Volume& volume) {
  const std::string prefix = "preset:";
  if (spec.rfind(prefix, 0) == 0)
    return TransferFunction::preset(spec.substr(prefix.size()), volume.valueMin, volume.valueMax);
  return TransferFunction::load(spec);
}

nlohmann::json stageTimingsJson() {
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& t : stageTimings())
    stages.push_back({{"name", t.name}, {"ms", t.totalMs}, {"calls", t.calls}, {"items", t.items}});
  return stages;
}

nlohmann::json ledgerJson(const MemoryLedger& ledger) {
  nlohmann::json fields = nlohmann::json::array();
  for (const auto& e : ledger.entries())
    fields.push_back({{"name", e.name}, {"bytes", e.bytes}, {"precision", e.precision}});
  return {{"fields", fields}, {"total_bytes", ledger.totalBytes()}};
}

std::string humanBytes(size_t bytes) {
  char buf[64];
  if (bytes >= (size_t(1) << 30))
    std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / double(size_t(1) << 30));
  else if (bytes >= (size_t(1) << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / double(size_t(1) << 20));
  else
    std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
  return buf;
}

bool applyPresetImportance(Engine& engine, const std::string& importance, const std::string& scene,
                           const std::string& tf) {
  std::string preset;
  if (importance.rfind("preset:", 0) == 0)
    preset = importance.substr(7);
  else if (importance.empty() && scene.empty() && tf.rfind("preset:", 0) == 0)
    preset = tf.substr(7);
  if (preset.empty()) return false;
  const auto curve = TransferFunction::presetImportance(preset);
  if (curve.empty() && !importance.empty())
    throw Error(ErrorKind::Usage, "--importance " + importance +
                                      ": this preset carries no importance (the CT presets "
                                      "ct-skin-bone and ct-bone do)");
  if (!curve.empty()) engine.setImportanceCurve(curve, "preset:" + preset);
  return true;
}

}  // namespace visopt::cli
