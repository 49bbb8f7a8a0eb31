// The Engine's ClearView state: the layers of the last view and what they were extracted for,
// so that a change of the hotspot, the measure, the shaders or the light composites only.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/device_buffer.h"
#include "render/clearview.h"
#include "visopt/camera.h"
#include "visopt/clearview.h"
#include "visopt/image.h"
#include "visopt/memory_ledger.h"
#include "visopt/volume.h"

namespace visopt {

// What one ClearView render reads of the scene.
struct ClearViewInputs {
  const Volume* volume = nullptr;
  const DeviceBuffer<glm::vec4>* transfer = nullptr;
  int transferToken = 0;  // changes with every bake of the transfer function
  Camera camera;
  PointLight light;
  // The context surfaces front to back, then the focus surfaces (settings.context first, then
  // its deeperContexts; settings.focus first, then its moreFoci).
  std::vector<ClearViewSurfaceSource> contexts, foci;
  // Counters the Engine advances when the volume, the context surfaces (also as the optimisation
  // moves them) or the importance change.
  uint64_t sceneRevision = 0, importanceRevision = 0;
};

class ClearViewCache {
 public:
  explicit ClearViewCache(MemoryLedger* ledger) : ledger_(ledger) {}
  ~ClearViewCache();
  ClearViewCache(const ClearViewCache&) = delete;
  ClearViewCache& operator=(const ClearViewCache&) = delete;

  void render(const ClearViewInputs& in, const ClearViewSettings& settings, ClearViewStats* stats,
              Image& image);
  int64_t extractions() const { return extractions_; }

 private:
  struct Key {
    Camera camera;
    int width = 0, height = 0;
    std::vector<ClearViewLayer> layers;  // the contexts, then the foci
    size_t contextCount = 0;
    bool volumeLayer = false;
    const void* volumeData = nullptr;
    std::vector<const void*> fields;  // of each layer
    int transferToken = 0;
    uint64_t sceneRevision = 0, importanceRevision = 0;
    bool operator==(const Key& o) const;
  };

  MemoryLedger* ledger_;
  int ledgerToken_ = 0;
  std::optional<Key> key_;
  ClearViewLayers layers_;
  int64_t extractions_ = 0;
};

}  // namespace visopt
