// Built-in scenes, generated in code and deterministic: they need no download and give exact
// answers for tests. Each carries its own transfer function, camera and light.
#pragma once

#include <string>
#include <vector>

#include "visopt/camera.h"
#include "visopt/precision.h"
#include "visopt/transfer_function.h"
#include "visopt/volume.h"

namespace visopt {

class MemoryLedger;

struct SceneDescription {
  std::string name;         // used as builtin:NAME
  std::string description;  // one line
};

struct BuiltinScene {
  Volume volume;
  TransferFunction transferFunction;
  // Default view as an orbit around the volume centre (distance in bounding-sphere radii).
  float azimuthDeg = 0.f, elevationDeg = 0.f, distanceInRadii = 3.f;
  // The importance curve over normalised values, for later issues: points (t, g).
  std::vector<glm::vec2> importanceCurve;
};

std::vector<SceneDescription> builtinScenes();
std::string defaultSceneName();  // "shepp-logan"
// Throws Error(Usage) for an unknown name. `resolution` is the longest axis in voxels (>= 2).
BuiltinScene makeBuiltinScene(const std::string& name, int resolution, Precision precision,
                              MemoryLedger* ledger = nullptr);

}  // namespace visopt
