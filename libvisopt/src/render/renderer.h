// The renderer's host side: builds kernel parameters from the scene and launches them.
#pragma once

#include <functional>

#include <vector>

#include <glm/glm.hpp>

#include "core/bit_mask_view.h"
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
  // The optimised mu as its change to mu_bar per voxel (optimised mu - mu_bar), on the volume's
  // grid, or null for mu_bar alone (kernels/volume_extinction.h says why not mu itself).
  const Field3D* extinctionChange = nullptr;
  const DeviceBuffer<glm::vec4>* transfer = nullptr;  // baked table (albedo, extinction)
  Camera camera;
  PointLight light;
  const FrustumGrid* lightFrustum = nullptr;  // with lightTransmittance, or both null
  const Field3D* lightTransmittance = nullptr;
  // Context surfaces to draw (the visible ones): current phi, base phi0, colour.
  std::vector<const Field3D*> surfaces, surfaceBases;
  std::vector<glm::vec3> surfaceColors;
  // For the comparison baselines: ghat (Eq. 19) and g on the volume grid.
  const Field3D* importanceBehind = nullptr;
  const Field3D* importance = nullptr;
  BitMaskView worldMask;  // for the world-mask overlay; invalid without a mask
  // Per-block ranges for empty-space skipping (computeBlockRange) of the volume's normalised
  // scalars and of extinctionChange, kept by the caller while those fields stay the same; null:
  // computed for the frame.
  const DeviceBuffer<glm::vec2>* volumeBlockRange = nullptr;
  const DeviceBuffer<glm::vec2>* changeBlockRange = nullptr;
  // Ambient occlusion of the volume's samples (computeVolumeOcclusion) on the volume's grid;
  // null: the volume's ambient light is unoccluded (surface hits keep their own occlusion).
  const Field3D* volumeOcclusion = nullptr;
};

// The range of a field on the volume's grid over each empty-space block (kernels/ray_skip.h,
// pass 1): what a frame's skip grid needs of the volume and of the extinction change.
DeviceBuffer<glm::vec2> computeBlockRange(const Field3D& field);

// out = mu - mu_bar on the volume's grid (out's grid), mu_bar from the baked transfer table at
// each voxel's scalar, mu sampled trilinearly at the voxel's world position (so a coarse
// level's mu works too): RenderScene::extinctionChange.
void computeExtinctionChange(const Volume& volume, const DeviceBuffer<glm::vec4>& transfer,
                             const Field3D& mu, Field3D& out);

// Ambient occlusion of each voxel (kernels/volume_occlusion.h: the mean transmittance of the six
// axis rays of length `radius`, world units) through the extinction and the visible surfaces of
// `scene` as `method` draws them (cut-away and transparency modulation with the scene's ghat and
// g); `out` on the volume's grid.
void computeVolumeOcclusion(const RenderScene& scene, RenderMethod method, float cutThreshold,
                            float radius, Field3D& out);

// T_L on the light frustum grid, midpoint discretisation (see kernels/transmittance_scan.h),
// with the surfaces as `method` draws them: opaque, or cut away where the scene's ghat exceeds
// `cutThreshold`, or faded to opacity 1 - ghat (the Fig. 10 baselines).
// `abandon` (may be empty) is polled between bands of light rays: when it returns true the
// computation stops and returns false, and `out` holds the new T_L on the bands done and what it
// held before on the others.
bool computeLightTransmittance(const RenderScene& scene, const FrustumGrid& lightFrustum,
                               Field3D& out, const std::function<bool()>& abandon = {},
                               RenderMethod method = RenderMethod::Optimized,
                               float cutThreshold = 0.3f);

// `abandon` (may be empty) is polled between bands of the image; when it returns true the render
// stops and returns an empty (0 x 0) image. `settings` must have passed checkRenderSettings
// (Engine::render checks them before it allocates the light grid).
Image renderImage(const RenderScene& scene, const RenderSettings& settings, RenderStats* stats,
                  const std::function<bool()>& abandon = {});

}  // namespace visopt
