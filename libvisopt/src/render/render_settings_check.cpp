// checkRenderSettings: every number of RenderSettings in the range the renderer can honour.
#include <cmath>
#include <cstdio>
#include <string>

#include "visopt/error.h"
#include "visopt/render_settings.h"

namespace visopt {

namespace {

[[noreturn]] void refuse(const char* what, const char* range) {
  throw Error(ErrorKind::Usage, std::string("render settings: ") + what + " must be " + range);
}

void finiteAtLeastZero(float v, const char* what) {
  if (!(std::isfinite(v) && v >= 0.f)) refuse(what, "finite and >= 0");
}

}  // namespace

void checkRenderSettings(const RenderSettings& s) {
  if (s.width <= 0 || s.height <= 0 || s.width > 16384 || s.height > 16384)
    throw Error(ErrorKind::Usage, "image size must be between 1 and 16384 pixels per side");
  if (!(s.stepFactor >= kMinStepFactor && s.stepFactor <= kMaxStepFactor)) {
    char message[128];
    std::snprintf(message, sizeof message,
                  "the ray-march step must be %g..%g times the smallest voxel spacing",
                  double(kMinStepFactor), double(kMaxStepFactor));
    throw Error(ErrorKind::Usage, message);
  }
  if (s.previewFactor < 1 || s.previewFactor > 64) refuse("the preview factor", "1..64");
  if (!(s.cutAwayThreshold >= 0.f && s.cutAwayThreshold <= 1.f))
    refuse("the cut-away threshold", "0..1");
  if (!std::isfinite(s.hgAnisotropy)) refuse("the Henyey-Greenstein anisotropy", "finite");
  finiteAtLeastZero(s.diffuse, "diffuse");
  finiteAtLeastZero(s.specular, "specular");
  finiteAtLeastZero(s.shininess, "shininess");
  finiteAtLeastZero(s.surfaceGradient, "the surface gradient");
  finiteAtLeastZero(s.ambient, "ambient");
  finiteAtLeastZero(s.exposure, "exposure");
  finiteAtLeastZero(s.surfaceSpecular, "the surface specular");
  finiteAtLeastZero(s.surfaceShininess, "the surface shininess");
  finiteAtLeastZero(s.ambientOcclusionRadius, "the ambient-occlusion radius");
  finiteAtLeastZero(s.deviationMaxVoxels, "the deviation range");
  if (!std::isfinite(s.importanceOverlay))  // <= 0 is off
    refuse("the importance overlay", "finite");
  if (!(s.earlyStop >= 0.f && s.earlyStop < 1.f)) refuse("the early stop", "0 <= value < 1");
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(s.background[c])) refuse("the background colour", "finite");
  // The light grid holds size^2 x depth transmittance cells: a session asking for 65536 rays
  // per side wanted 640 GiB.
  if (s.lightGridSize < kMinLightGridSize || s.lightGridSize > kMaxLightGridSize)
    refuse("the light grid", "16..1024 rays per side");
  if (s.lightGridDepth < 0 || s.lightGridDepth > kMaxLightGridDepth)
    refuse("the light grid's depth", "0 (automatic)..4096 cells");
}

}  // namespace visopt
