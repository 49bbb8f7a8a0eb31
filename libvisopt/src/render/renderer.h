// The renderer's host side: builds kernel parameters from the scene and launches them.
#pragma once

#include <glm/glm.hpp>

#include "core/device_buffer.h"
#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/frustum.h"
#include "visopt/image.h"
#include "visopt/render_settings.h"
#include "visopt/volume.h"

namespace visopt {

struct RenderScene {
  const Volume* volume = nullptr;
  const Field3D* extinction = nullptr;           // optimised mu, or null for mu_bar
  const DeviceBuffer<glm::vec4>* transfer = nullptr;  // baked table (albedo, extinction)
  Camera camera;
  PointLight light;
  const FrustumGrid* lightFrustum = nullptr;  // with lightTransmittance, or both null
  const Field3D* lightTransmittance = nullptr;
};

// T_L on the light frustum grid, midpoint discretisation (see kernels/transmittance_scan.h).
void computeLightTransmittance(const RenderScene& scene, const FrustumGrid& lightFrustum,
                               Field3D& out);

Image renderImage(const RenderScene& scene, const RenderSettings& settings, RenderStats* stats);

}  // namespace visopt
