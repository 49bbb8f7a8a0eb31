// Names, descriptions and dispatch of the built-in scenes.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "scenes/scene_common.h"
#include "scenes/scene_makers.h"
#include "visopt/error.h"
#include "visopt/precision.h"
#include "visopt/volume_io.h"

namespace visopt {

namespace {

struct Entry {
  const char* name;
  const char* description;
  BuiltinScene (*make)(int, Precision, MemoryLedger*);
};

const Entry kScenes[] = {
    {"shepp-logan",
     "3D Shepp-Logan head phantom: an opaque outer shell hides the tumours marked important",
     &scenes::makeSheppLogan},
    {"marschner-lobb", "Marschner-Lobb test signal (fM = 6, alpha = 0.25) on [-1, 1]^3",
     &scenes::makeMarschnerLobb},
    {"earth-mantle",
     "Earth-like sphere: opaque crust, hot core, cold slabs in the mantle marked important",
     &scenes::makeEarthMantle},
    {"mixer", "Stirred tank: wall, rod and paddle around vortex tubes marked important",
     &scenes::makeMixer},
    {"hydrogen", "Hydrogen 3d_z2 orbital density: lobes marked important, torus as context",
     &scenes::makeHydrogen},
    {"ct-head",
     "CT-like head: the skin isosurface hides a thick skull (marked important) under soft tissue",
     &scenes::makeCtHead},
    {"wall-and-membrane",
     "A dense wall hides an optically thin important disc behind it (volume only, no context "
     "surface)",
     &scenes::makeWallAndMembrane},
    {"level-set-cases",
     "Paper 000's Fig. 3: an important object in front of, nested inside and behind a context "
     "surface",
     &scenes::makeLevelSetCases},
};

// Former names, still accepted (sessions and scripts that use them), not listed.
struct Alias {
  const char* old;
  const char* name;
};
const Alias kAliases[] = {{"occluded-blob", "wall-and-membrane"}};

}  // namespace

std::vector<SceneDescription> builtinScenes() {
  std::vector<SceneDescription> out;
  for (const Entry& e : kScenes) out.push_back(SceneDescription{e.name, e.description});
  return out;
}

std::string defaultSceneName() {
  return "shepp-logan";
}

BuiltinScene makeBuiltinScene(const std::string& name, int resolution, Precision precision,
                              MemoryLedger* ledger) {
  for (const Alias& a : kAliases)
    if (name == a.old) return makeBuiltinScene(a.name, resolution, precision, ledger);
  for (const Entry& e : kScenes)
    if (name == e.name) {
      scenes::checkResolution(name, resolution);
      // Refused before anything is allocated: a scene holds about kSceneFields fields of
      // resolution^3 values while it is made (the volume, its importance, a context surface's
      // base SDF and the generator's own), and at 1024^3 that exceeded the machine.
      constexpr double kSceneFields = 4.0;
      const double bytes =
          std::pow(double(resolution), 3.0) * double(bytesPerValue(precision)) * kSceneFields;
      const double available = double(availableMemoryBytes());
      if (bytes > available) {
        char message[256];
        std::snprintf(message, sizeof message,
                      "scene %s: resolution %d needs about %.1f GiB, %.1f GiB are available",
                      name.c_str(), resolution, bytes / double(1 << 30),
                      available / double(1 << 30));
        throw Error(ErrorKind::Usage, message);
      }
      return e.make(resolution, precision, ledger);
    }
  std::string known;
  for (const Entry& e : kScenes) known += (known.empty() ? "" : ", ") + std::string(e.name);
  throw Error(ErrorKind::Usage, "unknown built-in scene '" + name + "' (known: " + known + ")");
}

}  // namespace visopt
