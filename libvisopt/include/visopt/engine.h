// The Engine: the one facade the workstation, the CLI and the tests use. It owns the scene's
// fields and the order of the stages; a user of the library never touches a kernel.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "visopt/camera.h"
#include "visopt/exec.h"
#include "visopt/image.h"
#include "visopt/memory_ledger.h"
#include "visopt/precision.h"
#include "visopt/progress.h"
#include "visopt/render_settings.h"
#include "visopt/scenes.h"
#include "visopt/transfer_function.h"
#include "visopt/volume.h"

namespace visopt {

class Engine {
 public:
  explicit Engine(Precision precision = Precision::FP32);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  Precision precision() const;

  // Scene input. Loading replaces the volume and frames the camera and light on it.
  void loadVolume(const std::string& path, const ProgressCallback& progress = {});
  // Loads a built-in scene with its transfer function, view and light.
  void loadBuiltinScene(const std::string& name, int resolution = 128);
  void setVolume(Volume volume);
  bool hasVolume() const;
  const Volume& volume() const;

  void setTransferFunction(TransferFunction tf);
  const TransferFunction& transferFunction() const;

  void setCamera(const Camera& camera);
  const Camera& camera() const;
  // Orbit around the volume centre; distance in bounding-sphere radii.
  void orbitCamera(float azimuthDeg, float elevationDeg, float distanceInRadii);
  void setLight(const PointLight& light);
  const PointLight& light() const;

  // Renders the current scene. T_L is recomputed only when the light, the transfer function,
  // the volume or the light grid size changed since the last render.
  Image render(const RenderSettings& settings, RenderStats* stats = nullptr);

  const MemoryLedger& ledger() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace visopt
