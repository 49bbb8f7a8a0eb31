// Built-in scenes, generated in code and deterministic: they need no download and give exact
// answers for tests. Each carries its own transfer function, camera and light.
#pragma once

#include <string>
#include <vector>

#include "visopt/camera.h"
#include "visopt/context_surface.h"
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
  // What the user should see, from the scene's own definition: g(x) in [0, 1] on the volume's
  // grid (field name "importance"), e.g. a soft indicator of the tumours. Always present.
  Field3D importance;
  // The same structures as a curve over normalised values, points (t, g) — what a user could
  // set in an importance editor; may also catch edges that pass through the same values.
  std::vector<glm::vec2> importanceCurve;
  // The scene's context surfaces (Himmler & Günther 2026, §III) and the transfer function to use
  // with them: what the surfaces show is then transparent in the volume. Empty for scenes without.
  std::vector<ContextSurfaceSpec> contextSurfaces;
  TransferFunction contextTransferFunction;
};

std::vector<SceneDescription> builtinScenes();
std::string defaultSceneName();  // "shepp-logan"
// Throws Error(Usage) for an unknown name. `resolution` is the longest axis in voxels (>= 2).
BuiltinScene makeBuiltinScene(const std::string& name, int resolution, Precision precision,
                              MemoryLedger* ledger = nullptr);

}  // namespace visopt
