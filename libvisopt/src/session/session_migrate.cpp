#include "session/session_migrate.h"

#include "visopt/camera.h"
#include "visopt/session.h"

namespace visopt::session {

namespace {

// v1 -> v2: the camera was an orbit about its target, {"target", "azimuth", "elevation",
// "distance" (world units), "fovY"}; v2 stores the frame itself, {"eye", "target", "up", "fovY"}.
void cameraOrbitToFrame(nlohmann::json& doc, const Where& where) {
  auto it = doc.find("camera");
  if (it == doc.end()) return;
  const Where w = where.key("camera");
  expectObject(*it, w);
  glm::vec3 target{0.f};
  float azimuth = 0.f, elevation = 0.f, distance = 0.f;
  readRequired(*it, "target", target, w);
  readRequired(*it, "azimuth", azimuth, w);
  readRequired(*it, "elevation", elevation, w);
  readRequired(*it, "distance", distance, w);
  if (!(distance > 0.f)) w.key("distance").fail("must be positive");
  const Camera c = Camera::orbit(target, azimuth, elevation, distance);
  auto vec = [](glm::vec3 v) { return nlohmann::json{v.x, v.y, v.z}; };
  nlohmann::json frame = {{"eye", vec(c.eye)}, {"target", vec(c.target)}, {"up", vec(c.up)}};
  if (it->contains("fovY")) frame["fovY"] = (*it)["fovY"];
  *it = std::move(frame);
}

void renameKey(nlohmann::json& doc, const char* from, const char* to, const Where& where) {
  auto it = doc.find(from);
  if (it == doc.end()) return;
  if (doc.contains(to)) where.fail(std::string("both \"") + from + "\" and \"" + to + "\"");
  nlohmann::json value = std::move(*it);
  doc.erase(from);
  doc[to] = std::move(value);
}

// v2 -> v3: clearer names for two sections.
void renameSections(nlohmann::json& doc, const Where& where) {
  renameKey(doc, "tf", "transferFunction", where);
  renameKey(doc, "surfaces", "contextSurfaces", where);
}

// v3 -> v4: two additions, nothing renamed: the ClearView hotspot's settings ("clearView") and
// the importance kind "hotspot". A version-3 reader ignored keys it did not know, so a
// "clearView" in a version-3 file was never visopt's and meant nothing: it is dropped rather than
// read as settings. ("hotspot" was refused as an importance kind by version 3, so no version-3
// file holds it.)
void addClearView(nlohmann::json& doc, const Where&) {
  doc.erase("clearView");
}

// v4 -> v5: ClearView's further layers ("deeperContexts", "moreFoci" in "clearView"). A
// version-4 reader ignored them, so in a version-4 file they were never visopt's: dropped.
void addClearViewLayers(nlohmann::json& doc, const Where&) {
  auto it = doc.find("clearView");
  if (it == doc.end() || !it->is_object()) return;
  it->erase("deeperContexts");
  it->erase("moreFoci");
}

}  // namespace

const std::vector<Converter>& converters() {
  static const std::vector<Converter> list = {&cameraOrbitToFrame, &renameSections, &addClearView,
                                              &addClearViewLayers};
  return list;
}

void migrate(nlohmann::json& doc, int fromVersion, const Where& where) {
  const auto& list = converters();
  for (int v = fromVersion; v < kSessionFormatVersion; ++v) list.at(size_t(v - 1))(doc, where);
  doc["version"] = kSessionFormatVersion;
}

}  // namespace visopt::session
