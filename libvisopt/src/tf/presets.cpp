// Built-in transfer-function presets. Values are in data units: Hounsfield units for the CT
// presets, 0..255 for "mri"; "generic" is stored over [0, 1] and stretched to the data range.
#include "tf/presets.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "visopt/error.h"

namespace visopt {

namespace {

struct PresetData {
  const char* name;
  float unitDistance;
  std::vector<OpacityPoint> opacity;
  std::vector<ColorPoint> color;
};

const std::vector<PresetData>& presetTable() {
  static const std::vector<PresetData> table = {
      // Air clear; the skin boundary (-500..-150 HU) a semi-opaque skin-coloured layer; soft
      // tissue faint and reddish; bone (> 300 HU) opaque ivory.
      {"ct-skin-bone",
       3.f,
       {{-1024, 0.f},
        {-700, 0.f},
        {-500, 0.25f},
        {-150, 0.25f},
        {-50, 0.03f},
        {200, 0.03f},
        {350, 0.85f},
        {3071, 0.95f}},
       {{-1024, {0.55f, 0.25f, 0.15f}},
        {-500, {0.93f, 0.66f, 0.54f}},
        {-100, {0.93f, 0.66f, 0.54f}},
        {100, {0.80f, 0.35f, 0.30f}},
        {300, {0.95f, 0.92f, 0.82f}},
        {3071, {1.f, 1.f, 0.95f}}}},
      // Bone only: everything below ~150 HU is clear.
      {"ct-bone",
       2.f,
       {{-1024, 0.f}, {150, 0.f}, {300, 0.6f}, {700, 0.9f}, {3071, 0.95f}},
       {{-1024, {0.85f, 0.75f, 0.60f}},
        {150, {0.85f, 0.75f, 0.60f}},
        {400, {0.95f, 0.92f, 0.82f}},
        {3071, {1.f, 1.f, 1.f}}}},
      // 8-bit MRI: background clear, tissue a gentle ramp from cool grey to warm white.
      {"mri",
       3.f,
       {{0, 0.f}, {20, 0.f}, {60, 0.05f}, {120, 0.2f}, {255, 0.6f}},
       {{0, {0.20f, 0.20f, 0.25f}},
        {60, {0.55f, 0.50f, 0.50f}},
        {150, {0.85f, 0.75f, 0.65f}},
        {255, {1.f, 0.95f, 0.85f}}}},
      // A ramp over the data range (stored over [0, 1]), greyish to warm; unit distance 0 means
      // "the volume's smallest spacing".
      {"generic",
       0.f,
       {{0, 0.f}, {0.1, 0.f}, {1, 0.25f}},
       {{0, {0.35f, 0.35f, 0.40f}}, {0.5, {0.75f, 0.70f, 0.65f}}, {1, {1.f, 0.75f, 0.40f}}}},
  };
  return table;
}

std::string knownNames() {
  std::string s;
  for (const auto& p : presetTable()) s += (s.empty() ? "" : ", ") + std::string(p.name);
  return s;
}

}  // namespace

namespace tfpresets {

TransferFunction compiledIn(const std::string& name) {
  for (const auto& p : presetTable()) {
    if (name != p.name) continue;
    TransferFunction tf;
    tf.name = p.name;
    tf.unitDistance = p.unitDistance;
    tf.opacity = p.opacity;
    tf.color = p.color;
    tf.validate("preset " + name);
    return tf;
  }
  throw Error(ErrorKind::Usage,
              "unknown transfer-function preset '" + name + "' (known: " + knownNames() + ")");
}

std::string presetFile(const std::string& name) {
  namespace fs = std::filesystem;
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("VISOPT_RESOURCES"); env && *env) dirs.emplace_back(env);
#ifdef VISOPT_RESOURCE_DIR
  dirs.emplace_back(VISOPT_RESOURCE_DIR);
#endif
  for (const auto& dir : dirs) {
    const fs::path file = dir / "transfer-functions" / (name + ".json");
    std::error_code ec;
    if (fs::is_regular_file(file, ec)) return file.string();
  }
  return {};
}

}  // namespace tfpresets

std::vector<std::string> TransferFunction::presetNames() {
  std::vector<std::string> names;
  for (const auto& p : presetTable()) names.emplace_back(p.name);
  return names;
}

std::vector<glm::dvec2> TransferFunction::presetImportance(const std::string& name) {
  (void)tfpresets::compiledIn(name);  // rejects unknown names
  if (name == "ct-skin-bone" || name == "ct-bone")
    return {{-1024.0, 0.0}, {200.0, 0.0}, {300.0, 1.0}, {3071.0, 1.0}};
  return {};
}

std::optional<double> TransferFunction::presetContextIsovalue(const std::string& name) {
  (void)tfpresets::compiledIn(name);  // rejects unknown names
  if (name == "ct-skin-bone") return -400.0;
  return std::nullopt;
}

TransferFunction TransferFunction::preset(const std::string& name, double valueMin,
                                          double valueMax) {
  TransferFunction tf = tfpresets::compiledIn(name);  // also rejects unknown names
  if (const std::string file = tfpresets::presetFile(name); !file.empty()) tf = load(file);
  tf.name = name;
  if (name == "generic") {
    if (!std::isfinite(valueMin) || !std::isfinite(valueMax) || valueMax < valueMin)
      throw Error(ErrorKind::Usage, "preset generic: needs a finite data range with min <= max");
    const double span = valueMax - valueMin;
    for (auto& p : tf.opacity) p.value = valueMin + p.value * span;
    for (auto& p : tf.color) p.value = valueMin + p.value * span;
  }
  return tf;
}

}  // namespace visopt
