// Loading and repairing triangle meshes for SDF conversion (OpenMesh stays inside
// mesh_loading.cpp). The result is an indexed triangle list with duplicate vertices merged and
// degenerate faces removed, plus the MeshReport describing what was found.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "visopt/progress.h"
#include "visopt/sdf.h"

namespace visopt::sdf {

struct TriangleMesh {
  std::vector<glm::vec3> points;
  std::vector<glm::uvec3> triangles;
};

// Calls `progress` (when set) and throws Error(Cancelled, "PATH: cancelled") when it asks to stop.
void reportProgress(const ProgressCallback& progress, const std::string& path, float fraction,
                    const std::string& stage);

// Reads an OBJ / PLY / OFF / STL file, merges duplicate vertices (exact or within 1e-7 of the
// bounding-box diagonal), drops degenerate faces and checks closedness and manifoldness; fills
// `report`. Throws BadInput "PATH: problem" for unreadable input. Progress runs over
// [0, `progressEnd`].
TriangleMesh loadMesh(const std::string& path, MeshReport& report, const ProgressCallback& progress,
                      float progressEnd);

}  // namespace visopt::sdf
