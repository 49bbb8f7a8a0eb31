// Orbit, pan and zoom of a camera about its target, the way Slicer's and ParaView's mouse
// navigation feels: left drag orbits about the world's up axis (+z) and the camera's right
// axis, middle drag pans in the image plane, wheel and right drag zoom.
#pragma once

#include <glm/glm.hpp>

#include <visopt/camera.h>

namespace visopt::ws {

// Turns the eye about the target: azimuth about +z, elevation about the camera's right axis,
// elevation kept within ±89° so the view never flips.
Camera orbitCamera(const Camera& camera, float azimuthDeg, float elevationDeg);
// Moves eye and target together; `delta` is in viewport heights (x right, y down), so a drag
// across the whole viewport moves the scene under the cursor by the view's height at the target.
Camera panCamera(const Camera& camera, glm::vec2 delta);
// Divides the eye-target distance by `factor` (> 1 zooms in), kept within [minDist, maxDist].
Camera zoomCamera(const Camera& camera, float factor, float minDistance, float maxDistance);

}  // namespace visopt::ws
