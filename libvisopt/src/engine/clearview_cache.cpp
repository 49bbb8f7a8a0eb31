#include "engine/clearview_cache.h"

#include <chrono>

#include <glm/glm.hpp>

namespace visopt {

namespace {

bool sameCamera(const Camera& a, const Camera& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fovYDegrees == b.fovYDegrees;
}

}  // namespace

bool ClearViewCache::Key::operator==(const Key& o) const {
  return sameCamera(camera, o.camera) && width == o.width && height == o.height &&
         layers == o.layers && contextCount == o.contextCount && volumeLayer == o.volumeLayer &&
         volumeData == o.volumeData && fields == o.fields && transferToken == o.transferToken &&
         sceneRevision == o.sceneRevision && importanceRevision == o.importanceRevision;
}

ClearViewCache::~ClearViewCache() {
  if (ledgerToken_ && ledger_) ledger_->remove(ledgerToken_);
}

void ClearViewCache::render(const ClearViewInputs& in, const ClearViewSettings& settings,
                            ClearViewStats* stats, Image& image) {
  Key key;
  key.camera = in.camera;
  key.width = settings.width;
  key.height = settings.height;
  key.layers.push_back(settings.context);
  key.layers.insert(key.layers.end(), settings.deeperContexts.begin(),
                    settings.deeperContexts.end());
  key.contextCount = key.layers.size();
  key.layers.push_back(settings.focus);
  key.layers.insert(key.layers.end(), settings.moreFoci.begin(), settings.moreFoci.end());
  key.volumeLayer = settings.volumeLayer;
  key.volumeData = in.volume->normalized.raw();
  for (const auto* sources : {&in.contexts, &in.foci})
    for (const ClearViewSurfaceSource& s : *sources)
      key.fields.push_back(s.field ? s.field->raw() : nullptr);
  key.transferToken = in.transferToken;
  key.sceneRevision = in.sceneRevision;
  key.importanceRevision = in.importanceRevision;

  ClearViewStats local;
  ClearViewStats& st = stats ? *stats : local;
  st = ClearViewStats{};
  if (!key_ || !(*key_ == key)) {
    const auto start = std::chrono::steady_clock::now();
    key_.reset();  // a failed extraction leaves no layers that claim to be current
    extractClearViewLayers(*in.volume, *in.transfer, in.camera, settings.width, settings.height,
                           in.contexts, in.foci, settings.volumeLayer, layers_);
    key_ = key;
    ++extractions_;
    st.extracted = true;
    st.extractMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (ledger_) {
      if (ledgerToken_) ledger_->remove(ledgerToken_);
      ledgerToken_ = ledger_->add("clearview-layers", layers_.bytes(), "fp32");
    }
  }
  const Bounds b = in.volume->grid().worldBounds();
  const float defaultSize = 0.5f * 0.5f * glm::length(b.hi - b.lo);
  compositeClearView(layers_, settings, in.camera, in.light, defaultSize, &st, image);
  st.extractions = extractions_;
}

}  // namespace visopt
