// Cursor to scene: the camera ray through a widget position, exactly as the renderer casts it
// (FrustumGrid::forCamera: vertical field of view, aspect = width / height, pixel centres at
// half-integers of widget coordinates, row 0 at the top), and picking of the first visible
// thing along it.
#pragma once

#include <optional>

#include <QPointF>
#include <glm/glm.hpp>

#include <visopt/field.h>

#include "viewport_tool.h"

namespace visopt::ws {

struct WorldRay {
  glm::vec3 origin{0.f};     // the camera's eye
  glm::vec3 direction{0.f};  // unit length
};

// The ray through `widgetPos` (widget pixels, origin top left, continuous: the centre of pixel
// column c is c + 0.5). Empty when the image size is empty or the camera is degenerate.
std::optional<WorldRay> worldRay(const ViewContext& view, QPointF widgetPos);

// The inverse of worldRay: where `world` appears in the widget. Empty behind the eye or for a
// degenerate view.
std::optional<QPointF> projectToWidget(const ViewContext& view, glm::vec3 world);

// Widget pixels per world unit for something at `world` (perspective foreshortening); 0 when it
// is behind the eye.
double pixelsPerWorldUnit(const ViewContext& view, glm::vec3 world);

// Trilinear sample at continuous index coordinates (voxel centres at integers), clamped to the
// grid. An empty field samples 0.
float sampleTrilinear(const Field3D& field, glm::vec3 index);

struct PickOptions {
  // The volume is hit where the transfer function's opacity exceeds this.
  float opacityThreshold = 0.3f;
  // March step in units of the volume's smallest spacing.
  float stepFactor = 0.25f;
};

// The first point along the ray through `widgetPos` where it enters a visible context surface
// (phi0 goes from > 0 to <= 0, located by interpolation, then refined by regula falsi). Only when
// no visible surface is hit: the first point where the transfer function's opacity of the
// trilinearly sampled scalar exceeds `opacityThreshold`. Empty when the ray hits neither or the
// view has no scene.
std::optional<glm::vec3> pickWorldPoint(const ViewContext& view, QPointF widgetPos,
                                        const PickOptions& options = {});

}  // namespace visopt::ws
