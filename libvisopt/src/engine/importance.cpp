#include "engine/importance.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "io/file_util.h"
#include "visopt/error.h"
#include "visopt/transfer_function.h"
#include "visopt/volume_io.h"

namespace visopt {

namespace {

constexpr int kTableSize = 4096;

// Tabulates the curve over normalised values t and applies it to every voxel.
Field3D applyTable(const Volume& volume, const std::vector<float>& table, Precision precision,
                   MemoryLedger* ledger) {
  Field3D g("importance", volume.grid(), precision, ledger);
  FieldView out(g), in(volume.normalized);
  const float* t = table.data();
  const int n = int(table.size());
  exec::parallelFor("importance", int64_t(g.size()), [=](int64_t v) {
    const float x = std::clamp(in.load(size_t(v)), 0.f, 1.f) * float(n - 1);
    const int i0 = std::min(int(x), n - 2);
    const float f = x - float(i0);
    out.store(size_t(v), t[i0] + f * (t[i0 + 1] - t[i0]));
  });
  return g;
}

float evaluate(const std::vector<glm::dvec2>& pts, double value) {
  if (value <= pts.front().x) return float(pts.front().y);
  if (value >= pts.back().x) return float(pts.back().y);
  auto it = std::upper_bound(pts.begin(), pts.end(), value,
                             [](double v, const glm::dvec2& p) { return v < p.x; });
  const glm::dvec2& b = *it;
  const glm::dvec2& a = *(it - 1);
  const double f = b.x > a.x ? (value - a.x) / (b.x - a.x) : 1.0;
  return float(a.y + f * (b.y - a.y));
}

std::vector<glm::dvec2> validated(std::vector<glm::dvec2> points, const std::string& origin) {
  if (points.empty()) throwBadInput(origin, "the importance curve has no points");
  for (const auto& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      throwBadInput(origin, "the importance curve has a NaN or infinite value");
    if (p.y < 0.0 || p.y > 1.0)
      throwBadInput(origin, "importance must lie in [0, 1], found " + std::to_string(p.y));
  }
  std::stable_sort(points.begin(), points.end(),
                   [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x; });
  return points;
}

}  // namespace

Field3D importanceFromCurve(const Volume& volume, const std::vector<glm::dvec2>& points,
                            const std::string& origin, Precision precision, MemoryLedger* ledger) {
  const auto pts = validated(points, origin);
  std::vector<float> table(kTableSize);
  for (int i = 0; i < kTableSize; ++i)
    table[size_t(i)] = evaluate(pts, volume.toValue(float(i) / float(kTableSize - 1)));
  return applyTable(volume, table, precision, ledger);
}

Field3D importanceFromNormalizedCurve(const Volume& volume, const std::vector<glm::vec2>& points,
                                      Precision precision, MemoryLedger* ledger) {
  std::vector<glm::dvec2> pts;
  for (const auto& p : points) pts.emplace_back(volume.toValue(p.x), p.y);
  return importanceFromCurve(volume, pts, "scene importance curve", precision, ledger);
}

Field3D importanceFromHotspot(const Volume& volume, glm::vec3 centre, float radius,
                              Precision precision, MemoryLedger* ledger) {
  Field3D g("importance", volume.grid(), precision, ledger);
  FieldView out(g);
  const GridMap map(volume.grid());
  const float inner = 0.5f * radius;
  exec::parallelFor("importance: hotspot", int64_t(g.size()), [=](int64_t v) {
    const VoxelIjk ijk = map.ijk(v);
    const float d = glm::length(map.toWorld(glm::vec3(ijk.i, ijk.j, ijk.k)) - centre);
    const float x = std::clamp((radius - d) / (radius - inner), 0.f, 1.f);  // 1 inside, 0 out
    out.store(size_t(v), x * x * (3.f - 2.f * x));
  });
  return g;
}

bool isCurveFile(const std::string& path) {
  return path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
}

std::vector<glm::dvec2> readImportanceCurve(const std::string& path) {
  io::checkedFileSize(path, io::kMaxTextInputBytes, "an importance curve");
  std::ifstream file(path);
  if (!file) throwBadInput(path, "cannot open the importance curve");
  std::stringstream ss;
  ss << file.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ss.str());
  } catch (const nlohmann::json::exception&) {
    throwBadInput(path, "not valid JSON");
  }
  std::vector<glm::dvec2> points;
  if (j.is_object() && j.contains("points")) {
    const auto& arr = j["points"];
    if (!arr.is_array()) throwBadInput(path, "\"points\" must be a list of [value, g] pairs");
    for (const auto& p : arr) {
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
        throwBadInput(path, "\"points\" must be a list of [value, g] pairs");
      points.emplace_back(p[0].get<double>(), p[1].get<double>());
    }
  } else {
    TransferFunction tf = TransferFunction::fromJson(ss.str(), path);
    for (const auto& p : tf.opacity) points.emplace_back(p.value, double(p.opacity));
  }
  return validated(points, path);
}

Field3D importanceFromVolumeFile(const Volume& volume, const std::string& path, Precision precision,
                                 MemoryLedger* ledger) {
  Volume g = readVolume(path, precision, nullptr);
  if (g.grid().dims != volume.grid().dims)
    throwBadInput(path, "the importance volume's dimensions differ from the data's");
  if (g.valueMin < 0.0 || g.valueMax > 1.0)
    throwBadInput(path, "importance values must lie in [0, 1], found " +
                            std::to_string(g.valueMin) + " .. " + std::to_string(g.valueMax));
  Field3D out("importance", volume.grid(), precision, ledger);
  FieldView o(out), in(g.normalized);
  const float lo = float(g.valueMin), span = float(g.valueMax - g.valueMin);
  exec::parallelFor("importance", int64_t(out.size()),
                    [=](int64_t v) { o.store(size_t(v), lo + span * in.load(size_t(v))); });
  return out;
}

}  // namespace visopt
