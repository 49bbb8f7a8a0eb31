// ClearView's host side (Krüger, Schneider, Westermann 2006): the cached layers, their extraction
// (kernels/clearview_extract.h) and the compositing (kernels/clearview_composite.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "core/device_buffer.h"
#include "kernels/clearview_composite.h"
#include "visopt/camera.h"
#include "visopt/clearview.h"
#include "visopt/field.h"
#include "visopt/image.h"
#include "visopt/volume.h"

namespace visopt {

// One context surface layer of one view.
struct ClearViewContextLayer {
  DeviceBuffer<glm::vec3> position, normal;
  DeviceBuffer<float> depth, normalDistance;
  int64_t pixels = 0;  // with a hit
  size_t bytes() const;
};

// The layers of one view: one entry per pixel, row 0 at the top. The first context layer's
// buffers are named (contextPosition ...), the deeper ones follow in deeperContexts; the focus
// buffers hold the nearest hit of all focus surfaces.
struct ClearViewLayers {
  int width = 0, height = 0;
  DeviceBuffer<glm::vec3> contextPosition, contextNormal, focusPosition, focusNormal;
  DeviceBuffer<float> contextDepth, focusDepth, normalDistance;
  std::vector<ClearViewContextLayer> deeperContexts;
  DeviceBuffer<glm::vec4> volume;  // empty without a volume layer
  int64_t contextPixels = 0, focusPixels = 0;

  size_t bytes() const;
  ClearViewLayersView view() const;
};

// A surface layer's field on the volume's grid: inside where sign * (value - iso) >= 0.
struct ClearViewSurfaceSource {
  const Field3D* field = nullptr;
  float iso = 0.f;
  float sign = 1.f;
};

// Extracts the layers of `camera`'s view at width x height: the context surfaces in `contexts`
// (front to back) and the nearest hit of those in `foci` (1..kClearViewMaxLayers each).
// `transfer` (the baked table) is read only with a volume layer. The distance measure looks along
// the normal as far as a quarter of the volume's diagonal.
void extractClearViewLayers(const Volume& volume, const DeviceBuffer<glm::vec4>& transfer,
                            const Camera& camera, int width, int height,
                            std::span<const ClearViewSurfaceSource> contexts,
                            std::span<const ClearViewSurfaceSource> foci, bool volumeLayer,
                            ClearViewLayers& out);

// The focus point C (§3.2): the cursor's pixel projected onto the focus layer; false when the
// focus layer has no hit there (the context then stays opaque everywhere).
bool clearViewFocusPoint(const ClearViewLayers& layers, glm::vec2 focusPixel, glm::vec3& point);

// The hotspot radius when the user gave none: twice the depth of the focus point below the
// context surface along the focus pixel's ray, so that the context there is half opaque and
// fades out over about 1.7 times that depth around it (a focus deep inside needs a
// larger sphere than one just under the skin); `fallback` where the focus pixel does not see
// the context in front of the focus, and at least a tenth of it.
float automaticClearViewSize(const ClearViewLayers& layers, glm::vec2 focusPixel, float fallback);

// Composites the layers (settings.width x height must equal the layers'); `defaultSize` is the
// fallback of automaticClearViewSize, used when settings.size is 0.
// `image` is resized to the layers' size; its pixels are reused when it already has it.
void compositeClearView(const ClearViewLayers& layers, const ClearViewSettings& settings,
                        const Camera& camera, const PointLight& light, float defaultSize,
                        ClearViewStats* stats, Image& image);

}  // namespace visopt
